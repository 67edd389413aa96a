"""Bad input to the Python API, simulation guards and the CLI's output folders (docs/robustness.md).

Every bad input raises a ValueError naming the argument, the entry and the rule; a simulation
that leaves the model's domain stops with SimulationStopped naming the step and keeping the rows
computed before it; the CLI never overwrites a run's outputs unless asked and marks partial ones.
"""
import json

import numpy as np
import pytest

from runtime import (ENERGY_TOL, ROTATION_TOL, KernelError, Model, Params, SimulationStopped, initial_state,
                     project_state)
from runtime.__main__ import main as cli
from runtime.so3 import rot_x, rot_y, rot_z


@pytest.fixture(scope="module")
def model():
    return Model(Params.paper_simulation())


@pytest.fixture
def x():
    return initial_state(theta_Y=0.3, theta_P=-0.4, R_S=rot_z(0.2) @ rot_x(0.1), w_S=(0.2, -0.1, 0.0), w_Y=0.5)


# -- arrays -----------------------------------------------------------------------------------
@pytest.mark.parametrize("dtype, kind", [(np.complex128, "complex"), (bool, "bool"), (object, "object")])
def test_state_of_a_non_real_dtype_is_rejected_by_name(model, x, dtype, kind):
    with pytest.raises(ValueError, match=rf"^x: expected real numbers .*got {kind}"):
        model.accel(x.astype(dtype))


def test_integer_arrays_are_accepted_as_reals(model):
    u = np.array([0, 0])
    assert np.array_equal(model.accel(initial_state(), u), model.accel(initial_state()))


def test_state_of_the_wrong_shape_names_the_shapes(model):
    with pytest.raises(ValueError, match=r"x: expected shape \(35,\) or \('B', 35\), got \(34,\)"):
        model.accel(np.zeros(34))


def test_ragged_input_is_a_value_error(model):
    with pytest.raises(ValueError, match="^u: expected an array of real numbers"):
        model.accel(initial_state(), [[0.1], [0.1, 0.2]])


# -- state rules ------------------------------------------------------------------------------
def test_rotation_tolerance_is_the_c_librarys():
    assert ROTATION_TOL == 1e-6


def test_a_nan_entry_is_named_by_index_and_meaning(model, x):
    x[12] = np.nan
    with pytest.raises(KernelError, match=r"^x: x\[12\] \(R_Y\[1,0\]\) is nan, expected a finite number$"):
        model.accel(x)


@pytest.mark.parametrize("method", ["inertia", "energy", "equilibrium_residual", "rhs", "step"])
def test_every_kernel_checks_the_state_in_full(model, x, method):
    x[11] = 1e-3  # R_Y[0,2]: not read by the kernels, but R_Y must be a rotation about x
    with pytest.raises(KernelError, match=r"R_Y \(x\[9:18\]\) must be a rotation about x: R_Y\[0,2\]"):
        getattr(model, method)(x)


def test_non_orthonormal_R_S_reports_the_defect_and_the_tolerance(model, x):
    x[0:9] = (1 + 2e-6) * x[0:9]
    with pytest.raises(KernelError, match=r"R_S \(x\[0:9\]\) is not orthonormal: max \|RᵀR − I\| = 4e-06 "
                                          r"exceeds the tolerance 1e-06") as info:
        model.accel(x)
    assert info.value.status == 3  # SR_ERR_NOT_ROTATION


def test_orthonormality_within_the_tolerance_is_accepted(model, x):
    x[0:9] = (1 + 2e-7) * x[0:9]
    assert np.all(np.isfinite(model.accel(x)))


def test_a_reflection_is_not_a_rotation(model, x):
    x[0:9] = -x[0:9]
    with pytest.raises(KernelError, match=r"R_S .* det = -1, a reflection"):
        model.energy(x)


def test_R_P_must_be_a_rotation_about_y(model, x):
    x[18:27] = rot_x(0.2).ravel()
    with pytest.raises(KernelError, match=r"R_P \(x\[18:27\]\) must be a rotation about y"):
        model.accel(x)


def test_q_z_must_equal_r(model, x):
    x[29] = 0.25
    with pytest.raises(KernelError, match=r"x\[29\] \(q_z\) = 0.25 must equal r = 0.3") as info:
        model.accel(x)
    assert info.value.status == 7  # SR_ERR_CONSTRAINT


def test_batch_errors_name_the_row(model, x):
    X = np.tile(x, (5, 1))
    X[3, 30] = np.inf
    with pytest.raises(KernelError, match=r"^x\[3\]: x\[3\]\[30\] \(w_S\[0\]\) is inf"):
        model.accel(X)


def test_a_non_finite_torque_is_named(model, x):
    with pytest.raises(ValueError, match=r"^u: u\[1\] is nan"):
        model.accel(x, [0.1, np.nan])


# -- re-projection -------------------------------------------------------------------------------
def test_project_state_makes_a_nearly_valid_state_valid(model, x):
    rng = np.random.default_rng(1)
    bad = x + 1e-4 * rng.normal(size=35)
    with pytest.raises(KernelError):
        model.accel(bad)
    fixed = model.project(bad)
    assert np.all(np.isfinite(model.accel(fixed)))
    assert np.abs(fixed - x).max() < 1e-3
    assert np.array_equal(fixed[30:], bad[30:]) and np.array_equal(fixed[27:29], bad[27:29])


def test_project_state_keeps_a_valid_state_to_rounding(x):
    assert np.abs(project_state(x, 0.3) - x).max() < 1e-15


def test_project_state_refuses_non_finite_entries(x):
    x[5] = np.nan
    with pytest.raises(ValueError, match=r"x\[5\] \(R_S\[1,2\]\)"):
        project_state(x, 0.3)


# -- parameters -----------------------------------------------------------------------------------
def test_paper_parameters_whose_inertias_underflow_are_rejected():
    tiny = 1e-200
    with pytest.raises(ValueError, match="^Params.j_S: must be > 0, got 0.0"):
        Params.paper(r=tiny, b=tiny, h=tiny, l=tiny)


def test_paper_parameters_whose_inertias_overflow_are_rejected():
    big = 1e200
    with pytest.raises(ValueError, match="^Params: the paper's parameters .* give no valid robot"):
        Params.paper(r=big, b=0.2 * big, h=0.5 * big, l=0.2 * big)


def test_parameters_that_overflow_the_model_are_rejected():
    with pytest.raises(KernelError, match="^params: the model overflows"):
        Model(Params().replace(r=1e200, j_S=1e200))


# -- simulation guards ------------------------------------------------------------------------------
def test_default_energy_tolerance_is_documented_value():
    assert ENERGY_TOL == 0.5


def frictionless():
    return Model(Params.paper_simulation(k_S=0, k_Y=0, k_P=0))


def test_energy_rising_without_input_stops_the_run_with_the_rows_so_far():
    with pytest.raises(SimulationStopped, match=r"^x: simulation stopped at step \d+ \(t = .*\): the energy rose "
                                                r"without input power") as info:
        frictionless().simulate(initial_state(theta_P=1.0), dt=0.05, steps=2000)
    stop = info.value
    assert stop.status == 10 and 1 <= stop.step < 2000
    assert stop.time == pytest.approx((stop.step - 1) * 0.05)
    assert stop.trajectory.shape == (stop.step, 35) and np.all(np.isfinite(stop.trajectory))
    assert stop.state is not None


def test_energy_guard_can_be_disabled():
    traj = frictionless().simulate(initial_state(theta_P=1.0), dt=0.05, steps=400, energy_tol=None)
    assert np.all(np.isfinite(traj))


def test_energy_guard_tolerance_must_be_non_negative(model):
    with pytest.raises(ValueError, match="^energy_tol:"):
        model.simulate(initial_state(), 0.01, 10, energy_tol=-1)


def test_a_state_that_overflows_stops_the_run_at_its_step(model):
    x0 = initial_state(w_S=(1e300, 0, 0))   # finite, but |ω|² (in the accelerations) overflows in the first step
    with pytest.raises(SimulationStopped, match=r"simulation stopped at step 1 \(t = 0 → 0.01 s\): the state "
                                                r"or an intermediate result became non-finite") as info:
        model.simulate(x0, 0.01, 10, energy_tol=None)
    assert len(info.value.trajectory) == 1


def nearly_orthonormal_spinning_state(d=0.9e-6):
    """R_S = I + S/2 with S = d(11ᵀ − I): within tolerance, but spinning moves the defect to 2d."""
    x = initial_state(theta_Y=0.3, theta_P=0.2, w_S=(3.0, -2.0, 5.0))
    x[0:9] = (np.eye(3) + 0.5 * d * (np.ones((3, 3)) - np.eye(3))).ravel()
    return x


def test_rotation_drifting_out_of_tolerance_stops_the_run(model):
    with pytest.raises(SimulationStopped, match=r"the state drifted off the constraints: R_S .* not orthonormal") as info:
        model.simulate(nearly_orthonormal_spinning_state(), 0.01, 2000, method="rkmk4")
    assert info.value.status == 3 and info.value.step % 16 == 0


def test_feedback_simulation_has_the_same_guards():
    with pytest.raises(SimulationStopped, match="energy rose"):
        frictionless().simulate(initial_state(theta_P=1.0), dt=0.05, steps=2000, u=lambda t, x: (0.0, 0.0))


def test_guards_do_not_change_a_valid_run(model):
    x0 = initial_state(theta_P=0.7)
    u = np.tile([0.05, 0.0], (500, 1))
    assert np.array_equal(model.simulate(x0, 0.01, 500, u), model.simulate(x0, 0.01, 500, u, energy_tol=None))


# -- the CLI: existing outputs, partial outputs --------------------------------------------------------
SHORT = ["tilted-yoke", "--steps", "20", "--no-gif", "--quiet"]


def test_cli_refuses_a_folder_that_holds_outputs(tmp_path, capsys):
    assert cli(["run", *SHORT, "--out", str(tmp_path)]) == 0
    before = (tmp_path / "tilted-yoke" / "summary.json").read_bytes()
    assert cli(["run", *SHORT, "--out", str(tmp_path)]) == 2
    assert "already holds the outputs of a run" in capsys.readouterr().err
    assert (tmp_path / "tilted-yoke" / "summary.json").read_bytes() == before


def test_cli_force_overwrites_and_removes_stale_outputs(tmp_path):
    folder = tmp_path / "tilted-yoke"
    folder.mkdir()
    (folder / "robot.gif").write_bytes(b"old")          # from an earlier run with the GIF
    (folder / "notes.txt").write_text("mine")           # not ours: kept
    assert cli(["run", *SHORT, "--out", str(tmp_path), "--force"]) == 0
    assert not (folder / "robot.gif").exists()
    assert (folder / "notes.txt").read_text() == "mine"
    assert json.loads((folder / "summary.json").read_text())["steps"] == 20


def test_cli_writes_marked_partial_outputs_when_a_guard_stops_the_run(tmp_path, capsys):
    scenario = tmp_path / "unstable.toml"
    scenario.write_text('dt = 0.05\nsteps = 2000\n[params]\nk_S = 0\nk_Y = 0\nk_P = 0\n'
                        '[initial]\ntheta_P = 1.0\n')
    assert cli(["run", str(scenario), "--out", str(tmp_path), "--no-gif", "--quiet"]) == 3
    err = capsys.readouterr().err
    assert "simulation stopped at step" in err and "trajectory.partial.csv" in err
    folder = tmp_path / "unstable"
    assert sorted(p.name for p in folder.iterdir()) == ["summary.partial.json", "trajectory.partial.csv"]
    summary = json.loads((folder / "summary.partial.json").read_text())
    rows = (folder / "trajectory.partial.csv").read_text().splitlines()
    assert len(rows) == 1 + summary["steps_computed"] + 1 and summary["stopped"]["step"] == summary["steps_computed"] + 1


def test_cli_reports_an_unwritable_output_folder(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("")
    assert cli(["run", *SHORT, "--out", str(blocker)]) == 2
    assert "cannot write the outputs" in capsys.readouterr().err
