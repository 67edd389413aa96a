"""The EKF's recovery from a lost estimate (c/include/sr_ekf.h, docs/estimation.md, "Recovery"):
after n samples of a kind refused by the gate in a row, the next refused one is admitted with the
prior and its noise inflated by NIS / gate.  The C filter equals its NumPy reference through
recoveries (fresh and late fixes), the reference fails the comparison without the inflation, the
policy is counted, and a filter started off in heading with a shrunken heading σ (the start of a
robot that stood still: the fixes that would correct it look like outliers) gets back to the truth
with it and stays lost without it."""
import math

import numpy as np
import pytest

from runtime import Model, Params
from runtime.ekf import Ekf, RECOVER_AFTER
from runtime.state import IDX_Q
from runtime.verification.ekf_reference import EkfReference

from .test_ekf import TOL, make_run, run_c, run_reference, worst_relative_difference

POLICY = {"position": 2}


@pytest.fixture(scope="module")
def model():
    return Model(Params.paper_simulation())


def lost_start(model, first, offset=0.3):
    """The filter started 0.3 m off in x with a 1 cm position σ: every fix is an outlier to it."""
    from runtime.ekf import start_from_measurements
    from .test_ekf import NOISE
    ekf = start_from_measurements(model, first[3:], encoders=(0.0, 0.0), fix=(offset, 0.0), noise=NOISE)
    return ekf


def started_with(model, first, policy):
    from .test_ekf import NOISE
    probe = lost_start(model, first)
    ekf = Ekf(model, probe.x, P0=probe.P, noise=NOISE, recover_after=policy)
    ref = EkfReference(model, probe.x, probe.biases, probe.P, recover_after=policy)
    return ekf, ref


@pytest.mark.parametrize("latency", [0, 50])
def test_the_c_filter_equals_the_numpy_reference_through_recoveries(model, latency):
    first, samples = make_run(model, 0.8, fix_every=20, latency=latency)
    ekf, ref = started_with(model, first, POLICY)
    c_history = run_c(ekf, samples)
    ref_history = run_reference(ref, samples)
    assert worst_relative_difference(c_history, ref_history) <= TOL
    c = ekf.counters["position"]
    assert (c["accepted"], c["gated"], c["recovered"]) == (ref.accepted["position"], ref.gated["position"],
                                                          ref.recovered["position"])
    assert c["recovered"] >= 1 and c["gated"] >= POLICY["position"]


class InflatesTheNoiseOnly(EkfReference):
    def admission(self, kind, nis, gate):
        lam = super().admission(kind, nis, gate)
        if lam is not None and lam != 1.0:
            self.P_aug = self.P_aug / lam
        return lam


def test_the_comparison_fails_for_a_reference_that_does_not_inflate_the_prior(model):
    first, samples = make_run(model, 0.6, fix_every=20)
    ekf, _ = started_with(model, first, POLICY)
    probe = lost_start(model, first)
    bad = InflatesTheNoiseOnly(model, probe.x, probe.biases, probe.P, recover_after=POLICY)
    assert not worst_relative_difference(run_c(ekf, samples), run_reference(bad, samples)) <= 1e3 * TOL


def rolled_from_a_wrong_heading(model, policy):
    """20 s of rolling (about 3 m) with 2 Hz fixes and no heading sensor, the filter started 12° off
    in heading with a heading σ of 1°: a seed-24-like start, whose σ has already shrunk."""
    from runtime.ekf import start_from_measurements
    from .test_ekf import NOISE
    first, samples = make_run(model, 20.0, heading=False)
    probe = start_from_measurements(model, first[3:], encoders=(0.0, 0.0), fix=(0.0, 0.0), noise=NOISE,
                                    heading_prior=math.radians(12.0), heading_sigma=math.radians(1.0))
    ekf = Ekf(model, probe.x, P0=probe.P, noise=NOISE, recover_after=policy)
    history = run_c(ekf, samples)
    error = np.linalg.norm(history[-1][0][IDX_Q][:2] - samples[-1]["q"])
    return error, ekf.counters["position"]


def test_a_filter_started_off_in_heading_gets_back_to_the_truth_by_recovering():
    model = Model(Params.paper_simulation())
    error, counts = rolled_from_a_wrong_heading(model, {"position": 4})
    assert error < 0.02
    assert counts["recovered"] >= 1


def test_without_the_recovery_the_same_start_stays_lost():
    model = Model(Params.paper_simulation())
    error, counts = rolled_from_a_wrong_heading(model, {})
    assert error > 0.2
    assert counts["gated"] > 20 and counts["recovered"] == 0


def test_the_default_policy_recovers_position_fixes():
    assert RECOVER_AFTER.get("position", 0) > 0


def test_recovery_is_off_unless_asked_for_in_c_and_set_per_kind(model):
    from bindings._sr import ffi, lib
    ekf = Ekf(model, model_state(model), sigma=np.full(18, 0.01), recover_after={})
    assert list(ekf._ekf.recover_after) == [0, 0, 0, 0]
    assert lib.sr_ekf_set_recovery(ekf._ekf, lib.SR_EKF_HEADING, 3) == lib.SR_OK
    assert list(ekf._ekf.recover_after) == [0, 0, 0, 3]
    assert lib.sr_ekf_set_recovery(ekf._ekf, lib.SR_EKF_NKINDS, 3) == lib.SR_ERR_ARG
    assert lib.sr_ekf_set_recovery(ekf._ekf, lib.SR_EKF_IMU, -1) == lib.SR_ERR_ARG
    assert lib.sr_ekf_set_recovery(ffi.NULL, lib.SR_EKF_IMU, 1) == lib.SR_ERR_NULL
    assert list(ekf._ekf.recover_after) == [0, 0, 0, 3]


def model_state(model):
    from runtime import initial_state
    return initial_state(r=model.params.r)


@pytest.mark.parametrize("policy, message", [
    ([4], "recover_after: expected a dict"),
    ({"camera": 4}, "recover_after: unknown sensor kind 'camera'"),
    ({"position": -1}, r"recover_after\['position'\]: expected a whole number"),
    ({"position": 2.5}, r"recover_after\['position'\]: expected a whole number"),
])
def test_a_bad_policy_is_a_value_error_naming_it(model, policy, message):
    with pytest.raises(ValueError, match=rf"^{message}"):
        Ekf(model, model_state(model), sigma=np.full(18, 0.01), recover_after=policy)
