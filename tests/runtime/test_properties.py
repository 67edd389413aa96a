"""Property-based tests of the Python API (hypothesis): any valid state gives finite results, any
invalid one the documented error, never a NaN (docs/robustness.md)."""
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from runtime import KernelError, Model, Params, SimulationStopped, initial_state, project_state
from runtime.validation import STATE_ENTRY_NAMES

SETTINGS = settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
MODEL = Model(Params.paper_simulation())
R = MODEL.params.r
NONFINITE, NOT_ROTATION, CONSTRAINT = 2, 3, 7

angle = st.floats(-np.pi, np.pi)
speed = st.floats(-50.0, 50.0)


@st.composite
def valid_states(draw):
    """R_S from a unit quaternion, any joint angles, q on the plane, speeds up to 50 rad/s."""
    quat = np.array(draw(st.lists(st.floats(-1, 1), min_size=4, max_size=4)))
    if np.linalg.norm(quat) < 1e-3:
        quat = np.array([1.0, 0, 0, 0])
    w, x, y, z = quat / np.linalg.norm(quat)
    R_S = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                    [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                    [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
    q = (draw(st.floats(-100, 100)), draw(st.floats(-100, 100)), R)
    return initial_state(draw(angle), draw(angle), R_S=R_S, q=q, w_S=[draw(speed) for _ in range(3)],
                         w_Y=draw(speed), w_P=draw(speed), r=R)


torques = st.lists(st.floats(-10, 10), min_size=2, max_size=2).map(np.array)


@SETTINGS
@given(valid_states(), torques)
def test_any_valid_state_gives_finite_accelerations(x, u):
    a = MODEL.accel(x, u)
    assert a.shape == (5,) and np.all(np.isfinite(a))


@SETTINGS
@given(valid_states())
def test_any_valid_state_gives_a_finite_energy_and_a_positive_definite_inertia(x):
    assert np.isfinite(MODEL.energy(x))
    assert np.linalg.eigvalsh(MODEL.inertia(x)).min() > 0


@SETTINGS
@given(valid_states(), st.integers(0, 34), st.sampled_from([np.nan, np.inf, -np.inf]))
def test_a_non_finite_entry_raises_nonfinite_naming_the_entry(x, i, bad):
    x[i] = bad
    with pytest.raises(KernelError) as info:
        MODEL.accel(x)
    assert f"x[{i}] ({STATE_ENTRY_NAMES[i]}) is {bad!r}" in str(info.value)
    assert info.value.status == NONFINITE


@SETTINGS
@given(valid_states(), st.floats(1e-5, 0.5), st.sampled_from([-1.0, 1.0]))
def test_a_scaled_R_S_raises_not_rotation(x, eps, sign):
    x[0:9] *= 1 + sign * eps
    with pytest.raises(KernelError, match=r"R_S \(x\[0:9\]\)") as info:
        MODEL.accel(x)
    assert info.value.status == NOT_ROTATION


@SETTINGS
@given(valid_states(), st.floats(2e-6, 10.0), st.sampled_from([-1.0, 1.0]))
def test_a_centre_off_the_plane_raises_constraint(x, dz, sign):
    x[29] = R * (1 + sign * dz)
    with pytest.raises(KernelError, match=r"x\[29\] \(q_z\)") as info:
        MODEL.accel(x)
    assert info.value.status == CONSTRAINT


@SETTINGS
@given(valid_states(), st.integers(0, 2**32 - 1), st.floats(1e-8, 1e-2))
def test_project_state_turns_a_perturbed_state_into_a_valid_one(x, seed, size):
    noisy = x + size * np.random.default_rng(seed).normal(size=35)
    assert np.all(np.isfinite(MODEL.accel(project_state(noisy, R))))


@settings(max_examples=60, deadline=None)
@given(valid_states(), st.sampled_from(["lie-euler", "rkmk4", "cf4"]), st.floats(1e-4, 0.2))
def test_a_short_simulation_is_finite_or_stops_with_the_rows_so_far(x, method, dt):
    try:
        traj = MODEL.simulate(x, dt, 20, method=method)
    except SimulationStopped as stop:
        traj = stop.trajectory
        assert 1 <= len(traj) == stop.step <= 20
    assert np.all(np.isfinite(traj))
