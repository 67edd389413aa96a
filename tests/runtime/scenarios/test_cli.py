"""`python -m runtime run` (runtime/scenarios/cli.py): the files it writes and its exit statuses."""
import json

import numpy as np
import pytest

from runtime import Model, Params, initial_state
from runtime.scenarios import cli as scenario_cli


def read_csv(path):
    lines = path.read_text().splitlines()
    header = lines[0].split(",")
    rows = np.array([[float(v) for v in line.split(",")] for line in lines[1:]])
    return header, rows


def test_cli_writes_csv_figures_and_summary(tmp_path):
    assert scenario_cli.main(["t-shape", "--out", str(tmp_path), "--steps", "300", "--no-gif", "--quiet"]) == 0
    folder = tmp_path / "t-shape"
    names = sorted(p.name for p in folder.iterdir())
    assert names == sorted(["trajectory.csv", "summary.json", "trajectory.png", "inclinations.png",
                            "absolute_inclinations.png", "energy.png", "replay.html"])
    for png in folder.glob("*.png"):
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"

    header, rows = read_csv(folder / "trajectory.csv")
    columns = 1 + 3 + 3 * 9 + 5 + 2 + 1                         # t, q, R_S R_Y R_P, speeds, torques, E
    assert len(header) == rows.shape[1] == columns and len(set(header)) == columns
    assert rows.shape[0] == 301
    col = {name: i for i, name in enumerate(header)}
    model = Model(Params.paper_simulation())
    # The t-shape's first window (yoke, 0.1 N·m on steps 1-800, Section 5.3.3) covers all 300 steps.
    direct = model.simulate(initial_state(), 0.01, 300, np.tile([0.1, 0.0], (300, 1)))
    np.testing.assert_allclose(rows[:, col["t"]], 0.01 * np.arange(301), rtol=0, atol=1e-12)
    # Shortest repr round-trips: the file holds the simulated doubles exactly.
    np.testing.assert_array_equal(rows[:, [col["q_x"], col["q_y"], col["q_z"]]], direct[:, 27:30])
    np.testing.assert_array_equal(rows[:, col["R_S_13"]], direct[:, 2])
    np.testing.assert_array_equal(rows[:, col["R_Y_32"]], direct[:, 9 + 7])
    np.testing.assert_array_equal(rows[:, col["R_P_31"]], direct[:, 18 + 6])
    np.testing.assert_array_equal(rows[:, [col["w_S_x"], col["w_S_y"], col["w_S_z"], col["w_Y"], col["w_P"]]],
                                  direct[:, 30:35])
    assert np.all(rows[:, col["u_Y"]] == 0.1) and np.all(rows[:, col["u_P"]] == 0.0)
    assert rows[-1, col["E"]] == model.energy(direct[-1])

    summary = json.loads((folder / "summary.json").read_text())
    assert summary["final_position_m"] == direct[-1, 27:29].tolist()
    distances = np.hypot(direct[:, 27], direct[:, 28])
    assert summary["largest_excursion_m"] == pytest.approx(distances.max(), rel=1e-12)
    assert summary["steps"] == 300 and summary["method"] == "lie-euler"
    assert set(summary["final_inclinations_rad"]) == {"yoke_relative_to_shell", "pendulum_relative_to_yoke",
                                                      "yoke_normal_to_vertical", "pendulum_shaft_to_vertical"}
    assert summary["wall_time_s"]["simulation"] > 0


def test_cli_reports_a_bad_scenario_and_exits_2(tmp_path, capsys):
    assert scenario_cli.main(["no-such-scenario", "--out", str(tmp_path)]) == 2
    assert "no-such-scenario: no such scenario file" in capsys.readouterr().err
    assert scenario_cli.main(["t-shape", "--out", str(tmp_path), "--method", "rk99", "--no-gif"]) == 2
    assert "method: unknown integrator" in capsys.readouterr().err


def test_a_run_that_needs_more_friction_than_its_floor_gives_warns_and_says_so_in_its_summary(tmp_path, capsys):
    scenario = tmp_path / "slippery.toml"
    scenario.write_text('dt = 0.01\nsteps = 20\nfriction = 1e-6\n[params]\npreset = "paper_simulation"\n'
                        '[[torque]]\nfrom_step = 1\nto_step = 20\nu_Y = 0.5\n')
    assert scenario_cli.main([str(scenario), "--out", str(tmp_path / "out"), "--no-gif", "--no-replay"]) == 0
    warning = [line for line in capsys.readouterr().err.splitlines() if line.startswith("warning: slippery:")]
    assert len(warning) == 1 and "would slide" in warning[0]
    contact = json.loads((tmp_path / "out" / "slippery" / "summary.json").read_text())["contact"]
    assert contact["friction"] == 1e-6 and [flag["kind"] for flag in contact["flags"]] == ["slide"]
