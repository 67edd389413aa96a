"""The memory a run needs, estimated before it allocates anything, against a budget.

Every application sizes its largest arrays from its inputs (a scenario's trajectory, a control
task's path table and NMPC problem, a sweep's per-task arrays and result table) and calls
`check` before the run starts: a run that cannot fit is refused with `MemoryBudgetExceeded`
(a ValueError naming the file and what is large), never a MemoryError or a machine that swaps.

The budget: `SR_MEMORY_FRACTION` (default 0.5) of the memory available when the run starts
(MemAvailable of /proc/meminfo; the physical memory where that is not readable).
"""
import os

#: The fraction of the available memory a run may plan to use (environment: SR_MEMORY_FRACTION).
DEFAULT_FRACTION = 0.5
#: Bytes of one state row (35 float64).
STATE_ROW_BYTES = 35 * 8


class MemoryBudgetExceeded(ValueError):
    """A run whose estimated memory exceeds the budget; `.needed` and `.budget` in bytes."""

    def __init__(self, message, needed, budget):
        super().__init__(message)
        self.needed, self.budget = needed, budget


def available_bytes():
    """The memory available to a new run [bytes]."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")


def fraction():
    """The budget's fraction of the available memory: SR_MEMORY_FRACTION, default DEFAULT_FRACTION."""
    text = os.environ.get("SR_MEMORY_FRACTION")
    if text is None:
        return DEFAULT_FRACTION
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not 0 < value <= 1:
        raise ValueError(f"SR_MEMORY_FRACTION: expected a number in (0, 1], got {text!r}")
    return value


def budget_bytes():
    """The memory a run may plan to use [bytes]."""
    return int(fraction() * available_bytes())


def gib(n):
    """`n` bytes as text in GiB (or MiB below one GiB)."""
    return f"{n / 2**30:.3g} GiB" if n >= 2**30 else f"{n / 2**20:.3g} MiB"


def check(where, parts, budget=None):
    """The total of `parts` ({what: bytes}) if it fits `budget` (default `budget_bytes()`);
    otherwise MemoryBudgetExceeded("<where>: ...") naming the total, the largest parts and the budget."""
    needed = int(sum(parts.values()))
    source = f" (SR_MEMORY_FRACTION = {fraction():g} of the memory available)" if budget is None else ""
    budget = budget_bytes() if budget is None else int(budget)
    if needed > budget:
        largest = sorted(parts.items(), key=lambda item: -item[1])[:3]
        detail = ", ".join(f"{what} {gib(n)}" for what, n in largest if n > 0)
        raise MemoryBudgetExceeded(
            f"{where}: the run needs about {gib(needed)} ({detail}), more than the memory budget of "
            f"{gib(budget)}{source}; shorten the run or raise SR_MEMORY_FRACTION", needed, budget)
    return needed


def trajectory_bytes(steps):
    """A simulation's rows: states (steps+1, 35), torques (steps+1, 2) twice, energy (steps+1,)."""
    return (steps + 1) * (STATE_ROW_BYTES + 2 * 2 * 8 + 8)
