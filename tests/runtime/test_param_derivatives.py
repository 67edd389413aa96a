"""Model.param_jacobian, Model.step_param_jacobian and Model.regressor (runtime/param_derivatives.py):
shapes and batches, the regressor form against the kernels, and the base parameters of the robot.
Their accuracy against AD and differences: tests/runtime/verification/test_param_jacobians.py."""
import numpy as np
import pytest

from runtime import Model, Params
from runtime.param_derivatives import (NPARAM, NPI, PARAMETER_NAMES, PI_NAMES, base_parameters, inertial_parameters,
                                      trajectory_sensitivities)
from runtime.state import IDX_Q, NE, NV
from runtime.verification.sampling import random_general_params, random_inputs, random_state

RNG = np.random.default_rng(38)
GENERAL = random_general_params(RNG)


def states(model, n, seed=0):
    rng = np.random.default_rng(seed)
    return np.array([random_state(rng, model.params, max_speed=3.0) for _ in range(n)]), random_inputs(rng, n)


def test_parameter_names_follow_the_c_parameter_vector():
    p = GENERAL.as_array()
    assert len(PARAMETER_NAMES) == NPARAM == p.size
    assert p[PARAMETER_NAMES.index("J_Y_xy")] == np.asarray(GENERAL.J_Y)[0, 1]
    assert p[PARAMETER_NAMES.index("c_P_z")] == GENERAL.c_P[2]


@pytest.mark.parametrize("params", [Params.paper_simulation(), GENERAL], ids=["paper", "general"])
def test_param_jacobian_of_a_batch_is_that_of_each_state(params):
    model = Model(params)
    X, U = states(model, 3)
    J = model.param_jacobian(X, U)
    assert J.shape == (3, NV, NPARAM)
    for i in range(3):
        np.testing.assert_array_equal(J[i], model.param_jacobian(X[i], U[i]))


def test_the_param_jacobian_does_not_depend_on_where_the_robot_stands():
    """q enters no dynamics, so no column of dν̇/dp depends on q_x, q_y."""
    model = Model(GENERAL)
    x, u = states(model, 1)
    moved = x[0].copy()
    moved[IDX_Q.start:IDX_Q.start + 2] += (3.0, -2.0)
    np.testing.assert_array_equal(model.param_jacobian(x[0], u[0]), model.param_jacobian(moved, u[0]))


@pytest.mark.parametrize("method", ["lie-euler", "rkmk4"])
def test_step_param_jacobian_of_a_batch_is_that_of_each_state(method):
    model = Model(GENERAL)
    X, U = states(model, 3, seed=1)
    J = model.step_param_jacobian(X, U, 0.01, method)
    assert J.shape == (3, NE, NPARAM)
    for i in range(3):
        np.testing.assert_array_equal(J[i], model.step_param_jacobian(X[i], U[i], 0.01, method))


def test_the_lie_euler_step_moves_with_the_parameters_only_through_nu_and_the_rolling():
    """x_new = x · exp(h f(x)): the attitude and the joint angles move with ω alone, which the
    parameters do not change within one step; ν moves by h ∂ν̇/∂p."""
    model = Model(GENERAL)
    x, u = states(model, 1, seed=2)
    J = model.step_param_jacobian(x[0], u[0], 0.02, "lie-euler")
    assert not J[:5].any()
    np.testing.assert_allclose(J[7:], 0.02 * model.param_jacobian(x[0], u[0]), rtol=1e-14, atol=0)


def test_step_param_jacobian_names_a_method_without_one():
    with pytest.raises(ValueError, match="method"):
        Model().step_param_jacobian(random_state(RNG), None, 0.01, "cf4")


@pytest.mark.parametrize("name", ["k_P", "c_P_z", "j_mY"])
def test_chained_sensitivities_of_a_trajectory_are_central_differences_in_the_parameter(name):
    """S_n of 20 RKMK4 steps against the difference of the end states of two runs of the robots
    p ± h e_k (step 1e-4 relative: error ~1e-8 of the column)."""
    model = Model(GENERAL)
    x0, U = states(model, 1, seed=4)
    u = np.tile(U[0], (20, 1))
    X, S, Phi = trajectory_sensitivities(model, x0[0], 0.01, 20, u)
    k = PARAMETER_NAMES.index(name)
    p0 = GENERAL.as_array()
    h = 1e-4 * abs(p0[k])
    ends = []
    for sign in (1, -1):
        p = p0.copy()
        p[k] += sign * h
        ends.append(Model(Params.from_array(p)).simulate(x0[0], 0.01, 20, u=u, method="rkmk4")[-1])
    column = (model.local(X[-1], ends[0]) - model.local(X[-1], ends[1])) / (2 * h)
    np.testing.assert_allclose(S[-1][:, k], column, rtol=0, atol=1e-6 * np.abs(column).max())
    assert not np.allclose(S[-1][:, k], 0) and Phi.shape == (21, NE, NE)


@pytest.mark.parametrize("seed", range(4))
def test_the_regressor_times_the_inertial_parameters_is_m_nudot_minus_f(seed):
    """Y(x, ν̇) π = M ν̇ − f(x, u = 0) on random states and accelerations of random robots."""
    rng = np.random.default_rng(100 + seed)
    params = random_general_params(rng) if seed else Params.paper_simulation()
    model = Model(params)
    X = np.array([random_state(rng, params) for _ in range(5)])
    A = rng.uniform(-10, 10, size=(5, NV))
    pi = inertial_parameters(params)
    for x, a, Y in zip(X, A, model.regressor(X, A)):
        expected = model.inertia(x) @ a - model.rhs(x, None)
        assert np.abs(Y @ pi - expected).max() <= 1e-12 * np.abs(expected).max()


def test_along_a_motion_the_regressor_gives_the_applied_torques():
    model = Model(GENERAL)
    X, U = states(model, 4, seed=3)
    pi = inertial_parameters(GENERAL)
    for x, u in zip(X, U):
        forces = model.regressor(x, model.accel(x, u)) @ pi
        np.testing.assert_allclose(forces, [0, 0, 0, *u], atol=1e-12 * max(1.0, np.abs(forces).max()))


def test_the_regressor_names_a_non_finite_acceleration():
    with pytest.raises(ValueError, match="nudot"):
        Model().regressor(random_state(RNG), [0.0, np.nan, 0.0, 0.0, 0.0])


def test_the_regressor_names_accelerations_of_the_wrong_shape():
    with pytest.raises(ValueError, match="nudot"):
        Model().regressor(np.tile(random_state(RNG), (2, 1)), np.zeros((3, NV)))


def unit(*names, weights=None):
    c = np.zeros(NPI)
    for name, w in zip(names, weights or [1.0] * len(names)):
        c[PI_NAMES.index(name)] = w
    return c


@pytest.fixture(scope="module")
def geared():
    """A general robot with a geared yoke motor (n_Y = 60), as in the battery-geared build."""
    return base_parameters(Model(GENERAL.replace(n_Y=60.0)), n_states=40)


@pytest.fixture(scope="module")
def direct():
    """The same robot with its yoke motor's rotor turning with the joint (n_Y = 1)."""
    return base_parameters(Model(GENERAL.replace(n_Y=1.0)), n_states=40)


def test_the_total_mass_is_identifiable_and_each_mass_alone_is_not(geared):
    assert geared.identifiable(unit("m_S", "m_Y", "m_P"))
    assert not any(geared.identifiable(unit(m)) for m in ("m_S", "m_Y", "m_P"))


def test_the_dampings_and_the_first_moments_across_the_pendulum_axis_are_identifiable(geared):
    names = ["mc_Y_x", "mc_Y_z", "mc_P_x", "mc_P_z", "k_S", "k_Y", "k_P"]
    assert all(geared.identifiable(unit(n)) for n in names)


def test_the_first_moments_along_the_pendulum_axis_are_seen_only_together(geared):
    """The pendulum's hinge axis is the yoke's y axis: a first moment along it turns with the yoke
    whichever body carries it."""
    assert geared.identifiable(unit("mc_Y_y", "mc_P_y"))
    assert not geared.identifiable(unit("mc_Y_y")) and not geared.identifiable(unit("mc_P_y"))


def test_the_inertia_about_each_hinge_axis_is_identifiable(geared):
    assert geared.identifiable(unit("JO_P_yy")) and geared.identifiable(unit("JO_Y_xx", "JO_P_zz"))


def test_a_rotor_turning_with_its_joint_is_seen_only_inside_the_yoke_axis_inertia(direct):
    assert geared_free(direct)


def geared_free(base):
    return (base.identifiable(unit("JO_Y_xx", "JO_P_zz", "j_mY"))
            and not base.identifiable(unit("j_mY")))


def test_a_geared_rotor_separates_from_the_yoke(geared):
    """With n_Y ≠ ±1 the rotor's ½ j_mY (ω_Sx + n_Y ω_Y)² differs from the yoke's ½ J (ω_Sx + ω_Y)²:
    j_mY is identifiable on its own (through terms 1/n and 1/n² of the reflected n² j_mY)."""
    assert geared.identifiable(unit("j_mY"))


def test_the_identifiability_check_refuses_a_wrongly_weighted_combination(direct):
    """The check can fail: the rotor counted twice in the yoke's axis inertia."""
    assert not direct.identifiable(unit("JO_Y_xx", "JO_P_zz", "j_mY", weights=[1.0, 1.0, 2.0]))


def test_base_parameter_values_are_a_linear_image_of_pi(geared):
    pi = inertial_parameters(GENERAL.replace(n_Y=60.0))
    values = geared.values(pi)
    assert values.shape == (geared.rank,) and len(geared.names()) == geared.rank
    assert geared.rank < NPI


def _same_base(a, b):
    return (a.independent == b.independent and a.dependent == b.dependent
            and np.array_equal(a.combination, b.combination) and np.array_equal(a.null_space, b.null_space))


def test_robots_that_agree_in_the_regressors_entries_have_the_same_base_parameters():
    """What lets `base_parameters` keep its result per REGRESSOR_ENTRIES: computed afresh for a robot
    with every other entry moved, the base parameters are the same to the bit."""
    from runtime.param_derivatives import REGRESSOR_ENTRIES, _base_parameters

    geared = Model(GENERAL.replace(n_Y=60.0))
    p = geared.params.as_array()
    moved = np.array([n not in REGRESSOR_ENTRIES and n[:2] in ("m_", "c_", "k_", "j_") for n in PARAMETER_NAMES])
    other = Model(Params.from_array(p * np.where(moved, 1.2, 1.0)))
    assert _same_base(_base_parameters(geared, 60, 0, 1e-9), _base_parameters(other, 60, 0, 1e-9))


def test_the_same_base_check_tells_robots_apart_that_differ_in_a_regressor_entry():
    from runtime.param_derivatives import _base_parameters

    geared = Model(GENERAL.replace(n_Y=60.0))
    other = Model(geared.params.replace(r=geared.params.r * 1.01))
    assert not _same_base(_base_parameters(geared, 60, 0, 1e-9), _base_parameters(other, 60, 0, 1e-9))


def test_the_kept_base_parameters_are_those_of_the_robot_asked_for():
    from runtime.param_derivatives import _base_parameters

    geared = Model(GENERAL.replace(n_Y=60.0))
    other = Model(geared.params.replace(n_Y=geared.params.n_Y * 2))
    base_parameters(geared)
    assert _same_base(base_parameters(other), _base_parameters(other, 60, 0, 1e-9))
    assert base_parameters(geared).combination.flags.writeable is False
