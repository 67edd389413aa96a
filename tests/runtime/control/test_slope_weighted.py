"""The LQR's weighted slope estimate (`slope_prior` > 0; runtime/control/slope.py's SlopeEstimator and
SlopeEstimatorC with `prior_scale`): on the sensor tasks, whose plant has process noise, it keeps
lqr-slope at the plain LQR's tracking where the unweighted estimate does not."""
import dataclasses

import pytest

from runtime.control import closed_loop as cl, lqr
from runtime.control.metrics import tracking_metrics
from runtime.control.offsets import with_controller
from runtime.control.slope import SlopeEstimator
from runtime.control.task import load_task
from runtime.params import Params

#: docs/control.md: circle-sensors seed 0, lqr-slope 48 mm unweighted, 20 mm weighted (the plain LQR 19 mm).
BOUND_M = 0.030


def _circle_sensors_rms(slope_prior):
    task = with_controller(load_task("circle-sensors"), "lqr-slope")
    spec = task.controllers[0]
    spec = dataclasses.replace(spec, gains=dataclasses.replace(spec.gains, slope_prior=slope_prior))
    task = dataclasses.replace(task, controllers=(spec,), noise=dataclasses.replace(task.noise, seed=0))
    reference = task.reference()
    result = cl.simulate_on_sensors(task.plant_params, task.controller(), reference, task.scenario.x0,
                                    task.duration, task.scenario.dt, task.make_estimator(), task.sensors,
                                    task.scenario.method, 0, engine="c-loop", record_samples=False)
    every = max(1, round(1 / (task.rate * task.scenario.dt)))
    return tracking_metrics(result, reference, "circle", task.plant_params.r, sample_every=every)["cross_track_rms_m"]


def test_the_weighted_estimate_holds_circle_sensors_where_the_unweighted_one_does_not():
    assert _circle_sensors_rms(1.0) < BOUND_M < _circle_sensors_rms(0.0)


def test_the_lqr_refuses_a_bad_slope_prior_by_name():
    for gains in (dict(slope_estimate_s=5.0, slope_prior=-1.0), dict(slope_estimate_s=5.0, slope_prior=float("nan")),
                  dict(slope_prior=1.0)):                             # the last: no estimate to weigh
        with pytest.raises(ValueError, match="slope_prior"):
            lqr.LqrGains(**gains)


def test_the_nmpc_refuses_the_weighted_estimate_by_name():
    from runtime.control.nmpc import NmpcGains
    with pytest.raises(ValueError, match="slope_prior"):
        NmpcGains(slope_estimate_s=5.0, slope_prior=1.0)


def test_the_numpy_estimate_refuses_a_bad_prior_scale_by_name():
    for bad in (-1.0, float("inf")):
        with pytest.raises(ValueError, match="slope_prior"):
            SlopeEstimator(Params.paper_simulation(), 0.02, 5.0, prior_scale=bad)

