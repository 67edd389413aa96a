"""The paper's matrix formulas (NumPy transcription) agree with the kernels once corrected, and not as printed."""
import dataclasses

import numpy as np
import pytest

from runtime import Model, Params
from runtime.verification.errata import relative_error
from runtime.verification.paper_formulas import Errata, PaperModel
from runtime.verification.sampling import random_inputs, random_params, random_state


@pytest.fixture(scope="module", params=[0, 1, 2])
def setup(request):
    rng = np.random.default_rng(request.param)
    params = Params.paper_simulation() if request.param == 0 else random_params(rng)
    states = [(random_state(rng, params), random_inputs(rng, 1)[0]) for _ in range(100)]
    return Model(params), PaperModel(params), states, params


def test_appendix_c_matrix_equals_the_generated_inertia(setup):
    model, paper, states, _ = setup
    assert max(relative_error(paper.inertia(x), model.inertia(x)) for x, _ in states) < 1e-13


def test_corrected_paper_equations_give_the_generated_accel(setup):
    model, paper, states, _ = setup
    assert max(relative_error(paper.accel(x, u), model.accel(x, u)) for x, u in states) < 1e-12


def test_corrected_paper_energy_equals_the_generated_energy(setup):
    model, paper, states, _ = setup
    assert max(relative_error(paper.energy(x), model.energy(x)) for x, _ in states) < 1e-13


@pytest.mark.parametrize("erratum, quantity", [
    ("eq31_mass", "energy"), ("eq71_gamma", "accel"), ("eq102_Jdot", "accel"), ("eq105_minus_J", "accel")])
def test_each_printed_form_disagrees_with_the_kernel(setup, erratum, quantity):
    model, _, states, params = setup
    printed = PaperModel(params, dataclasses.replace(Errata(), **{erratum: True}))
    if quantity == "energy":
        err = max(relative_error(printed.energy(x), model.energy(x)) for x, _ in states)
    else:
        err = max(relative_error(printed.accel(x, u), model.accel(x, u)) for x, u in states)
    assert err > 1e-2
