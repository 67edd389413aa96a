"""Numbers before times: every kernel's and every alternative's output is compared before its time counts."""
import numpy as np


class WrongNumbers(RuntimeError):
    pass


def check_close(name, ours, theirs, rtol):
    ours, theirs = np.asarray(ours, dtype=float), np.asarray(theirs, dtype=float)
    err = np.abs(ours - theirs).max() / max(np.abs(theirs).max(), 1e-300)
    if not err <= rtol:
        raise WrongNumbers(f"{name}: relative difference {err:.3g} > {rtol:g}")
    return float(err)
