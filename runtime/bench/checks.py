"""Numbers before times: every kernel's and every alternative's output is compared before its time counts."""
import numpy as np


class WrongNumbers(RuntimeError):
    """A benchmarked path gave numbers that differ from the reference's: its timing would mean nothing."""
    pass


def check_close(name, ours, theirs, rtol):
    """The relative max-difference of `ours` from `theirs`; raises WrongNumbers when it exceeds `rtol`."""
    ours, theirs = np.asarray(ours, dtype=float), np.asarray(theirs, dtype=float)
    err = np.abs(ours - theirs).max() / max(np.abs(theirs).max(), 1e-300)
    if not err <= rtol:
        raise WrongNumbers(f"{name}: relative difference {err:.3g} > {rtol:g}")
    return float(err)
