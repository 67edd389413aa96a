"""The EKF's observability constraint (c/include/sr_ekf.h, "Observability constraint"): the
directions N of `unobservable` are what the IMU, the encoders and the step cannot see (checked
against the sensors' Jacobians and the step's, and failing for a slightly wrong N); the C filter
with the constraint equals its NumPy reference, and that comparison fails when any one part of the
constraint is left out; with the constraint the information along N is left as it is by the
predicts and the IMU's and encoders' samples, without it it grows; bad input named."""
import dataclasses

import numpy as np
import pytest

from runtime import Model, Params, initial_state, sensors
from runtime.ekf import Ekf, gate_threshold
from runtime.state import NE
from runtime.verification.ekf_reference import EkfReference, unobservable

from .test_ekf import DT, NOISE, TOL, make_run, run_c, run_reference, started, worst_relative_difference
from .test_ekf_held import HELD, run_c as run_c_held, run_reference_held

QUIET = dataclasses.replace(NOISE, torque_psd=0.0, gyro_bias_rw=0.0, accel_bias_rw=0.0)


@pytest.fixture(scope="module")
def model():
    return Model(Params.paper_simulation())


@pytest.fixture(scope="module")
def truth(model):
    """States and torques of a rolling, turning truth away from the origin, every 30th of 3 s."""
    x = initial_state(r=model.params.r)
    x[27:29] = (0.7, -0.4)
    _, samples = make_run(model, 3.0, fix_every=10**9, heading=False)
    out = []
    for k, s in enumerate(samples):
        x = model.step(x, s["u"], DT, "rkmk4")
        if k % 30 == 0:
            out.append((x.copy(), s["u"]))
    return out


def turn_about_the_body_z(model, x):
    """A wrong N: the turn about the shell's own z axis (R_S's column instead of its row)."""
    N = unobservable(model, x)
    N[0:3, 0] = x[0:9].reshape(3, 3) @ np.array([0.0, 0.0, 1.0])
    return N


def turn_without_moving_q(model, x):
    """A wrong N: the turn leaves the position where it was."""
    N = unobservable(model, x)
    N[5:7, 0] = 0.0
    return N


def worst_blind_spot(model, truth, directions):
    """The largest |H N| of the IMU (relative to its largest |H|) and the encoders, and the largest
    |F N(x) - N(step(x))| of the Lie-Euler step, over the truth's states."""
    worst_h, worst_f = 0.0, 0.0
    for x, u in truth:
        N = directions(model, x)
        _, H = sensors.imu_jacobian(model, x, u)
        _, He = sensors.encoders_jacobian(model, x)
        worst_h = max(worst_h, np.abs(H[:, :NE] @ N).max() / np.abs(H).max(), np.abs(He[:, :NE] @ N).max())
        F, _ = model.step_jacobian(x, u, DT, "lie-euler")
        worst_f = max(worst_f, np.abs(F @ N - directions(model, model.step(x, u, DT, "lie-euler"))).max())
    return worst_h, worst_f


def test_the_imu_the_encoders_and_the_step_cannot_see_the_directions_of_n(model, truth):
    worst_h, worst_f = worst_blind_spot(model, truth, unobservable)
    assert worst_h <= 1e-14 and worst_f <= 1e-14


@pytest.mark.parametrize("wrong, seen_by", [(turn_about_the_body_z, "sensors"), (turn_without_moving_q, "step")])
def test_the_check_of_n_fails_for_a_slightly_wrong_n(model, truth, wrong, seen_by):
    worst_h, worst_f = worst_blind_spot(model, truth, wrong)
    assert (worst_h if seen_by == "sensors" else worst_f) > 1e-4


def test_on_a_slope_only_the_moves_along_the_floor_are_unobservable(model):
    sloped = Model(dataclasses.replace(Params.paper_simulation(), slope=0.05))
    N = unobservable(sloped, initial_state(r=sloped.params.r))
    assert N.shape == (NE, 2) and (N[:5] == 0).all()
    ekf = Ekf(sloped, initial_state(r=sloped.params.r), sigma=np.full(18, 0.1), constrained=True)
    assert ekf._ekf.null_cols == 2


def constrained_pair(model, first, noise=NOISE, reference=EkfReference):
    probe, _ = started(model, first)
    ekf = Ekf(model, probe.x, P0=probe.P, noise=noise, constrained=True)
    return ekf, reference(model, probe.x, probe.biases, probe.P, constrained=True)


def run_c_heading_first(ekf, samples):
    """The C filter over the samples, each heading applied before the IMU sample of its instant:
    the IMU's H is then taken at a state the heading moved, away from where N was taken."""
    history = []
    for s in samples:
        ekf.predict(s["u"], DT)
        if "heading" in s:
            ekf.update_heading(s["heading"])
        ekf.update_imu(s["imu"], s["u"])
        if "encoders" in s:
            ekf.update_encoders(s["encoders"])
        if "fix" in s:
            ekf.update_position(s["fix"])
        history.append((ekf.x, ekf.biases, ekf.P))
    return history


def run_reference_heading_first(ref, samples, noise=NOISE):
    g = {n: gate_threshold(0.999, n) for n in (1, 2, 6)}
    mount = sensors.DEFAULT_MOUNT
    history = []
    for s in samples:
        ref.predict(s["u"], DT, (noise.torque_psd,) * 3, noise.gyro_bias_rw, noise.accel_bias_rw)
        if "heading" in s:
            ref.update_heading(s["heading"], mount, noise.heading, g[1])
        ref.update_imu(s["imu"], s["u"], mount, noise.gyro, noise.accel, g[6])
        if "encoders" in s:
            ref.update_encoders(s["encoders"], noise.encoder, g[2])
        if "fix" in s:
            ref.update_position(s["fix"], noise.position, g[2])
        history.append((ref.x.copy(), ref.b.copy(), ref.P.copy()))
    return history


@pytest.fixture(scope="module")
def constrained_run(model):
    """2 s with every sensor and both outliers, headings before the IMU: the constrained C
    filter's history."""
    first, samples = make_run(model, 2.0)
    ekf, _ = constrained_pair(model, first)
    return first, samples, run_c_heading_first(ekf, samples)


def test_the_constrained_c_filter_equals_the_numpy_reference(model, constrained_run):
    first, samples, c_history = constrained_run
    _, ref = constrained_pair(model, first)
    assert worst_relative_difference(c_history, run_reference_heading_first(ref, samples)) <= TOL


def test_the_constrained_c_filter_equals_the_numpy_reference_with_late_fixes(model):
    first, samples = make_run(model, 1.0, fix_every=20, latency=30)
    ekf, ref = constrained_pair(model, first)
    assert worst_relative_difference(run_c(ekf, samples), run_reference(ref, samples)) <= TOL


def test_the_constrained_c_filter_equals_the_numpy_reference_with_the_held_disturbance(model):
    first, samples = make_run(model, 0.6, fix_every=20, latency=50)
    ekf, ref = constrained_pair(model, first, noise=HELD)
    assert worst_relative_difference(run_c_held(ekf, samples), run_reference_held(ref, samples)) <= TOL


class TransitionNotConstrained(EkfReference):
    """F as it is (N still taken at each predicted state)."""
    def constrain_transition(self, F):
        super().constrain_transition(F)
        return F


class SamplesNotConstrained(EkfReference):
    """The IMU's and the encoders' H as they are."""
    def constrain_sample(self, H):
        return H


class NotMovedByTheReset(EkfReference):
    """N kept as it was taken at the predicted state through the resets."""
    def reset(self, e):
        N = self.N
        super().reset(e)
        self.N = N


@pytest.mark.parametrize("planted", [TransitionNotConstrained, SamplesNotConstrained, NotMovedByTheReset])
def test_the_comparison_fails_for_a_reference_with_one_part_of_the_constraint_left_out(model, constrained_run,
                                                                                      planted):
    first, samples, c_history = constrained_run
    _, ref = constrained_pair(model, first, reference=planted)
    assert worst_relative_difference(c_history, run_reference_heading_first(ref, samples)) > 1e3 * TOL


def information_along_n(P, N):
    """N^T P^-1 N (k, k): what the filter knows of the directions N."""
    Nb = np.zeros((len(P), N.shape[1]))
    Nb[:NE] = N
    return Nb.T @ np.linalg.solve(P, Nb)


def information_history(model, constrained):
    """Over 2 s of IMU and encoders without process noise: N^T P^-1 N after every sample's updates,
    N the filter's own (constrained) or N at the estimate (not)."""
    first, samples = make_run(model, 2.0, fix_every=10**9, heading=False)
    probe, _ = started(model, first)
    ekf = Ekf(model, probe.x, P0=probe.P, noise=QUIET, constrained=constrained)
    history = []
    for s in samples:
        ekf.predict(s["u"], DT)
        ekf.update_imu(s["imu"], s["u"])
        if "encoders" in s:
            ekf.update_encoders(s["encoders"])
        N = np.array(list(ekf._ekf.null_space)).reshape(NE, 3) if constrained else unobservable(model, ekf.x)
        history.append(information_along_n(ekf.P, N))
    return np.array(history)


def test_with_the_constraint_the_information_along_n_stays_as_it_was(model):
    info = information_history(model, True)
    assert np.abs(info - info[0]).max() <= 1e-9 * np.abs(info[0]).max()


def test_without_the_constraint_the_filter_learns_the_heading_the_sensors_do_not_tell(model):
    info = information_history(model, False)
    assert info[-1, 0, 0] > 10 * info[0, 0, 0]


def two_imu_samples_a_step(model, reference):
    """The reference without process noise, each predict followed by two IMU samples (the second at
    the state the first moved): N^T P^-1 N before and after the second."""
    first, samples = make_run(model, 0.3, fix_every=10**9, heading=False)
    probe, _ = started(model, first)
    ref = reference(model, probe.x, probe.biases, probe.P, constrained=True)
    g = gate_threshold(0.999, 6)
    before, after = [], []
    for s in samples:
        ref.predict(s["u"], DT, (0.0,) * 3)
        ref.update_imu(s["imu"], s["u"], sensors.DEFAULT_MOUNT, QUIET.gyro, QUIET.accel, g)
        before.append(information_along_n(ref.P, ref.N))
        ref.update_imu(s["imu"], s["u"], sensors.DEFAULT_MOUNT, QUIET.gyro, QUIET.accel, g)
        after.append(information_along_n(ref.P, ref.N))
    return np.array(before), np.array(after)


def test_after_the_projection_an_imu_sample_away_from_where_n_was_taken_tells_nothing_along_n(model):
    before, after = two_imu_samples_a_step(model, EkfReference)
    assert np.abs(after - before).max() <= 1e-9 * np.abs(before).max()
    before, after = two_imu_samples_a_step(model, SamplesNotConstrained)
    assert np.abs(after - before).max() > 1e-6 * np.abs(before).max()


@pytest.mark.parametrize("value", ["yes", 1, None])
def test_a_constrained_that_is_not_a_bool_is_a_value_error_naming_it(model, value):
    with pytest.raises(ValueError, match="constrained"):
        Ekf(model, initial_state(r=model.params.r), sigma=np.full(18, 0.1), constrained=value)
