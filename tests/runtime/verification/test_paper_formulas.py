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


# -- the factor 2 between the paper's τ, k and physical torque and damping ----------------------
def test_eq_42_pairs_a_unit_rotation_axis_with_itself_to_two():
    """⟨Σ, Σ⟩ = tr(ΣᵀΣ) = 2 for Σ_Y, Σ_P, Σ_C and any unit ⟦e⟧: the origin of the factor."""
    from runtime.so3 import hat
    from runtime.verification.paper_formulas import SIGMA_C, SIGMA_P, SIGMA_Y, pairing
    e = np.array([0.36, -0.48, 0.8])
    assert [pairing(S, S) for S in (SIGMA_Y, SIGMA_P, SIGMA_C, hat(e))] == pytest.approx([2, 2, 2, 2], abs=1e-15)


def test_equal_virtual_work_makes_the_papers_tau_half_the_physical_torque():
    """A torque u about x does u·ε on the rotation εΣ_Y; the paper's τΣ_Y does ⟨τΣ_Y, εΣ_Y⟩ = 2τε."""
    from runtime.verification.paper_formulas import SIGMA_Y, paper_coefficient, pairing
    u, eps = 0.1, 1e-3
    tau = paper_coefficient(u, SIGMA_Y)
    assert pairing(tau * SIGMA_Y, eps * SIGMA_Y) == pytest.approx(u * eps, rel=1e-15)
    assert tau == pytest.approx(u / 2, rel=1e-15)


def papers_power_balance(params, x, tau, k):
    """(dE/dt along the paper's equations with τ, k as printed, ⟨F, Ω⟩ of eq. 42, τ·ω − k·ω²)."""
    from runtime.verification import verify
    from runtime.verification.paper_formulas import pairing
    paper = PaperModel(params)

    class AsPrinted:                      # the paper's equations, its energy and inertia; τ and k as printed
        inertia, energy = paper.inertia, paper.energy

        @staticmethod
        def accel(x, u=None):
            return paper.accel_paper_units(x, tau, k)
    rate = verify.energy_rate(AsPrinted, x, None)
    _, _, _, _, O_S, O_Y, O_P = paper.unpack(x)
    forces = paper.nonconservative(O_S, O_Y, O_P, tau, k)
    paired = sum(pairing(F, O) for F, O in zip(forces, (O_S, O_Y, O_P)))
    w_S, w_Y, w_P = x[30:33], x[33], x[34]
    as_dot_products = tau[0] * w_Y + tau[1] * w_P - k[0] * w_S @ w_S - k[1] * w_Y ** 2 - k[2] * w_P ** 2
    return rate, paired, as_dot_products


def test_the_papers_own_equations_make_tau_deliver_the_power_2_tau_omega(rng):
    """The factor emerges: along eqs. (85)-(105) with τ and k used as printed, and the paper's energy
    (eqs. 32, 100, in joules: it equals the reference's), dE/dt = ⟨F, Ω⟩ = 2τω − 2kω², not τω − kω².
    So the printed τ acts as the physical torque 2τ and the printed k as the physical damping 2k."""
    params = Params.paper()
    for _ in range(5):
        x = random_state(rng, params, max_speed=3.0)
        tau, k = rng.uniform(-0.2, 0.2, size=2), (params.k_S, params.k_Y, params.k_P)
        rate, paired, as_dot_products = papers_power_balance(params, x, tau, k)
        assert rate == pytest.approx(paired, rel=1e-8, abs=1e-10)
        assert paired == pytest.approx(2 * as_dot_products, rel=1e-12)
        assert abs(rate - as_dot_products) > 1e-3 * abs(as_dot_products)


def test_the_factor_check_fails_if_the_paper_pairing_were_the_dot_product(rng, monkeypatch):
    """With ⟨A, B⟩ = ½tr(AᵀB) (the dot product of the axial vectors) in eq. (42) the power would be
    τω − kω²: the test above can tell the two readings apart."""
    from runtime.verification import paper_formulas
    params = Params.paper()
    x = random_state(rng, params, max_speed=3.0)
    tau, k = (0.1, -0.05), (params.k_S, params.k_Y, params.k_P)
    rate, _, as_dot_products = papers_power_balance(params, x, tau, k)
    original = paper_formulas.PaperModel.nonconservative
    monkeypatch.setattr(paper_formulas.PaperModel, "nonconservative",
                        staticmethod(lambda O_S, O_Y, O_P, t, kk: tuple(F / 2 for F in original(O_S, O_Y, O_P, t, kk))))
    rate_dot, _, _ = papers_power_balance(params, x, tau, k)
    assert rate_dot == pytest.approx(as_dot_products, rel=1e-8, abs=1e-10)
    assert abs(rate_dot - rate) > 1e-3 * abs(rate)
