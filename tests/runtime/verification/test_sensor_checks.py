"""The sensor checks of `make verify` (runtime/verification/sensor_checks.py): each passes for the C
sensors and fails for a slightly perturbed one (a lever arm off by 1e-6 m, a reading off by 1e-9,
a Jacobian entry off by 1e-7, ν̇ held where it moves)."""
import dataclasses
import types

import numpy as np
import pytest

from runtime import sensors
from runtime.params import Params
from runtime.verification import sensor_checks as checks
from runtime.verification.sampling import random_general_params

N = 9   # three states per body

API = ("imu", "imu_partials", "imu_jacobian", "heading", "heading_jacobian", "encoders", "encoders_jacobian",
       "position", "position_jacobian")


def api(**replaced):
    """runtime.sensors with some functions replaced."""
    return types.SimpleNamespace(**{**{name: getattr(sensors, name) for name in API}, **replaced})


def moved_lever(mount, by=1e-6):
    return dataclasses.replace(mount, lever=tuple(np.add(mount.lever, by)))


def entry_added(f, index, by=1e-7):
    """f with `by` added to one entry of its Jacobian H, the second of its results."""
    def perturbed(*args, **kwargs):
        out = list(f(*args, **kwargs))
        out[1] = np.array(out[1], copy=True)
        out[1][index] += by
        return tuple(out)
    return perturbed


def failing(rows):
    return [name for name, _, rel, tol in rows if not rel <= tol]


@pytest.fixture(scope="module")
def general():
    return random_general_params(np.random.default_rng(3))


def test_the_c_sensors_pass_every_check_on_the_papers_robot():
    rows = checks.value_checks(N) + checks.ad_checks(N) + checks.difference_checks(3) + checks.measured_accel_check(3)
    assert failing(rows) == []


def test_the_c_sensors_pass_every_check_on_a_general_robot_on_a_slope(general):
    rows = (checks.value_checks(N, params=general) + checks.ad_checks(N, params=general)
            + checks.difference_checks(3, params=general) + checks.measured_accel_check(3, params=general))
    assert failing(rows) == []


def test_the_value_check_fails_for_a_lever_arm_off_by_a_micrometre():
    def imu(model, x, nu_dot=None, *, mount=None, **kw):
        return sensors.imu(model, x, nu_dot, mount=moved_lever(mount), **kw)
    rows = checks.value_checks(N, api=api(imu=imu))
    assert failing(rows) == [rows[0][0]]


def test_the_value_check_fails_for_the_slope_left_out(general):
    flat = general.replace(slope=0.0)
    def imu(model, x, nu_dot=None, **kw):
        return sensors.imu(type(model)(flat), x, nu_dot, **kw)
    rows = checks.value_checks(N, params=general, api=api(imu=imu))
    assert failing(rows) == [rows[0][0]]


def test_the_value_check_fails_for_a_heading_or_an_encoder_off_by_1e_9():
    rows = checks.value_checks(N, api=api(heading=lambda *a: sensors.heading(*a) + 1e-9,
                                          encoders=lambda *a: sensors.encoders(*a) + [0.0, 1e-9]))
    assert failing(rows) == [rows[1][0], rows[2][0]]


def test_the_ad_check_fails_for_a_jacobian_entry_off_by_1e_7():
    rows = checks.ad_checks(N, api=api(imu_partials=entry_added(sensors.imu_partials, (4, 2)),
                                       heading_jacobian=entry_added(sensors.heading_jacobian, 5),
                                       position_jacobian=entry_added(sensors.position_jacobian, (1, 6))))
    assert failing(rows) == [r[0] for r in rows]


def test_the_ad_check_fails_for_an_entry_along_nu_dot_off_by_1e_7():
    def imu_partials(*args, **kwargs):
        y, H, Hn = sensors.imu_partials(*args, **kwargs)
        Hn = Hn.copy()
        Hn[5, 3] += 1e-7
        return y, H, Hn
    rows = checks.ad_checks(N, api=api(imu_partials=imu_partials))
    assert failing(rows) == [rows[0][0]]


def test_the_difference_check_fails_for_nu_dot_held():
    def held(model, x, u=None, *, mount=None, bias=None):
        y, H, _ = sensors.imu_partials(model, x, model.accel(x, u), mount=mount, bias=bias)
        return y, H
    rows = checks.difference_checks(3, api=api(imu_jacobian=held))
    assert failing(rows) == [rows[0][0]]


def test_the_difference_check_fails_for_jacobian_entries_off_by_1e_7():
    def imu_partials(*args, **kwargs):
        y, H, Hn = sensors.imu_partials(*args, **kwargs)
        Hn = Hn.copy()
        Hn[3, 1] += 1e-7
        return y, H, Hn
    rows = checks.difference_checks(3, api=api(imu_jacobian=entry_added(sensors.imu_jacobian, (5, 0)),
                                               imu_partials=imu_partials,
                                               heading_jacobian=entry_added(sensors.heading_jacobian, 3)))
    assert failing(rows) == [r[0] for r in rows]


def test_the_measured_accel_check_fails_for_a_lever_arm_off_by_a_micrometre():
    def imu(model, x, nu_dot=None, *, mount=None, **kw):
        return sensors.imu(model, x, nu_dot, mount=moved_lever(mount), **kw)
    assert failing(checks.measured_accel_check(3, api=api(imu=imu))) != []
