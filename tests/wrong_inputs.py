"""Hypothesis strategies of wrong input, and the contract every public entry point keeps on it
(docs/robustness.md): a ValueError whose message starts with the name of the argument, or a
result that is finite, never another exception and never a NaN."""
import re

import numpy as np
from hypothesis import HealthCheck, settings
from hypothesis import strategies as st

#: Few examples, each bounded: the suite is a guard, not a search (about a minute on 2 cores).
#: deadline only reports a case that ran far too long (a hang stays a hang, but never passes).
SETTINGS = settings(max_examples=40, deadline=10_000,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])

WRONG_TYPES = ["0.01", "abc", b"\xff", {"a": 1}, object(), 1j, [1, "a"], [[1, 2], [3]]]
"""Values of the wrong type for any numeric argument (None is left out: some arguments take it)."""
NONFINITE = [np.nan, np.inf, -np.inf]
HUGE = [1e308, -1e308, 1.7e308, 1e300, 2.0 ** 1000]

#: Kinds of wrong value that must be refused; "huge" (finite, overflow-size) may also be computed,
#: with a finite result.
MUST_FAIL = {"type", "dtype", "shape", "nonfinite", "name"}


def wrong_array(base, draw):
    """(kind, value): `base` (a valid array) made wrong in one way."""
    base = np.asarray(base, dtype=float)
    kind = draw(st.sampled_from(["type", "dtype", "shape", "nonfinite", "huge"]))
    if kind == "type":
        return kind, draw(st.sampled_from(WRONG_TYPES))
    if kind == "dtype":
        return kind, draw(st.sampled_from([base.astype(complex), base.astype(bool), base.astype(str),
                                           np.atleast_1d(base).astype(object).tolist() + ["x"]]))
    if kind == "shape":
        shape = tuple(draw(st.lists(st.integers(0, 40), min_size=0, max_size=3)))
        tail = base.shape[-1:] if base.ndim else ()
        if shape[-1:] == tail and len(shape) <= base.ndim + 1 and shape:
            shape = shape[:-1] + (shape[-1] + 1,)     # never a valid (B, n) batch
        return kind, np.zeros(shape)
    value = base.copy()
    index = draw(st.integers(0, max(value.size - 1, 0)))
    if value.size:
        value.flat[index] = draw(st.sampled_from(NONFINITE if kind == "nonfinite" else HUGE))
    else:
        value = np.full(1, np.nan)
    return kind, value


def wrong_scalar(draw, allow_zero=False):
    kind = draw(st.sampled_from(["type", "nonfinite", "huge", "negative"]))
    if kind == "type":
        return "type", draw(st.sampled_from(WRONG_TYPES + [True, np.array([0.01, 0.02])]))
    if kind == "nonfinite":
        return kind, draw(st.sampled_from(NONFINITE))
    if kind == "huge":
        return kind, draw(st.sampled_from(HUGE[:3]))
    return "nonfinite", draw(st.sampled_from([-1.0, -1e-300] + ([] if allow_zero else [0.0])))


def wrong_name(draw):
    return "name", draw(st.one_of(st.text(max_size=12).filter(lambda s: s not in KNOWN_NAMES),
                                  st.sampled_from([None, ["rkmk4"], ("rkmk4",), {"rkmk4": 1}, 1, b"rkmk4",
                                                   "RKMK4", " rkmk4"])))


KNOWN_NAMES = {"lie-euler", "rkmk4", "cf4", "rkmk4-projected", "cf4-projected",
               "sr_accel", "sr_step_lie_euler", "sr_step_rkmk4", "sr_step_cf4"}


def names_argument(message, names):
    """Whether `message` starts with one of `names`, possibly indexed ("x[3]: ...", "Params.J_Y: ...")."""
    return any(re.match(rf"{re.escape(n)}(\[[^\]]*\])?( \([^)]*\))?: ", message) for n in names)


def all_finite(result):
    if isinstance(result, (tuple, list)):
        return all(all_finite(r) for r in result)
    if isinstance(result, dict):
        return all(all_finite(r) for r in result.values())
    if isinstance(result, np.ndarray) or isinstance(result, (float, int)):
        return bool(np.all(np.isfinite(result)))
    return True


def keeps_contract(call, kind, names):
    """Run `call`; a ValueError must name one of `names`; success is allowed only when `kind` is not
    one that must fail, and then every number returned must be finite.  Anything else propagates."""
    try:
        result = call()
    except ValueError as exc:
        assert names_argument(str(exc), names), f"{kind}: the message does not name {names}: {exc}"
        assert "\n" not in str(exc).strip(), f"a one-line message expected: {exc}"
        return None
    assert kind not in MUST_FAIL, f"{kind}: accepted, returned {result!r}"
    assert all_finite(result), f"{kind}: a non-finite result {result!r}"
    return result
