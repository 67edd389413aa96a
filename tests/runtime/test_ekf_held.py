"""The EKF with the held torque disturbance (c/include/sr_ekf.h, "Held disturbance";
docs/estimation.md, "Consistency"): the accelerometer reads the acceleration a = M⁻¹ w of the
torque disturbance that drives the next step, so the IMU's noise and the process noise are
correlated.  The C filter equals its NumPy reference (the augmented state (e, a)) over a run with
late fixes, gating and an IMU recovery; that comparison fails for a reference with any one of the
new terms removed; ∂y/∂ν̇ is the finite difference of the reading; on a simulated truth the IMU's
innovations have the size the filter expects with the correlation and not without it."""
import dataclasses

import numpy as np
import pytest

from runtime import Model, Params
from runtime import sensors
from runtime.ekf import Ekf, gate_threshold
from runtime.sensor_set import SensorSet
from runtime.sensor_sim import SensorSimulation, ekf_noise
from runtime.state import IDX_E_NU, NV, initial_state
from runtime.verification.ekf_reference import NB, EkfReference

from .test_ekf import DT, NOISE, TOL, make_run, started, worst_relative_difference

HELD = dataclasses.replace(NOISE, torque_hold=DT)
POLICY = {"imu": 1}


@pytest.fixture(scope="module")
def model():
    return Model(Params.paper_simulation())


def run_c(ekf, samples):
    """The C filter over the samples, a late fix marked after the IMU sample of its instant (so
    that it shares the held disturbance's correlation with the error)."""
    history = []
    for s in samples:
        ekf.predict(s["u"], DT)
        ekf.update_imu(s["imu"], s["u"])
        if "mark" in s:
            ekf.mark_position(s["mark"])
        if "encoders" in s:
            ekf.update_encoders(s["encoders"])
        if "heading" in s:
            ekf.update_heading(s["heading"])
        if "fix" in s:
            ekf.update_position(s["fix"])
        for slot, fix in s["arrive"]:
            ekf.update_position_delayed(slot, fix)
        history.append((ekf.x, ekf.biases, ekf.P))
    return history


def run_reference_held(ref, samples, noise=HELD, gate=0.999):
    g = {n: gate_threshold(gate, n) for n in (1, 2, 6)}
    mount = sensors.DEFAULT_MOUNT
    sigma = np.array([noise.gyro] * 3 + list(noise.accel))
    psd = (noise.torque_psd,) * 3
    history = []
    for s in samples:
        ref.predict(s["u"], DT, psd, noise.gyro_bias_rw, noise.accel_bias_rw)
        ref.update_imu_held(s["imu"], s["u"], mount, sigma, psd, noise.torque_hold, g[6])
        if "mark" in s:
            ref.mark_position(s["mark"])
        if "encoders" in s:
            ref.update_encoders(s["encoders"], noise.encoder, g[2])
        if "heading" in s:
            ref.update_heading(s["heading"], mount, noise.heading, g[1])
        if "fix" in s:
            ref.update_position(s["fix"], noise.position, g[2])
        for slot, fix in s["arrive"]:
            ref.update_position_delayed(slot, fix, noise.position, g[2])
        history.append((ref.x.copy(), ref.b.copy(), ref.P.copy()))
    return history


def two_outliers(samples):
    """A second accelerometer spike right after make_run's: with POLICY it is recovered."""
    samples[61]["imu"] = samples[61]["imu"] + np.array([0, 0, 0, 0, 5.0, 0])
    return samples


def filters(model, first, reference=EkfReference, noise=HELD):
    probe, _ = started(model, first)
    ekf = Ekf(model, probe.x, P0=probe.P, noise=noise, recover_after=POLICY)
    return ekf, reference(model, probe.x, probe.biases, probe.P, recover_after=POLICY)


@pytest.fixture(scope="module")
def late_run(model):
    """0.6 s, fixes at 10 Hz arriving 0.25 s late, two IMU outliers: the C filter's history."""
    first, samples = make_run(model, 0.6, fix_every=20, latency=50)
    samples = two_outliers(samples)
    ekf, _ = filters(model, first)
    return first, samples, run_c(ekf, samples), ekf


def test_the_c_filter_with_the_held_disturbance_equals_the_numpy_reference(model, late_run):
    first, samples, c_history, ekf = late_run
    _, ref = filters(model, first)
    assert worst_relative_difference(c_history, run_reference_held(ref, samples)) <= TOL
    c = ekf.counters["imu"]
    assert (c["accepted"], c["gated"], c["recovered"]) == (ref.accepted["imu"], ref.gated["imu"], ref.recovered["imu"])
    assert c["gated"] >= 1 and c["recovered"] >= 1
    assert ekf.counters["position"]["accepted"] >= 1


def test_a_disturbance_held_over_two_predicts_equals_the_numpy_reference(model):
    # a simulation step of 10 ms under 200 Hz samples: two IMU samples read the same a
    first, samples = make_run(model, 0.4, fix_every=20, latency=10)
    noise = dataclasses.replace(HELD, torque_hold=2 * DT)
    ekf, ref = filters(model, first, noise=noise)
    assert worst_relative_difference(run_c(ekf, samples), run_reference_held(ref, samples, noise)) <= TOL


class NoCrossTermInPredict(EkfReference):
    """The predict steps with a's covariance but forgets its correlation with the error."""
    def predict(self, u, dt, torque_psd, gyro_bias_rw=0.0, accel_bias_rw=0.0):
        if self.held is not None:
            n = len(self.P_aug)
            self.P_aug[:n - NV, n - NV:] = 0.0
            self.P_aug[n - NV:, :n - NV] = 0.0
        super().predict(u, dt, torque_psd, gyro_bias_rw, accel_bias_rw)


class MeanNotStepped(EkfReference):
    """The predict ignores the estimate of a."""
    def predict(self, u, dt, torque_psd, gyro_bias_rw=0.0, accel_bias_rw=0.0):
        if self.held is not None:
            self.held = np.zeros(NV)
        super().predict(u, dt, torque_psd, gyro_bias_rw, accel_bias_rw)


class TorqueNoiseTwice(EkfReference):
    """The predict adds the torque noise on top of the held a."""
    def predict(self, u, dt, torque_psd, gyro_bias_rw=0.0, accel_bias_rw=0.0):
        held = self.held is not None
        super().predict(u, dt, torque_psd, gyro_bias_rw, accel_bias_rw)
        if held:
            self.P = self.P + self.process_noise(dt, torque_psd, 0.0, 0.0)


class AccelerometerBlindToA(EkfReference):
    """The sample does not read a (Hn = 0): a stays its prior, the plain filter."""
    def update_imu_held(self, y, u, mount, sigma, torque_psd, hold, gate):
        original = sensors.imu_partials
        sensors.imu_partials = lambda *a, **k: (*original(*a, **k)[:2], np.zeros((6, NV)))
        try:
            return super().update_imu_held(y, u, mount, sigma, torque_psd, hold, gate)
        finally:
            sensors.imu_partials = original


class LateFixesUnlinkedFromA(EkfReference):
    """A fix marked while a is held does not share a's correlation with the error."""
    def mark_position(self, slot):
        super().mark_position(slot)
        if self.held is not None:
            n, k = len(self.P_aug), NB * (list(self.clones).index(slot) + 1)
            self.P_aug[k:k + NB, n - NV:] = 0.0
            self.P_aug[n - NV:, k:k + NB] = 0.0



@pytest.mark.parametrize("broken", [NoCrossTermInPredict, MeanNotStepped, TorqueNoiseTwice, AccelerometerBlindToA,
                                    LateFixesUnlinkedFromA])
def test_the_comparison_fails_for_a_reference_without_one_of_the_held_terms(model, late_run, broken):
    first, samples, c_history, _ = late_run
    _, ref = filters(model, first, broken)
    assert worst_relative_difference(c_history, run_reference_held(ref, samples)) > 1e-6


def test_the_accelerometers_rows_in_nu_dot_are_the_finite_difference_of_the_reading(model):
    rng = np.random.default_rng(4)
    x = initial_state(0.3, -0.2, r=model.params.r)
    x[-NV:] = rng.normal(0.0, 0.5, NV)
    a, h = rng.normal(0.0, 2.0, NV), 1e-4
    _, _, Hn = sensors.imu_partials(model, x, np.zeros(NV))
    _, _, Hn_a = sensors.imu_partials(model, x, a)
    fd = np.column_stack([(sensors.imu(model, x, a + h * e) - sensors.imu(model, x, a - h * e)) / (2 * h)
                          for e in np.eye(NV)])
    assert np.allclose(Hn, fd, rtol=0, atol=1e-8 * np.abs(fd).max())
    assert np.array_equal(Hn, Hn_a)          # linear in ν̇: the C evaluates it at ν̇ = 0
    assert np.all(Hn[:3] == 0) and np.abs(Hn[3:]).max() > 0.01


def mean_imu_nis(model, noise, seconds=3.0):
    """The IMU's average NIS over a simulated straight roll with the default sensor set's truth."""
    sensor_set = SensorSet.default()
    steps = round(seconds / DT)
    sim = SensorSimulation(model, sensor_set, DT, steps, "rkmk4", seed=2)
    x, u = initial_state(r=model.params.r), np.array([0.2, 0.0])
    sigma = np.full(18, 1e-3)
    sigma[IDX_E_NU] = 1e-3
    ekf = Ekf(model, x, sigma=sigma, biases=sim.bias, noise=noise, gate=1.0)
    nis = []
    for k in range(steps):
        x_next, new = sim.advance(k, x, u)
        for kind, i in new:
            if kind == "imu":
                ekf.update_imu(sim.readings["imu"][i], u)
                nis.append(ekf.counters["imu"]["nis"])
            elif kind == "encoders":
                ekf.update_encoders(sim.readings["encoders"][i])
        ekf.predict(u, DT)
        x = x_next
    return float(np.mean(nis[40:]))


def test_with_the_held_disturbance_the_imus_innovations_have_the_size_the_filter_expects(model):
    params = model.params
    held = ekf_noise(SensorSet.default(), params, accel_axes="held")
    assert held.torque_hold == pytest.approx(1 / SensorSet.default().imu.rate)
    assert 5.0 < mean_imu_nis(model, held) < 7.2                    # chi-square with 6: mean 6
    blind = dataclasses.replace(held, torque_hold=0.0)               # the same numbers, no correlation
    assert mean_imu_nis(model, blind) > 12


@pytest.mark.parametrize("hold", [-0.005, float("nan"), float("inf"), "5 ms"])
def test_a_bad_torque_hold_is_a_value_error_naming_it(hold):
    with pytest.raises(ValueError, match="^torque_hold:"):
        dataclasses.replace(NOISE, torque_hold=hold)


def test_the_held_rule_holds_the_disturbance_over_the_given_step_and_names_a_bad_one(model):
    held = ekf_noise(SensorSet.default(), model.params, accel_axes="held", hold=0.01)
    assert held.torque_hold == 0.01 and held.accel == (SensorSet.default().imu.accel_noise,) * 3
    with pytest.raises(ValueError, match="^hold:"):
        ekf_noise(SensorSet.default(), model.params, accel_axes="held", hold=0.0)


def test_a_short_circle_estimated_with_the_held_rule_meets_the_targets():
    from runtime.estimation.consistency import run_once
    from .estimation.test_tasks import short
    metrics = run_once(short("circle"), None, seed=1, accel_noise="held")["metrics"]
    assert metrics["position_rms_m"] <= 0.01 and metrics["tilt_rms_deg"] <= 0.3
