"""Evidence for docs/errata.md: each printed formula against its corrected form, at random states.

`python -m runtime errata [--states N] [--seed S]` prints a markdown table: for
every erratum, the worst relative error against the kernel (and, where it
exists, the independent CasADi reference) with the printed form and with the
corrected one.
"""
import argparse
import dataclasses

import numpy as np

from ..model import Model
from ..params import Params
from ..so3 import hat
from ..state import IDX_WS, gamma, rotations
from .paper_formulas import Errata, PaperModel
from .sampling import random_inputs, random_state


def relative_error(a, b):
    """max |a - b| / max |b|."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return float(np.abs(a - b).max() / max(np.abs(b).max(), 1e-300))


def worst(pairs):
    """The largest relative_error over the pairs (a, b)."""
    return max(relative_error(a, b) for a, b in pairs)


def accel_errors(model, paper, states):
    """The worst relative error of the paper formulas' accelerations against the model's over the states."""
    return worst((paper.accel(x, u), model.accel(x, u)) for x, u in states)


def energy_errors(model, paper, states):
    """The worst relative error of the paper formulas' energy against the model's over the states."""
    return worst((paper.energy(x), model.energy(x)) for x, _ in states)


def norm_errors(states, r):
    """Eq. (34): ½ m_R‖Ṙ_Sᵀ q̇‖² written for ½ m_R‖R_Sᵀ q̇‖² = ½ m_R‖q̇‖²."""
    out = []
    for x, _ in states:
        R_S, w = rotations(x)[0], x[IDX_WS]
        q_dot = r * R_S @ np.cross(w, gamma(x))
        printed = (R_S @ hat(w)).T @ q_dot
        out.append((printed @ printed, q_dot @ q_dot))
    return worst(out)


def diamond_sign_errors(rng, n):
    """Eq. (55): ⟦a×b⟧ = abᵀ − baᵀ as printed; the identity holds for baᵀ − abᵀ."""
    printed, corrected = [], []
    for _ in range(n):
        a, b = rng.normal(size=3), rng.normal(size=3)
        printed.append((np.outer(a, b) - np.outer(b, a), hat(np.cross(a, b))))
        corrected.append((np.outer(b, a) - np.outer(a, b), hat(np.cross(a, b))))
    return worst(printed), worst(corrected)


def evidence(n_states=200, seed=0):
    """Rows (equation, quantity, error printed, error corrected); None where a column does not apply."""
    rng = np.random.default_rng(seed)
    params = Params.paper_simulation()
    model = Model(params)
    states = [(random_state(rng, params), random_inputs(rng, 1)[0]) for _ in range(n_states)]
    corrected = PaperModel(params)
    rows = []
    for field, equation, quantity, measure in [
        ("eq31_mass", "(31)", "energy", energy_errors),
        ("eq71_gamma", "(71)", "accel", accel_errors),
        ("eq102_Jdot", "(102)-(103)", "accel", accel_errors),
        ("eq105_minus_J", "(105), (110)", "accel", accel_errors),
    ]:
        printed = PaperModel(params, dataclasses.replace(Errata(), **{field: True}))
        rows.append((equation, quantity, measure(model, printed, states), measure(model, corrected, states)))
    rows.append(("(34)", "translational energy", norm_errors(states, params.r), None))
    rows.append(("(55)", "⟦a×b⟧", *diamond_sign_errors(rng, n_states)))
    rows.append(("(87)-(99), App. C (no erratum)", "M", None, worst((corrected.inertia(x), model.inertia(x)) for x, _ in states)))
    rows.append(("(85)-(95), (105) all corrected", "accel", None, accel_errors(model, corrected, states)))
    return rows


def main(argv=None):
    """Prints the errata's evidence as a Markdown table."""
    parser = argparse.ArgumentParser(prog="python -m runtime errata", description=__doc__.splitlines()[0])
    parser.add_argument("--states", type=int, default=200)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    print("| equation | quantity | worst rel. error, printed | worst rel. error, corrected |")
    print("|---|---|---|---|")
    for equation, quantity, printed, corrected in evidence(args.states, args.seed):
        cells = ["—" if v is None else f"{v:.2e}" for v in (printed, corrected)]
        print(f"| {equation} | {quantity} | {cells[0]} | {cells[1]} |")
    return 0
