"""runtime.simulate_many / sr_simulate_batch: many robots in one C call, one status per sample."""
import ctypes
import threading

import numpy as np
import pytest

import bindings._sr
from bindings._sr import lib
from runtime import Model, Params, initial_state, simulate_many
from runtime.batch import METRIC_NAMES
from runtime.model import CHUNK_STEPS
from runtime.state import IDX_Q, IDX_QZ, IDX_WS, NX

STEPS = CHUNK_STEPS + 300     # crosses a chunk boundary: the energy guard and Kahan sums restart there


def samples(n, rng, steps=STEPS):
    """n different robots: parameters, initial states and torque programs all vary."""
    params = [Params.paper_simulation(m_P=rng.uniform(0.8, 1.2), k_S=rng.uniform(0.1, 0.2)) for _ in range(n)]
    x0 = np.stack([initial_state(theta_Y=rng.uniform(-1, 1), theta_P=rng.uniform(-1, 1),
                                 w_S=rng.uniform(-1, 1, 3)) for _ in range(n)])
    u = rng.uniform(-0.1, 0.1, (n, steps, 2))
    return params, x0, u


@pytest.mark.parametrize("method", ["lie-euler", "rkmk4", "cf4-projected"])
def test_every_sample_equals_model_simulate_bit_for_bit(method, rng):
    params, x0, u = samples(3, rng)
    result = simulate_many(params, x0, 0.01, STEPS, u, method=method, trajectories=True)
    assert result.ok.all()
    for i in range(3):
        alone = Model(params[i]).simulate(x0[i], 0.01, STEPS, u[i], method=method)
        assert np.array_equal(result.trajectories[i], alone)
        assert np.array_equal(result.final[i], alone[-1])


def test_the_bit_for_bit_comparison_sees_a_one_ulp_change_of_one_parameter(rng):
    params, x0, u = samples(1, rng)
    nudged = params[0].with_changes(m_P=np.nextafter(params[0].m_P, 2.0))
    result = simulate_many(params, x0, 0.01, STEPS, u)
    assert not np.array_equal(result.final[0], Model(nudged).simulate(x0[0], 0.01, STEPS, u[0])[-1])


def test_final_states_without_trajectories_equal_the_last_rows_of_the_trajectories(rng):
    params, x0, u = samples(3, rng)
    finals = simulate_many(params, x0, 0.01, STEPS, u, method="rkmk4")
    full = simulate_many(params, x0, 0.01, STEPS, u, method="rkmk4", trajectories=True)
    assert finals.trajectories is None
    assert np.array_equal(finals.final, full.trajectories[:, -1])
    for name in METRIC_NAMES:
        assert np.array_equal(finals.metrics[name], full.metrics[name])


def test_metrics_equal_numpy_on_the_trajectories(rng):
    params, x0, u = samples(3, rng)
    result = simulate_many(params, x0, 0.01, STEPS, u, trajectories=True)
    for i, traj in enumerate(result.trajectories):
        q, w = traj[:, IDX_Q], traj[:, IDX_WS]
        expected = {"path_length": np.linalg.norm(np.diff(q, axis=0), axis=1).sum(),
                    "max_distance": np.linalg.norm(q - q[0], axis=1).max(),
                    "max_shell_rate": np.linalg.norm(w, axis=1).max(),
                    "final_energy": Model(params[i]).energy(traj[-1])}
        for name, value in expected.items():
            assert result.metrics[name][i] == pytest.approx(value, rel=1e-12), name


def test_shared_arguments_equal_the_same_values_repeated(rng):
    params, x0, u = samples(1, rng)
    shared = simulate_many(params[0], x0[0], 0.01, 500, u[0, :500])
    explicit = simulate_many(params * 3, np.repeat(x0, 3, 0), 0.01, 500, np.repeat(u[:, :500], 3, 0))
    assert shared.final.shape == (1, NX)
    assert np.array_equal(np.repeat(shared.final, 3, 0), explicit.final)


def test_a_bad_sample_fails_alone_with_its_status(rng):
    params, x0, u = samples(5, rng, steps=300)
    p = np.stack([q.as_array() for q in params])
    p[1, lib.SR_P_m_P] = -1.0          # m_P < 0
    x0[2, 0] = np.nan                               # non-finite initial state
    x0[3, IDX_QZ] *= 1.01                           # q_z != r
    u[4, 99, 0] = np.inf                            # a bad torque at step 100
    result = simulate_many(p, x0, 0.01, 300, u, trajectories=True)
    assert result.status.tolist() == [lib.SR_OK, lib.SR_ERR_PARAM, lib.SR_ERR_NONFINITE,
                                      lib.SR_ERR_CONSTRAINT, lib.SR_ERR_NONFINITE]
    assert result.steps_done.tolist() == [300, 0, 0, 0, 99]
    assert np.isnan(result.final[1:]).all() and np.isnan(result.metrics["path_length"][1:]).all()
    alone = simulate_many(p[:1], x0[:1], 0.01, 300, u[:1], trajectories=True)
    assert np.array_equal(result.trajectories[0], alone.trajectories[0])
    assert np.array_equal(result.trajectories[4, :100], Model(params[4]).simulate(x0[4], 0.01, 99, u[4, :99]))
    assert result.message(4) == "non-finite value"


def test_a_sample_stopped_by_the_energy_guard_fails_alone():
    x0 = initial_state(theta_P=1.5)
    frictionless, damped = Params(k_S=0, k_Y=0, k_P=0), Params(k_S=0.5, k_Y=0.5, k_P=0.5)
    result = simulate_many([frictionless, damped], x0, 0.05, 400)   # Lie-Euler, a coarse step
    assert result.status.tolist() == [lib.SR_ERR_ENERGY, lib.SR_OK]
    with pytest.raises(ValueError, match="energy rose"):
        Model(frictionless).simulate(x0, 0.05, 400)
    assert np.array_equal(result.final[1], Model(damped).simulate(x0, 0.05, 400)[-1])


@pytest.mark.parametrize("kwargs, field", [
    (dict(params=np.ones((2, 11))), "params"),
    (dict(params="heavy"), "params"),
    (dict(x0=np.zeros(34)), "x0"),
    (dict(u=np.zeros((10, 2))), "u"),
    (dict(x0=np.zeros((3, NX))), "batch sizes differ"),
    (dict(dt=0.0), "dt"),
    (dict(steps=-1), "steps"),
    (dict(steps=2.5), "steps"),
    (dict(method="euler"), "method"),
    (dict(energy_tol=-1.0), "energy_tol"),
])
def test_malformed_arguments_raise_value_errors_naming_the_field(kwargs, field):
    args = dict(params=[Params(), Params()], x0=initial_state(), dt=0.01, steps=20)
    args.update(kwargs)
    with pytest.raises(ValueError, match=field):
        simulate_many(**args)


# -- the GIL ------------------------------------------------------------------------------------
GIL_SAMPLES, GIL_STEPS = 3000, 300


def seen_midway(call, status):
    """Whether this thread saw `status` partly written while `call` ran in another thread.

    sr_simulate_batch writes status[i] when sample i is done.  A thread can see some entries
    written and others not only if it ran while the C loop was running: only if the call
    released the GIL.
    """
    status[:] = -1
    worker = threading.Thread(target=call)
    worker.start()
    seen = False
    while worker.is_alive():
        done = np.count_nonzero(status != -1)
        seen = seen or 0 < done < len(status)
    worker.join()
    assert (status != -1).all()
    return seen


def batch_buffers():
    x0 = initial_state(theta_P=0.5)
    return dict(p=Params().as_array(), x0=x0, work=np.empty((CHUNK_STEPS + 1, NX)),
                final=np.empty((GIL_SAMPLES, NX)), status=np.full(GIL_SAMPLES, -1, dtype=np.intc),
                done=np.zeros(GIL_SAMPLES, dtype=np.int_))


def test_the_batch_runs_with_the_gil_released():
    buf = batch_buffers()
    ffi = bindings._sr.ffi

    def call():
        ptr = lambda a: ffi.from_buffer(a)  # noqa: E731
        lib.sr_simulate_batch(lib.SR_LIE_EULER, GIL_SAMPLES, ffi.cast("double *", ptr(buf["p"])), 0,
                              ffi.cast("double *", ptr(buf["x0"])), 0, 0.01, GIL_STEPS, ffi.NULL, 0, 0.5,
                              CHUNK_STEPS, ffi.cast("double *", ptr(buf["work"])), ffi.NULL,
                              ffi.cast("double *", ptr(buf["final"])), ffi.NULL,
                              ffi.cast("int *", ptr(buf["status"])), ffi.cast("long *", ptr(buf["done"])))

    assert any(seen_midway(call, buf["status"]) for _ in range(3))
    assert (buf["status"] == lib.SR_OK).all()


def test_the_gil_check_fails_for_the_same_call_holding_the_gil():
    buf = batch_buffers()
    holding = ctypes.PyDLL(bindings._sr.__file__).sr_simulate_batch   # PyDLL: the GIL stays held
    d, i, L = ctypes.c_double, ctypes.c_int, ctypes.c_long
    holding.argtypes = [i, L, ctypes.c_void_p, L, ctypes.c_void_p, L, d, L, ctypes.c_void_p, L, d, L,
                        ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p,
                        ctypes.c_void_p, ctypes.c_void_p]
    holding.restype = i
    addr = lambda a: a.ctypes.data  # noqa: E731

    def call():
        holding(lib.SR_LIE_EULER, GIL_SAMPLES, addr(buf["p"]), 0, addr(buf["x0"]), 0, 0.01, GIL_STEPS, None,
                0, 0.5, CHUNK_STEPS, addr(buf["work"]), None, addr(buf["final"]), None,
                addr(buf["status"]), addr(buf["done"]))

    assert not seen_midway(call, buf["status"])
    assert (buf["status"] == lib.SR_OK).all()


def test_inertia_batch_equals_the_inertia_of_each_state(rng):
    model = Model(Params.paper_simulation())
    x = np.stack([initial_state(theta_Y=rng.uniform(-1, 1), theta_P=rng.uniform(-1, 1)) for _ in range(4)])
    np.testing.assert_array_equal(model.inertia_batch(x), np.stack([model.inertia(s) for s in x]))


def test_inertia_batch_names_the_bad_state():
    x = np.stack([initial_state(), initial_state()])
    x[1, IDX_QZ] = 1.0
    with pytest.raises(ValueError, match=r"x"):
        Model(Params.paper_simulation()).inertia_batch(x)
