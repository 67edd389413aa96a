"""Every public Python entry point refuses each kind of wrong input by name.

For each entry point, at least one input of every kind it can receive wrong: shape, type,
non-finite, out of range, inconsistent with the model.  Each case names the field the
ValueError must name.  (C's status codes for the same inputs: c/tests/test_status.c.)
"""
import numpy as np
import pytest

from runtime import Model, Params, initial_state, simulate_many
from runtime.model import MAX_STEPS
from runtime.validation import project_state

GOOD = initial_state()
U = np.zeros(2)
ROW_OF_LENGTH_2 = GOOD.copy()
ROW_OF_LENGTH_2[0] = 2.0
OFF_THE_PLANE = GOOD.copy()
OFF_THE_PLANE[29] = 0.25


def model():
    return Model(Params())


CASES = {
    # initial_state
    "initial_state theta_Y inf": (lambda: initial_state(theta_Y=np.inf), "theta_Y"),
    "initial_state theta_P nan": (lambda: initial_state(theta_P=np.nan), "theta_P"),
    "initial_state w_Y a string": (lambda: initial_state(w_Y="1"), "w_Y"),
    "initial_state w_P a bool": (lambda: initial_state(w_P=True), "w_P"),
    "initial_state R_S = 2 I": (lambda: initial_state(R_S=2 * np.eye(3)), "R_S"),
    "initial_state R_S a reflection": (lambda: initial_state(R_S=np.diag([1.0, 1.0, -1.0])), "R_S"),
    "initial_state R_S of shape (2, 2)": (lambda: initial_state(R_S=np.eye(2)), "R_S"),
    "initial_state R_S complex": (lambda: initial_state(R_S=np.eye(3) * (1 + 0j)), "R_S"),
    "initial_state R_S with nan": (lambda: initial_state(R_S=np.full((3, 3), np.nan)), "R_S"),
    "initial_state w_S of shape (2,)": (lambda: initial_state(w_S=(1.0, 2.0)), "w_S"),
    "initial_state w_S with inf": (lambda: initial_state(w_S=(1.0, np.inf, 0.0)), "w_S"),
    "initial_state q off the plane": (lambda: initial_state(q=(0.0, 0.0, 0.0)), "q"),
    "initial_state q of shape (2,)": (lambda: initial_state(q=(0.0, 0.3)), "q"),
    "initial_state r negative": (lambda: initial_state(r=-0.3), "r"),
    "initial_state r nan": (lambda: initial_state(r=np.nan), "r"),
    # Params and Model
    "Params a string": (lambda: Params(m_S="2"), "Params.m_S"),
    "Params nan": (lambda: Params(g=np.nan), "Params.g"),
    "Params negative mass": (lambda: Params(m_P=-1.0), "Params.m_P"),
    "Params pendulum longer than r": (lambda: Params.paper(l=0.5), "Params.l"),
    "Model not a Params": (lambda: Model({"r": 0.3}), "params"),
    "Model params that overflow": (lambda: Model(Params().replace(r=1e200, j_S=1e200)), "params"),
    "Params paper values that overflow": (lambda: Params.paper(r=1e200, b=1e200, h=1e200, l=1e200), "Params"),
    "Params a tensor that no body has": (lambda: Params(J_P=[[0.1, 0, 0], [0, 0.1, 0], [0, 0, 0.3]]), "Params.J_P"),
    "Params a centre of mass outside the shell": (lambda: Params(c_Y=[0.0, 0.0, 0.4]), "Params.c_Y"),
    "Params a slope beyond pi/2": (lambda: Params(slope=2.0), "Params.slope"),
    "Params a centre of the wrong shape": (lambda: Params(c_P=[0.0, -0.1]), "Params.c_P"),
    # the single-state kernels and step
    "accel x of shape (34,)": (lambda: model().accel(np.zeros(34)), "x"),
    "accel x of strings": (lambda: model().accel(np.array(["a"] * 35)), "x"),
    "accel x with nan": (lambda: model().accel(np.full(35, np.nan)), "x"),
    "accel R_S row of length 2": (lambda: model().accel(ROW_OF_LENGTH_2), "x"),
    "accel q_z off the plane": (lambda: model().accel(OFF_THE_PLANE), "x"),
    "accel u of shape (3,)": (lambda: model().accel(GOOD, np.zeros(3)), "u"),
    "accel u with inf": (lambda: model().accel(GOOD, [np.inf, 0.0]), "u"),
    "inertia batch given": (lambda: model().inertia(np.tile(GOOD, (2, 1))), "x"),
    "energy R_S row of length 2": (lambda: model().energy(ROW_OF_LENGTH_2), "x"),
    "rhs u complex": (lambda: model().rhs(GOOD, np.zeros(2, complex)), "u"),
    "equilibrium_residual nan": (lambda: model().equilibrium_residual(np.full(35, np.nan)), "x"),
    "step R_S row of length 2": (lambda: model().step(ROW_OF_LENGTH_2), "x"),
    "step dt negative": (lambda: model().step(GOOD, dt=-0.01), "dt"),
    "step dt nan": (lambda: model().step(GOOD, dt=np.nan), "dt"),
    "step dt a string": (lambda: model().step(GOOD, dt="0.01"), "dt"),
    "step unknown method": (lambda: model().step(GOOD, method="rk45"), "method"),
    # simulate
    "simulate 10^12 steps": (lambda: model().simulate(GOOD, 0.01, 10 ** 12), "steps"),
    "simulate MAX_STEPS + 1 steps": (lambda: model().simulate(GOOD, 0.01, MAX_STEPS + 1), "steps"),
    "simulate negative steps": (lambda: model().simulate(GOOD, 0.01, -1), "steps"),
    "simulate steps a float": (lambda: model().simulate(GOOD, 0.01, 10.0), "steps"),
    "simulate x0 off the plane": (lambda: model().simulate(OFF_THE_PLANE, 0.01, 10), "x0"),
    "simulate u of the wrong length": (lambda: model().simulate(GOOD, 0.01, 10, u=np.zeros((9, 2))), "u"),
    "simulate u with nan": (lambda: model().simulate(GOOD, 0.01, 2, u=[[0.0, 0.0], [np.nan, 0.0]]), "u"),
    "simulate energy_tol negative": (lambda: model().simulate(GOOD, 0.01, 10, energy_tol=-1.0), "energy_tol"),
    # simulate_adaptive
    "adaptive t_end beyond MAX_STEPS rows": (lambda: model().simulate_adaptive(GOOD, 1e12, 0.01), "t_end"),
    "adaptive t_end not a multiple": (lambda: model().simulate_adaptive(GOOD, 1.005, 0.01), "t_end"),
    "adaptive rtol nan": (lambda: model().simulate_adaptive(GOOD, 1.0, 0.01, rtol=np.nan), "rtol"),
    "adaptive x0 row of length 2": (lambda: model().simulate_adaptive(ROW_OF_LENGTH_2, 1.0, 0.01), "x0"),
    "adaptive lie-euler": (lambda: model().simulate_adaptive(GOOD, 1.0, 0.01, method="lie-euler"), "method"),
    # simulate_many
    "simulate_many 10^12 steps": (lambda: simulate_many(Params(), GOOD, 0.01, 10 ** 12), "steps"),
    "simulate_many x0 of shape (34,)": (lambda: simulate_many(Params(), np.zeros(34), 0.01, 10), "x0"),
    "simulate_many dt zero": (lambda: simulate_many(Params(), GOOD, 0.0, 10), "dt"),
    # project_state
    "project_state nan": (lambda: project_state(np.full(35, np.nan), 0.3), "x"),
    "project_state r negative": (lambda: project_state(GOOD, -1.0), "r"),
    "project_state shape (3,)": (lambda: project_state(np.zeros(3), 0.3), "x"),
}


@pytest.mark.parametrize("case", CASES, ids=list(CASES))
def test_bad_input_raises_a_value_error_naming_the_field(case):
    call, field = CASES[case]
    with pytest.raises(ValueError) as excinfo:
        call()
    assert str(excinfo.value).startswith(field), str(excinfo.value)


def test_initial_state_accepts_a_rotation_within_the_c_tolerance_and_flat_R_S():
    R = np.eye(3)
    R[0, 0] += 1e-8
    assert np.array_equal(initial_state(R_S=R.ravel())[:9], R.ravel())


def test_initial_state_q_with_q_z_equal_to_r_is_kept():
    assert np.array_equal(initial_state(q=(1.0, -2.0, 0.5), r=0.5)[27:30], [1.0, -2.0, 0.5])
