"""How a time is taken: one pinned core, best of several rounds; and the CPU the times belong to."""
import os
import pathlib
import platform
import time

import numpy as np


def pin_to_one_core():
    """Pins this process to the last CPU it may run on and returns its number (None where affinity is
    unavailable)."""
    try:
        cpus = sorted(os.sched_getaffinity(0))
        os.sched_setaffinity(0, {cpus[-1]})
        return cpus[-1]
    except (AttributeError, OSError):
        return None


def cpu_name():
    """The CPU's model name (from /proc/cpuinfo, else what the platform module reports)."""
    try:
        for line in pathlib.Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def best_seconds(fn, rounds):
    """The shortest of `rounds` wall times of fn() [s]."""
    best = np.inf
    for _ in range(rounds):
        start = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - start)
    return best


def _loop(fn, calls):
    """fn(*args) for every args in `calls`, written out for the usual arities: a call through
    `fn(*args)` builds a new tuple for a bound method (self prepended), which costs a Python method
    about 0.2 us more than the call `model.accel(x, u)` that a user writes; the raw C calls are
    builtins and pay nothing for it."""
    n = len(calls[0]) if calls else 0
    if n == 1:
        for (a,) in calls:
            fn(a)
    elif n == 2:
        for a, b in calls:
            fn(a, b)
    elif n == 3:
        for a, b, c in calls:
            fn(a, b, c)
    elif n == 4:
        for a, b, c, d in calls:
            fn(a, b, c, d)
    else:
        for args in calls:
            fn(*args)


def _round_ns(fn, calls, min_seconds):
    """One round: a Python loop over `calls` (argument tuples) lasting at least `min_seconds`; ns per call."""
    n, start = 0, time.perf_counter()
    while True:
        _loop(fn, calls)
        n += len(calls)
        elapsed = time.perf_counter() - start
        if elapsed > min_seconds:
            return elapsed / n * 1e9


def per_call_ns(fn, calls, min_seconds=0.1, rounds=7):
    """Best of `rounds` timings of a Python loop over `calls` (list of argument tuples), each
    lasting at least `min_seconds`.  Many short rounds, like the C loop's 11, so that a host
    busy for a moment slows some rounds and not the best one; a host busy for seconds still
    shows (the Kane call read 66 us with three 0.5 s rounds, 71 us with seven
    0.2 s rounds, against 47-49 us when quiet), which flatters our ratios, never theirs."""
    return min(_round_ns(fn, calls, min_seconds) for _ in range(rounds))


def per_call_ns_interleaved(cases, min_seconds=0.05, rounds=11):
    """`per_call_ns` for several {name: (fn, calls)} whose ratios are reported: their rounds
    alternate, round robin, so that a busy spell of the host slows all of them alike."""
    best = {name: np.inf for name in cases}
    for _ in range(rounds):
        for name, (fn, calls) in cases.items():
            best[name] = min(best[name], _round_ns(fn, calls, min_seconds))
    return best
