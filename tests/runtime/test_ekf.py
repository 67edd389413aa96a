"""The error-state EKF (runtime/ekf.py over c/include/sr_ekf.h): the C filter equals its NumPy
reference (runtime/verification/ekf_reference.py) over a run with asynchronous sensors and
outliers, and over one whose fixes arrive late, and that comparison fails for a reference with any
one equation broken; late fixes handled as such beat late fixes taken as fresh; the start rule;
gating counted; bad input named."""
import dataclasses
import math

import numpy as np
import pytest

from runtime import Model, Params, initial_state, so3
from runtime import sensors
from runtime.state import IDX_Q
from runtime.ekf import DELAYED_SLOTS, Ekf, EkfNoise, gate_threshold, start_from_measurements
from runtime.verification.ekf_reference import EkfReference

DT = 0.005
NOISE = EkfNoise(accel=(0.03, 0.05, 0.02), gyro_bias_rw=1e-4, accel_bias_rw=1e-3)
IMU_OUTLIER, FIX_OUTLIER = 60, 99           # samples with a 5 m/s² accelerometer spike, a 1 m fix jump
TOL = 1e-10


@pytest.fixture(scope="module")
def model():
    return Model(Params.paper_simulation())


def make_run(model, seconds, seed=3, fix_every=100, latency=0, heading=True):
    """Truth rolling under varying torques, and the readings of every sample: the IMU at 200 Hz,
    the encoders at 100 Hz, a heading at 10 Hz, position fixes every `fix_every` samples (2 Hz),
    each arriving `latency` samples after it measures; two outliers."""
    rng = np.random.default_rng(seed)
    arrivals = {}
    bias = rng.normal(0.0, [0.005] * 3 + [0.05] * 3)
    x = initial_state(r=model.params.r)
    samples = []
    first = sensors.imu(model, x, bias=bias) + rng.normal(0.0, [0.003] * 3 + [0.02] * 3)
    for k in range(round(seconds / DT)):
        t = k * DT
        u = np.array([0.15 + 0.1 * math.sin(0.9 * t), 0.05 * math.cos(1.7 * t)])
        x = model.step(x, u, DT, "rkmk4")
        sample = {"q": x[IDX_Q][:2], "u": u, "imu": sensors.imu(model, x, u=u, bias=bias) + rng.normal(0.0, [0.003] * 3 + [0.02] * 3)}
        if k == IMU_OUTLIER:
            sample["imu"][4] += 5.0
        if k % 2 == 1:
            sample["encoders"] = sensors.encoders(model, x) + rng.normal(0.0, NOISE.encoder, 2)
        if heading and k % 20 == 10:
            sample["heading"] = sensors.heading(model, x) + rng.normal(0.0, NOISE.heading)
        if k % fix_every == fix_every - 1:
            fix = sensors.position(model, x) + rng.normal(0.0, 0.01, 2) + (1.0 if k == FIX_OUTLIER else 0.0)
            if latency:
                sample["mark"] = k // fix_every % DELAYED_SLOTS
                arrivals.setdefault(k + latency, []).append((sample["mark"], fix))
            else:
                sample["fix"] = fix
        sample["arrive"] = arrivals.pop(k, [])
        samples.append(sample)
    return first, samples


def run_c(ekf, samples, delayed=True):
    """The C filter over the samples; late fixes marked and applied as such, or (`delayed` False)
    applied on arrival as if fresh."""
    history = []
    for s in samples:
        ekf.predict(s["u"], DT)
        if "mark" in s and delayed:
            ekf.mark_position(s["mark"])
        ekf.update_imu(s["imu"], s["u"])
        if "encoders" in s:
            ekf.update_encoders(s["encoders"])
        if "heading" in s:
            ekf.update_heading(s["heading"])
        if "fix" in s:
            ekf.update_position(s["fix"])
        for slot, fix in s["arrive"]:
            ekf.update_position_delayed(slot, fix) if delayed else ekf.update_position(fix)
        history.append((ekf.x, ekf.biases, ekf.P))
    return history


def run_reference(ref, samples, noise=NOISE, gate=0.999):
    g = {n: gate_threshold(gate, n) for n in (1, 2, 6)}
    mount = sensors.DEFAULT_MOUNT
    history = []
    for s in samples:
        ref.predict(s["u"], DT, (noise.torque_psd,) * 3, noise.gyro_bias_rw, noise.accel_bias_rw)
        if "mark" in s:
            ref.mark_position(s["mark"])
        ref.update_imu(s["imu"], s["u"], mount, noise.gyro, noise.accel, g[6])
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


def worst_relative_difference(c_history, ref_history):
    """The largest difference C − ref per component, relative to that component's scale: for the
    state and the biases the largest |value| it takes over the run (an entry passing through zero
    has no relative error of its own there), for P_ij √(P_ii P_jj) at that sample."""
    x, b, P = (np.array(v) for v in zip(*c_history))
    xr, br, Pr = (np.array(v) for v in zip(*ref_history))
    d = np.diagonal(Pr, axis1=1, axis2=2)
    return max(float(np.max(np.abs(x - xr) / np.max(np.abs(xr), axis=0).clip(1e-300))),
               float(np.max(np.abs(b - br) / np.max(np.abs(br), axis=0).clip(1e-300))),
               float(np.max(np.abs(P - Pr) / np.sqrt(d[:, :, None] * d[:, None, :]))))


def started(model, first):
    ekf = start_from_measurements(model, first[3:], encoders=(0.0, 0.0), fix=(0.0, 0.0), noise=NOISE)
    return ekf, EkfReference(model, ekf.x, ekf.biases, ekf.P)


@pytest.fixture(scope="module")
def short_run(model):
    """0.6 s with both outliers: the C filter's history and the run, for the planted errors."""
    first, samples = make_run(model, 0.6)
    ekf, _ = started(model, first)
    return first, samples, run_c(ekf, samples), ekf


def test_the_c_filter_equals_the_numpy_reference_over_a_5_s_run(model):
    first, samples = make_run(model, 5.0)
    ekf, ref = started(model, first)
    c_history = run_c(ekf, samples)
    ref_history = run_reference(ref, samples)
    assert worst_relative_difference(c_history, ref_history) <= TOL
    counts = ekf.counters
    for kind in ("imu", "encoders", "position", "heading"):
        assert (counts[kind]["accepted"], counts[kind]["gated"]) == (ref.accepted[kind], ref.gated[kind])
        assert counts[kind]["nis"] == pytest.approx(ref.nis[kind], rel=1e-9)
    assert counts["imu"]["accepted"] == 999 and counts["position"]["accepted"] == 9


def test_the_c_filter_equals_the_numpy_reference_with_late_fixes_several_waiting_at_once(model):
    # fixes at 10 Hz arriving 0.25 s late: three wait at a time; the 1 m outlier arrives late too
    first, samples = make_run(model, 1.5, fix_every=20, latency=50)
    ekf, ref = started(model, first)
    c_history = run_c(ekf, samples)
    ref_history = run_reference(ref, samples)
    assert worst_relative_difference(c_history, ref_history) <= TOL
    assert (ekf.counters["position"]["accepted"], ekf.counters["position"]["gated"]) == (11, 1)
    assert (ref.accepted["position"], ref.gated["position"]) == (11, 1)
    assert max(sum(1 for t in range(k - 49, k + 1) if "mark" in samples[t]) for k in range(49, len(samples))) == 3


def test_the_predict_equals_the_numpy_reference_for_a_general_robot():
    """The process noise's M⁻¹ comes from the factorisation of the accelerations' Jacobian, a
    Cholesky one for a general robot (the paper's takes the joints first): 0.1 s of predicts
    rolling, from a covariance with correlations, against the reference's M⁻¹ of the inertia."""
    from runtime.verification.sampling import random_general_params
    general = Model(random_general_params(np.random.default_rng(31)))
    assert general._model.general
    x = initial_state(r=general.params.r)
    rng = np.random.default_rng(5)
    A = rng.normal(0.0, 0.01, (18, 18))
    P0 = A @ A.T + 1e-4 * np.eye(18)
    ekf = Ekf(general, x, P0=P0, noise=NOISE)
    ref = EkfReference(general, x, np.zeros(6), P0)
    c_history, ref_history = [], []
    for k in range(20):
        u = np.array([0.2, -0.1 + 0.01 * k])
        ekf.predict(u, DT)
        ref.predict(u, DT, (NOISE.torque_psd,) * 3, NOISE.gyro_bias_rw, NOISE.accel_bias_rw)
        c_history.append((ekf.x, ekf.biases, ekf.P))
        ref_history.append((ref.x.copy(), ref.b.copy(), ref.P.copy()))
    assert worst_relative_difference(c_history, ref_history) <= TOL


def test_late_fixes_handled_as_late_beat_late_fixes_taken_as_fresh(model):
    # 2 Hz fixes arriving 0.2 s after they measure, on a robot rolling at about 0.3 m/s
    first, samples = make_run(model, 10.0, latency=40, heading=False)
    truth = np.array([s["q"] for s in samples[1000:]])
    rms = {}
    for delayed in (True, False):
        ekf, _ = started(model, first)
        estimate = np.array([x[IDX_Q][:2] for x, _, _ in run_c(ekf, samples, delayed=delayed)[1000:]])
        rms[delayed] = float(np.sqrt(np.mean(np.sum((estimate - truth) ** 2, axis=1))))
    assert rms[True] < 0.005
    assert rms[False] > 3 * rms[True]


def test_the_outliers_are_gated_and_counted(short_run):
    *_, ekf = short_run
    counts = ekf.counters
    assert counts["imu"]["gated"] == 1 and counts["position"]["gated"] == 1
    assert counts["imu"]["accepted"] == 119 and counts["position"]["accepted"] == 0
    assert counts["encoders"]["gated"] == counts["heading"]["gated"] == 0


class WrongGainSign(EkfReference):
    def gain(self, H, S):
        return -super().gain(H, S)


class NoJosephNoiseTerm(EkfReference):
    def joseph(self, K, H, R):
        return super().joseph(K, H, 0 * R)


class NoGate(EkfReference):
    @staticmethod
    def accepts(nis, gate):
        return True


class BiasNotUpdated(EkfReference):
    def inject(self, e):
        super().inject(np.concatenate([e[:12], np.zeros(6)]))


class NoReset(EkfReference):
    def reset(self, e):
        pass


class CrossTermsNotPropagated(EkfReference):
    def propagate(self, F, Q):
        P = super().propagate(F, Q)
        P[:12, 12:], P[12:, :12] = self.P[:12, 12:], self.P[12:, :12]
        return P


class NoBiasRandomWalk(EkfReference):
    def process_noise(self, dt, torque_psd, gyro_bias_rw, accel_bias_rw):
        return super().process_noise(dt, torque_psd, 0.0, 0.0)


class AccelSigmaOneNumber(EkfReference):
    def update_imu(self, y, u, mount, sigma_gyro, sigma_accel, gate):
        return super().update_imu(y, u, mount, sigma_gyro, max(sigma_accel), gate)


class TorqueNoiseWithoutInertia(EkfReference):
    def process_noise(self, dt, torque_psd, gyro_bias_rw, accel_bias_rw):
        Q = super().process_noise(dt, torque_psd, gyro_bias_rw, accel_bias_rw)
        Q[7:12, 7:12] = dt * torque_psd[0] ** 2 * np.eye(5)
        return Q


@pytest.mark.parametrize("planted", [WrongGainSign, NoJosephNoiseTerm, NoGate, BiasNotUpdated, NoReset,
                                     CrossTermsNotPropagated, NoBiasRandomWalk, AccelSigmaOneNumber,
                                     TorqueNoiseWithoutInertia])
def test_the_comparison_fails_for_a_reference_with_one_equation_broken(model, short_run, planted):
    first, samples, c_history, ekf = short_run
    _, good = started(model, first)
    bad = planted(model, good.x, good.b, good.P)
    with np.errstate(all="ignore"):
        try:
            worst = worst_relative_difference(c_history, run_reference(bad, samples))
        except ValueError:                 # the broken filter diverged: its state became invalid
            worst = math.inf
    assert not worst <= 1e3 * TOL


def test_the_start_takes_the_tilt_from_the_accelerometer_and_the_heading_given(model):
    truth = initial_state(0.3, -0.2, R_S=so3.rot_z(0.7) @ so3.rot_x(0.2), q=(1.0, -2.0, model.params.r),
                          r=model.params.r)
    accel = sensors.imu(model, truth, np.zeros(5))[3:]           # held at rest: gravity alone
    heading = sensors.heading(model, truth)
    ekf = start_from_measurements(model, accel, encoders=sensors.encoders(model, truth), fix=(1.0, -2.0),
                                  heading=heading)
    assert np.allclose(ekf.x, truth, atol=1e-12)
    assert ekf.sigma[2] < math.radians(10) / 2
    default = start_from_measurements(model, accel, encoders=sensors.encoders(model, truth))
    assert np.allclose(sensors.imu(model, default.x, np.zeros(5))[3:], accel, atol=1e-12)      # the tilt, whatever the heading
    assert sensors.heading(model, default.x) == pytest.approx(0.0, abs=1e-12)
    assert np.allclose(default.x[27:29], 0.0) and np.all(default.x[30:] == 0.0)
    up = default.x[6:9]                                   # γ: the vertical in the shell's axes
    assert float(np.sqrt(up @ default.P[:3, :3] @ up)) == pytest.approx(math.radians(10), rel=1e-9)


def test_the_gate_probability_sets_the_chi_square_quantile():
    assert gate_threshold(0.999, 2) == pytest.approx(13.815510557964274, rel=1e-12)
    assert gate_threshold(0.999, 6) == pytest.approx(22.457744484825323, rel=1e-12)
    assert gate_threshold(1, 6) == math.inf


@pytest.mark.parametrize("call, field", [
    (lambda e: e.predict((0.1,), DT), "u"),
    (lambda e: e.predict((0.1, math.nan), DT), "u"),
    (lambda e: e.predict((0.1, 0.0), 0.0), "dt"),
    (lambda e: e.update_imu([0.0] * 5), "y"),
    (lambda e: e.update_imu([0.0] * 5 + [math.nan]), "y"),
    (lambda e: e.update_encoders((0.0, math.inf)), "y"),
    (lambda e: e.update_position("here"), "y"),
    (lambda e: e.update_heading((0.1, 0.2)), "y"),
    (lambda e: e.mark_position(DELAYED_SLOTS), "slot"),
    (lambda e: e.mark_position(1.0), "slot"),
    (lambda e: e.update_position_delayed(0, (0.0, 0.0)), "slot"),
])
def test_bad_input_is_a_value_error_naming_the_argument_and_changes_nothing(model, call, field):
    ekf = start_from_measurements(model, (0.0, 0.0, 9.81))
    before = (ekf.x, ekf.P, ekf.counters)
    with pytest.raises(ValueError, match=rf"^{field}:"):
        call(ekf)
    assert np.array_equal(ekf.x, before[0]) and np.array_equal(ekf.P, before[1]) and ekf.counters == before[2]


@pytest.mark.parametrize("kwargs, field", [
    ({"sigma": np.full(18, 0.01), "P0": np.eye(18)}, "P0, sigma"),
    ({"sigma": np.full(18, -0.01)}, "sigma"),
    ({"P0": np.diag([1.0] * 17 + [-1.0])}, "P0"),
    ({"P0": np.eye(18) + np.eye(18, k=1) * 1e-3}, "P0"),
    ({"sigma": np.full(18, 0.01), "gate": 1.5}, "gate"),
    ({"sigma": np.full(18, 0.01), "method": "euler"}, "method"),
    ({"sigma": np.full(18, 0.01), "mount": "yoke"}, "mount"),
])
def test_a_bad_start_is_a_value_error_naming_the_argument(model, kwargs, field):
    with pytest.raises(ValueError, match=rf"^{field}:"):
        Ekf(model, initial_state(r=model.params.r), **kwargs)


@pytest.mark.parametrize("name, value, field", [("gyro", 0.0, "gyro"), ("encoder", math.nan, "encoder"),
                                                ("torque_psd", -1.0, "torque_psd"), ("gyro_bias_rw", math.inf, "gyro_bias_rw"),
                                                ("accel", -0.02, "accel"), ("accel", (0.02, 0.0, 0.02), r"accel\[1\]"),
                                                ("accel", (0.02, 0.02), "accel")])
def test_a_bad_noise_is_a_value_error_naming_the_field(name, value, field):
    with pytest.raises(ValueError, match=rf"^{field}:"):
        dataclasses.replace(EkfNoise(), **{name: value})


def test_the_accelerometer_sigma_is_one_number_for_three_axes_or_one_per_axis():
    assert EkfNoise(accel=0.05).accel == (0.05, 0.05, 0.05)
    assert EkfNoise(accel=[0.01, 0.02, 0.03]).accel == (0.01, 0.02, 0.03)
