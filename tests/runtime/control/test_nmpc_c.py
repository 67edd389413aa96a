"""The C NMPC (c/src/sr_nmpc.c, runtime/control/nmpc.py's NmpcC): its box QP solver equals DAQP on
random and recorded QPs, its prediction node equals the Python NMPC's to the integrators' error,
and a short closed loop tracks as the Python NMPC does."""
import dataclasses
import re

import numpy as np
import pytest

from bindings._sr import ffi, lib
from runtime.casadi_model import parameter_vector
from runtime.control import nmpc
from runtime.control.benchmark import run_task
from conftest import ROOT
from runtime.control.nmpc_c import (FIRMWARE_HORIZON, FIRMWARE_NODE_PERIODS, daqp_solution, design_initializer,
                                    lockstep_gaps, main, ratio_line, recorded_qps, task_header)
from runtime.control.offsets import with_controller
from runtime.control.task import load_task
from runtime.params import Params

PARAMS = Params.paper_simulation()
#: What the C solution may differ from DAQP's by (double).
QP_TOL = 1e-8


def c_solution(H, g, lb, ub):
    n = len(g)
    x = np.zeros(n)
    work, iwork = np.zeros(n * n + 3 * n), np.zeros(2 * n, dtype=np.intc)
    iterations = ffi.new("int *")
    double = lambda a: ffi.cast("double *", ffi.from_buffer(a))  # noqa: E731
    status = lib.sr_boxqp_solve(n, double(np.ascontiguousarray(H)), double(g), double(lb), double(ub), 20 * n,
                                double(x), double(work), ffi.cast("int *", ffi.from_buffer(iwork)), iterations)
    assert status == lib.SR_OK, ffi.string(lib.sr_status_string(status)).decode()
    return x


def random_qp(rng, n):
    M = rng.normal(size=(n, n))
    H = M @ M.T + rng.uniform(1e-3, 1.0) * n * np.eye(n)
    g = rng.normal(scale=rng.uniform(1.0, 30.0), size=n)
    lb = -rng.uniform(0.0, 1.0, size=n)
    return H, g, lb, lb + rng.uniform(0.0, 2.0, size=n)


def worst_gap_on_random_qps(perturb=0.0):
    rng = np.random.default_rng(11)
    worst, active = 0.0, 0
    for i in range(1000):
        H, g, lb, ub = random_qp(rng, 1 + i % 60)
        x = c_solution(H, g, lb, ub)
        x[0] += perturb
        ref, flag = daqp_solution(H, g, lb, ub)
        assert flag >= 1
        worst = max(worst, np.max(np.abs(x - ref)))
        active += np.any((x <= lb) | (x >= ub))
    return worst, active


def test_the_box_qp_equals_daqp_on_a_thousand_random_problems():
    worst, active = worst_gap_on_random_qps()
    assert worst < QP_TOL
    assert active > 500          # most problems have bounds active: the active set is exercised


def test_the_random_qp_comparison_fails_for_a_solution_off_by_a_millionth():
    assert worst_gap_on_random_qps(perturb=1e-6)[0] > QP_TOL


def circle(duration, kind="nmpc-c"):
    task = load_task("circle").with_controller("nmpc")
    task = dataclasses.replace(task, controllers=(dataclasses.replace(task.controllers[0], kind=kind),))
    return dataclasses.replace(task, scenario=dataclasses.replace(task.scenario, steps=round(duration / task.scenario.dt)))


def test_the_box_qp_equals_daqp_on_the_nmpcs_own_problems():
    qps = recorded_qps(circle(2.0), 40)
    assert len(qps) == 40
    gaps = [np.max(np.abs(x - daqp_solution(H, g, lb, ub)[0])) for H, g, lb, ub, x in qps]
    assert max(gaps) < QP_TOL
    assert any(np.any((x <= lb) | (x >= ub)) for _, _, lb, ub, x in qps)   # the limits are met on this start


def node_gap(kappa):
    """Largest gap between the C node (one RKMK4 step of the full model) and the Python NMPC's (RK4
    of the reduced field), relative to the change over the node; and of their sensitivities."""
    from runtime.model import Model
    model = Model(PARAMS)
    rng = np.random.default_rng(5)
    z, u = rng.normal(scale=0.1, size=nmpc.NZ_N), rng.normal(scale=0.2, size=2)
    theirs = [np.array(out) for out in nmpc.node_function(0.1)(z, u, 0.3, kappa, parameter_vector(PARAMS))]
    z_next, A, B = np.zeros(nmpc.NZ_N), np.zeros(nmpc.NZ_N ** 2), np.zeros(2 * nmpc.NZ_N)
    double = lambda a: ffi.cast("double *", ffi.from_buffer(a))  # noqa: E731
    assert lib.sr_nmpc_node(model._model, double(z), double(u), 0.3, kappa, 0.1, double(z_next), double(A),
                            double(B)) == lib.SR_OK
    state = np.abs(z_next - theirs[0].ravel()).max() / np.abs(theirs[0].ravel() - z).max()
    jac = max(np.abs(A.reshape(nmpc.NZ_N, -1) - theirs[1]).max(), np.abs(B.reshape(nmpc.NZ_N, -1) - theirs[2]).max())
    return state, jac


@pytest.mark.parametrize("kappa", [0.0, 0.5])
def test_the_c_node_is_the_python_nmpcs_to_the_integrators_error(kappa):
    # Two fourth-order steps of 0.1 s of the same flow (the full model's RKMK4 and the reduced
    # field's RK4; the cross-track integral by the trapezoid): within a percent of the change.
    state, jac = node_gap(kappa)
    assert state < 1e-2
    assert jac < 2e-2


def test_a_short_circle_tracks_as_the_python_nmpc():
    _, _, theirs = run_task(circle(3.0, "nmpc"))
    _, _, ours = run_task(circle(3.0))
    assert abs(ours["cross_track_max_m"] - theirs["cross_track_max_m"]) < 1e-3
    assert abs(ours["motor_energy_j"] - theirs["motor_energy_j"]) < 0.05 * theirs["motor_energy_j"]


def _figure8_meeting_error(**gains):
    """The largest cross-track error [m] of the C NMPC on the nominal figure eight (the task file's
    settings, `gains` changed) from 40 s to 60 s: the lobes meet at about 42 s."""
    from runtime.control.closed_loop import simulate_closed_loop
    from runtime.state import IDX_Q
    task = with_controller(load_task("figure8"), "nmpc-c")
    spec = task.controllers[0]
    task = dataclasses.replace(task, controllers=(dataclasses.replace(spec, gains=dataclasses.replace(spec.gains,
                                                                                                      **gains)),))
    reference = task.reference()
    result = simulate_closed_loop(task.plant_params, task.controller(), reference, task.scenario.x0, 60.0,
                                  task.scenario.dt, task.scenario.method)
    e = reference.cross_track(result.trajectory[::10, IDX_Q][:, :2])
    return np.abs(e[result.time[::10] >= 40.0]).max()


def test_the_c_nmpc_holds_the_figure_eight_where_its_lobes_meet():
    # The figure-eight task sizes the cross-track error 2 cm: about 53 mm at worst where the curvature
    # flips from +0.5 to -0.5 1/m (docs/control.md, "Robustness over many robots").
    assert _figure8_meeting_error() < 0.08


def test_the_lobes_meeting_check_fails_with_the_cross_track_error_sized_as_elsewhere():
    # Sized 0.15 m (the default), the plan keeps to the operating points' jump of lean and drifts about 0.14 m.
    assert _figure8_meeting_error(cross_track_m=0.15) > 0.08


def _meeting_lockstep_median(**python_gains):
    """The median per-sample torque gap [N m] of the Python NMPC handed the C NMPC's memory, over the
    figure eight's lobes meeting (40-46 s; runtime/control/nmpc_c.py, `lockstep_gaps`)."""
    return float(np.median(lockstep_gaps(load_task("figure8"), 40.0, 46.0, **python_gains)))


def test_the_python_nmpc_handed_the_c_memory_solves_the_figure_eights_meeting_as_the_c_nmpc():
    # Sample by sample the two formulations agree (measured 2.9e-4 N m median, 9.4e-3 at worst) where
    # their closed loops part (docs/control.md, "Equal to the Python NMPC").
    assert _meeting_lockstep_median() < 1e-3


def test_the_lockstep_check_fails_for_a_python_nmpc_with_its_cross_track_error_sized_5_percent_larger():
    # cross_track_m 0.021 instead of 0.02 in the Python NMPC alone: 3.8e-3 N m median.
    assert _meeting_lockstep_median(cross_track_m=0.021) > 1e-3


def test_handing_the_memory_over_refuses_a_sloped_model():
    task = load_task("circle").with_controller("nmpc")
    sloped = dataclasses.replace(task, scenario=dataclasses.replace(
        task.scenario, params=task.scenario.params.replace(slope=0.05)))
    c_task_ = with_controller(sloped, "nmpc-c")
    with pytest.raises(ValueError, match="slope"):
        c_task_.controller().hand_memory_to(sloped.controller())


def test_a_horizon_beyond_the_c_capacity_is_named():
    with pytest.raises(ValueError, match="horizon"):
        nmpc.NmpcC(PARAMS, gains=nmpc.NmpcGains(horizon=lib.SR_NMPC_MAX_HORIZON + 1))


def test_the_design_header_holds_the_c_design():
    controller = circle(0.1).controller()
    text = design_initializer(controller)
    assert f".horizon = {controller.n}," in text
    assert f".r = SR_C({controller._r!r})," in text
    assert text.count("SR_C(") == 7 + 2 * nmpc.NZ_N + controller._c.n_speeds + controller._c.n_curvatures + \
        controller._c.n_speeds * controller._c.n_curvatures * (nmpc.NZ_N + 2 + 2 * nmpc.NZ_N ** 2)


#: The firmware example's design (c/examples/firmware_nmpc.c), written by `make generate`.
SHIPPED_HEADER = ROOT / "generated" / "nmpc_task.h"
_NUMBER = re.compile(r"(?<![\w.])-?\d+\.?\d*(?:e[-+]?\d+)?")


def same_design(text, other):
    """The two headers are the same text but for their numbers, and those agree within the spread of
    LAPACK builds (the Riccati cost-to-go's last bits vary with the CPU)."""
    a, b = [np.array([float(v) for v in _NUMBER.findall(t)]) for t in (text, other)]
    return _NUMBER.sub("#", text) == _NUMBER.sub("#", other) and a.shape == b.shape and \
        np.allclose(a, b, rtol=1e-7, atol=1e-10)


@pytest.fixture(scope="module")
def fresh_header():
    return task_header("circle", FIRMWARE_HORIZON, FIRMWARE_NODE_PERIODS)


def test_the_shipped_firmware_design_is_the_current_design(fresh_header):
    assert same_design(SHIPPED_HEADER.read_text(), fresh_header), "stale: rerun make generate"


def test_the_shipped_design_check_fails_for_one_number_changed_in_its_sixth_digit(fresh_header):
    text = SHIPPED_HEADER.read_text()
    i = text.index("P_path")
    j = i + _NUMBER.search(text[i:]).start()
    value = _NUMBER.match(text, j).group()
    changed = text[:j] + repr(float(value) * (1 + 1e-6) + 1e-6) + text[j + len(value):]
    assert not same_design(changed, fresh_header)


def test_the_bench_line_gives_the_python_to_c_ratio_of_each_percentile():
    out = ratio_line((0.2, 0.4), (2.0, 8.0))
    assert "called from Python: C NMPC p50 0.200 ms, p99 0.400 ms" in out
    assert "Python / C: 10 (p50), 20 (p99)" in out


def test_a_negative_python_timing_span_is_a_named_error(capsys):
    assert main(["--timing", "--against-python", "-1"]) == 2
    assert "--against-python: must be >= 0 s" in capsys.readouterr().err

