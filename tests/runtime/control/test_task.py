"""Task files: the shipped ones load; every bad value is named."""
import pytest

from runtime.control.task import load_task, parse_task, shipped_tasks
from runtime.sensor_set import SensorSet

BASE = {"dt": 0.005, "duration": 1.0, "params": {"preset": "paper_simulation"},
        "reference": {"kind": "speed", "speed": 0.3}, "controller": {"kind": "pid", "rate": 50.0}}


def with_(section, **values):
    data = {k: (dict(v) if isinstance(v, dict) else v) for k, v in BASE.items()}
    data.setdefault(section, {}).update(values)
    return data


def test_the_six_tasks_of_issue_20_ship():
    assert set(shipped_tasks()) >= {"speed-step", "heading-step", "line", "circle", "figure8", "square"}
    for name in shipped_tasks():
        if load_task(name).sensors is not None:
            continue                    # on the estimator: the LQR and the C NMPC (test_on_sensors.py)
        if name.startswith("ramp"):     # the slope's feedforward and estimate: the LQR's and the NMPC's
            assert load_task(name).controller_kinds == ("lqr", "nmpc")
            continue
        assert load_task(name).controller_kinds == ("pid", "lqr", "nmpc")
        assert load_task(name).with_controller("nmpc").rate == 20.0


def test_the_tasks_on_sensors_run_the_lqr_and_the_c_nmpc_on_the_default_set():
    on_sensors = [name for name in shipped_tasks() if load_task(name).sensors is not None]
    assert sorted(on_sensors) == ["circle-sensors", "heading-step-sensors", "line-sensors"]
    for name in on_sensors:
        assert load_task(name).controller_kinds == ("lqr", "nmpc-c")
        assert load_task(name).sensors == SensorSet.default()


@pytest.mark.parametrize("section, values, named", [
    ("reference", {"kind": "spiral"}, "reference.kind"),
    ("reference", {"kind": "circle"}, "reference.radius"),
    ("reference", {"kind": "circle", "radius": -2.0}, "reference.radius"),
    ("reference", {"speed": "fast"}, "reference.speed"),
    ("reference", {"kind": "waypoints", "points": [[1.0]]}, "reference.points"),
    ("reference", {"colour": 1}, "reference: unknown key"),
    ("controller", {"kind": "nmpc", "horizon": 0}, "controller.horizon: expected a whole number"),
    ("controller", {"kind": "lqr", "n_speeds": 0.5}, "controller.n_speeds"),
    ("controller", {"kind": "lqr", "tilt_rad": 0.0}, "controller.tilt_rad"),
    ("controller", {"kind": "lqr", "k_v": 1.0}, "controller: unknown key"),
    ("controller", {"rate": -5.0}, "controller.rate"),
    ("controller", {"rate": 30.0}, "controller.rate"),
    ("controller", {"u_max": 0.0}, "controller.u_max"),
    ("controller", {"k_v": -1.0}, "controller.k_v"),
    ("controller", {"gain": 1.0}, "controller: unknown key"),
    ("plant", {"m_P": -1.0}, "plant"),
    ("plant", {"noise_position_m": -0.1}, "plant.noise_position_m"),
    ("plant", {"wheels": 4}, "plant: unknown key"),
])
def test_bad_values_are_named(section, values, named):
    with pytest.raises(ValueError, match=named.replace(".", r"\.").replace("(", r"\(")):
        parse_task(with_(section, **values), source="t.toml")


def test_missing_reference_is_named():
    data = dict(BASE)
    del data["reference"]
    with pytest.raises(ValueError, match="reference: missing"):
        parse_task(data)


def test_plant_overrides_change_only_the_plant():
    task = parse_task(with_("plant", m_P=1.1, k_S=0.2))
    assert task.plant_params.m_P == 1.1 and task.scenario.params.m_P == 1.0
    assert task.plant_params.k_S == 0.2


def test_a_task_lists_several_controllers_each_kind_once():
    data = with_("reference")
    data["controller"] = [{"kind": "pid"}, {"kind": "lqr", "rate": 100.0}]
    task = parse_task(data)
    assert task.controller_kinds == ("pid", "lqr")
    assert task.with_controller("lqr").rate == 100.0 and task.with_controller("lqr").controller_kinds == ("lqr",)
    data["controller"] = [{"kind": "pid"}, {"kind": "pid"}]
    with pytest.raises(ValueError, match=r"controller\[1\]\.kind: 'pid' appears twice"):
        parse_task(data, source="t.toml")


def test_the_lqr_of_a_task_with_noisy_rates_holds_its_integral_only_above_the_rate_noise():
    # ė_y read from rates with noise σ has noise of about r σ: a steadiness bound below twice that
    # holds ∫e_y on most samples, and the offset stays (a filter between sensors and controller, or a
    # reference without a path, leaves the bound free).
    for name in shipped_tasks():
        task = load_task(name)
        on_path = task.reference_spec["kind"] in ("line", "circle", "figure8", "waypoints")
        if task.noise.rate_rad_s > 0 and task.estimator is None and on_path and "lqr" in task.controller_kinds:
            bound = task.with_controller("lqr").gains.steady_rate_m_s
            assert bound >= 2 * task.scenario.params.r * task.noise.rate_rad_s, name
