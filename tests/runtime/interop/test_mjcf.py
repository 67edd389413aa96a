"""The MJCF twin: MuJoCo loads it with our bodies, runs like the kernels, and a wrong export shows."""
import json

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")

from runtime import Params                                       # noqa: E402
from runtime.__main__ import main                                # noqa: E402
from runtime.interop import mjcf, mujoco_compare                 # noqa: E402
from runtime.scenario import load_scenario                       # noqa: E402

#: A general robot with every feature the export writes: an off-centre yoke with products of inertia,
#: an off-axis pendulum, geared rotors, a slope.
GENERAL = Params().replace(c_Y=(0.01, 0.02, -0.03), J_Y=((0.12, 0.004, 0.0), (0.004, 0.46, 0.003), (0.0, 0.003, 0.57)),
                           c_P=(0.01, 0.0, -0.12), J_P=((4e-4, 0.0, 1e-5), (0.0, 5e-4, 0.0), (1e-5, 0.0, 3e-4)),
                           j_mY=4e-6, n_Y=60.0, j_mP=4e-6, n_P=-30.0, slope=0.01)

#: The short comparison: 1.5 s of each scenario at the exported settings (RK4 at 1 ms).  Measured:
#: 9.3e-7 m in all three (the contact's static penetration, 4e-7 m, and its settling); the full runs
#: stay within 2.9e-6 m (t-shape, 100 s) and 9.3e-7 m (the tilted runs; docs/interop.md).  The bound leaves a factor 10 for the platform: 1e-5 m.
#: The planted errors below move the centre by 8e-5 m (shell damping 10 % high) to 2.5e-2 m
#: (hinge axes swapped) within the same 1.5 s.
SHORT_STEPS = 150
SHORT_TOLERANCE = 1e-5


def full_tensor(model, body):
    """MuJoCo's inertia of a body about its centre, in the body frame (body_iquat, body_inertia)."""
    R = np.empty(9)
    mujoco.mju_quat2Mat(R, model.body_iquat[body])
    R = R.reshape(3, 3)
    return R @ np.diag(model.body_inertia[body]) @ R.T


def test_mujoco_loads_the_export_with_our_masses_centres_and_tensors():
    model = mujoco.MjModel.from_xml_string(mjcf.to_mjcf(GENERAL))
    shell, yoke, pendulum = (model.body(name).id for name in ("shell", "yoke", "pendulum"))
    assert model.body_mass[[shell, yoke, pendulum]] == pytest.approx([GENERAL.m_S, GENERAL.m_Y, GENERAL.m_P], rel=1e-15)
    assert np.allclose(model.body_ipos[yoke], GENERAL.c_Y, rtol=0, atol=1e-15)
    assert np.allclose(model.body_ipos[pendulum], GENERAL.c_P, rtol=0, atol=1e-15)
    rotors = np.diag([0.0, GENERAL.j_mP, 0.0])        # the pendulum motor's rotor rides on the yoke's y axis
    assert np.allclose(full_tensor(model, yoke), np.array(GENERAL.J_Y) + rotors, rtol=0, atol=1e-14)
    assert np.allclose(full_tensor(model, pendulum), GENERAL.J_P, rtol=0, atol=1e-14)
    assert np.allclose(full_tensor(model, shell), np.diag([GENERAL.j_S + GENERAL.j_mY, GENERAL.j_S, GENERAL.j_S]),
                       rtol=0, atol=1e-15)


def test_the_export_has_our_joints_motors_and_gravity():
    model = mujoco.MjModel.from_xml_string(mjcf.to_mjcf(GENERAL, u_max=0.5))
    yoke, pendulum = model.joint("yoke"), model.joint("pendulum")
    assert list(yoke.axis) == [1, 0, 0] and list(pendulum.axis) == [0, 1, 0]
    assert model.dof_damping[[yoke.dofadr[0], pendulum.dofadr[0]]] == pytest.approx([GENERAL.k_Y, GENERAL.k_P])
    assert model.dof_damping[model.joint("shell_rotation").dofadr[0]:][:3] == pytest.approx([GENERAL.k_S] * 3)
    assert model.dof_armature[[yoke.dofadr[0], pendulum.dofadr[0]]] == pytest.approx([4e-6 * 3600, 4e-6 * 900])
    assert model.actuator_gear[:, 0] == pytest.approx([60.0, -30.0])
    assert model.actuator_ctrlrange.ravel() == pytest.approx([-0.5 / 60, 0.5 / 60, -0.5 / 30, 0.5 / 30])
    assert model.opt.gravity == pytest.approx([-9.81 * np.sin(0.01), 0.0, -9.81 * np.cos(0.01)])


def test_the_pendulum_rods_zero_moment_is_raised_only_to_a_negligible_one():
    model = mujoco.MjModel.from_xml_string(mjcf.to_mjcf(Params.paper_simulation()))
    moments = model.body_inertia[model.body("pendulum").id]
    assert moments.min() == pytest.approx(mjcf.MIN_PRINCIPAL * moments.max())


def short_run(name, steps=SHORT_STEPS):
    scenario = load_scenario(name).with_overrides(steps=steps)
    ours = mujoco_compare.kernels_trace(scenario)
    return mujoco_compare.differences(ours, mujoco_compare.mujoco_trace(scenario, mjcf.EXPORTED))


@pytest.mark.parametrize("name", ["t-shape", "tilted-pendulum", "tilted-yoke"])
def test_mujoco_follows_the_kernels_over_a_short_run(name):
    diff = short_run(name)
    assert diff["position"].max() <= SHORT_TOLERANCE
    assert diff["attitude"].max() <= SHORT_TOLERANCE / 0.3


def swap_hinge_axes(text):
    return text.replace('axis="1 0 0" damping', 'axis="T" damping').replace(
        'axis="0 1 0" damping', 'axis="1 0 0" damping').replace('axis="T" damping', 'axis="0 1 0" damping')


def heavier_pendulum(text):
    return text.replace('mass="1.0"', 'mass="1.1"')


def stronger_shell_damping(text):
    return text.replace('damping="0.16"', 'damping="0.176"')


@pytest.mark.parametrize("plant, name", [(swap_hinge_axes, "tilted-yoke"), (heavier_pendulum, "tilted-pendulum"),
                                         (stronger_shell_damping, "t-shape")])
def test_a_wrong_export_fails_the_short_comparison(monkeypatch, plant, name):
    export = mjcf.to_mjcf
    monkeypatch.setattr(mjcf, "to_mjcf", lambda *args, **kwargs: plant(export(*args, **kwargs)))
    assert plant(export(Params.paper_simulation())) != export(Params.paper_simulation())
    assert short_run(name)["position"].max() > SHORT_TOLERANCE


def test_the_command_writes_a_model_mujoco_loads(tmp_path):
    robot = tmp_path / "robot.toml"
    robot.write_text("m_P = 1.5\nn_Y = 60.0\nj_mY = 4e-6\n")
    out = tmp_path / "robot.xml"
    assert main(["export", "mjcf", "--params", str(robot), "--out", str(out)]) == 0
    model = mujoco.MjModel.from_xml_path(str(out))
    assert model.body_mass[model.body("pendulum").id] == 1.5
    assert model.actuator_gear[0, 0] == 60.0


@pytest.mark.parametrize("content, named", [("m_P = -1.0\n", "m_P"), ("m_Q = 1.0\n", "m_Q"),
                                            ("c_P = [0.0, 0.0, -0.5]\n", "c_P"), ("m_P = \n", "robot.toml")])
def test_a_bad_params_file_is_refused_naming_the_field(tmp_path, capsys, content, named):
    robot = tmp_path / "robot.toml"
    robot.write_text(content)
    out = tmp_path / "robot.xml"
    assert main(["export", "mjcf", "--params", str(robot), "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert err.startswith("export mjcf: ") and named in err and "Traceback" not in err
    assert not out.exists()


def test_a_missing_params_file_is_refused_naming_it(tmp_path, capsys):
    missing = tmp_path / "no-such-robot.toml"
    assert main(["export", "mjcf", "--params", str(missing), "--out", str(tmp_path / "robot.xml")]) == 1
    assert str(missing) in capsys.readouterr().err


def test_export_without_a_kind_lists_the_kinds(capsys):
    assert main(["export"]) == 2
    err = capsys.readouterr().err
    assert "fmu" in err and "mjcf" in err


def test_compare_mujoco_writes_its_summary_table_and_figures(tmp_path):
    scenario = tmp_path / "short.toml"
    scenario.write_text('dt = 0.01\nsteps = 20\nmethod = "rkmk4"\n[params]\npreset = "paper_simulation"\n'
                        '[initial]\ntheta_P = 0.5\n[[torque]]\nfrom_step = 1\nto_step = 10\nu_Y = 0.1\n')
    out = tmp_path / "out"
    assert main(["compare-mujoco", str(scenario), "--out", str(out), "--timesteps", "2e-3,1e-3"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    labels = [row["setting"] for row in summary["settings"]]
    assert labels[:2] == ["exported, dt 2 ms", "exported, dt 1 ms"] and len(labels) == 2 + 5
    assert all(row["position_target_met"] for row in summary["settings"])
    rows = (out / "comparison.csv").read_text().splitlines()
    assert len(rows) == 1 + len(labels) * 21
    assert (out / "comparison.png").stat().st_size > 0 and (out / "convergence.png").stat().st_size > 0


def test_compare_mujoco_refuses_a_timestep_that_does_not_divide_the_scenarios(tmp_path, capsys):
    assert main(["compare-mujoco", "tilted-yoke", "--out", str(tmp_path), "--timesteps", "3e-3"]) == 2
    assert "--timesteps" in capsys.readouterr().err
    assert not any(tmp_path.iterdir())


def test_an_out_file_in_a_missing_folder_is_refused_naming_it(tmp_path, capsys):
    out = tmp_path / "no-such-folder" / "robot.xml"
    with pytest.raises(SystemExit) as exit_:
        main(["export", "mjcf", "--out", str(out)])
    assert exit_.value.code == 2 and str(out) in capsys.readouterr().err
