"""The Monte Carlo consistency of the EKF (runtime/estimation/consistency.py): the NEES and 3σ
checks pass errors drawn from the covariance they are scored against and flag a covariance four
times too large or too small; the physical components see a heading and a joint error where
they belong; the command runs a few short seeded runs and writes its table, figure and summary.
The long Monte Carlo itself is `make consistency`."""
import json

import numpy as np
import pyarrow.parquet as pq
import pytest

from runtime.estimation.consistency import (COMPONENTS, OBSERVABLE, consistency, main, nees, nees_band,
                                            transform)
from runtime.so3 import rot_x, rot_z
from runtime.state import IDX_RS, IDX_RY, initial_state

RUNS, SAMPLES = 50, 200


def synthetic_runs(scale=1.0, fixes=True, seed=0):
    """RUNS runs whose errors are drawn from P, scored against scale · P."""
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(18, 18)) / 6
    P = A @ A.T + np.diag(np.linspace(0.01, 1.0, 18))
    L = np.linalg.cholesky(P)
    return [{"seed": k, "t": np.arange(SAMPLES) * 0.1, "e": rng.normal(size=(SAMPLES, 18)) @ L.T,
             "P": np.broadcast_to(scale * P, (SAMPLES, 18, 18)), "fixes": fixes} for k in range(RUNS)]


def test_nees_is_the_squared_error_over_the_variance_in_one_dimension():
    assert nees(np.array([[2.0]]), np.array([[[4.0]]]))[0] == pytest.approx(1.0)


def test_the_band_brackets_the_number_of_components():
    low, high = nees_band(18, RUNS)
    assert low < 18 < high and high - low < 4


def test_errors_drawn_from_the_covariance_are_consistent():
    report = consistency(synthetic_runs())
    assert report["inside"] >= 0.9
    assert min(report["within_3_sigma"].values()) >= 0.99
    assert report["passes"]


@pytest.mark.parametrize("scale", [4.0, 0.25])
def test_a_covariance_four_times_too_large_or_too_small_is_flagged_inconsistent(scale):
    report = consistency(synthetic_runs(scale))
    assert report["inside"] < 0.1
    assert not report["passes"]


def test_a_covariance_four_times_too_small_breaks_the_three_sigma_share():
    report = consistency(synthetic_runs(0.25))
    assert max(report["within_3_sigma"].values()) < 0.99


def test_without_fixes_only_the_observable_components_are_scored_and_the_rest_drift():
    report = consistency(synthetic_runs(fixes=False))
    assert report["components"] == list(OBSERVABLE) and report["dims"] == len(OBSERVABLE)
    assert set(report["drift"]) == {"heading", "q_x", "q_y"}
    assert report["drift"]["heading"]["ratio_median"] == pytest.approx(1.0, abs=0.2)


def test_a_heading_error_of_the_shell_is_the_heading_component_alone():
    x = initial_state(r=0.2)
    x[IDX_RS] = rot_x(0.3).ravel()                          # a tilted shell: its z axis is not the world's
    xi = 0.01 * np.linalg.inv(rot_x(0.3)) @ np.array([0.0, 0.0, 1.0])   # about the world's vertical
    e = transform(x[None], "yoke")[0] @ np.concatenate([xi, np.zeros(15)])
    assert e[COMPONENTS.index("heading")] == pytest.approx(0.01)
    assert np.allclose(np.delete(e, COMPONENTS.index("heading")), 0.0, atol=1e-15)


def test_a_yoke_angle_error_tilts_an_imu_on_the_yoke_but_not_one_on_the_shell():
    x = initial_state(r=0.2)
    x[IDX_RS] = rot_z(0.7).ravel()
    x[IDX_RY] = rot_x(0.2).ravel()
    d = np.zeros(18)
    d[3] = 0.01                                             # θ_Y
    tilt = [COMPONENTS.index("tilt_x"), COMPONENTS.index("tilt_y")]
    assert np.linalg.norm((transform(x[None], "yoke")[0] @ d)[tilt]) == pytest.approx(0.01)
    assert np.linalg.norm((transform(x[None], "shell")[0] @ d)[tilt]) == 0.0


def test_the_command_writes_its_table_figure_and_summary(tmp_path):
    out = tmp_path / "c"
    status = main(["circle", "--runs", "2", "--duration", "3", "--scheduler", "serial", "--quiet",
                   "--out", str(out)])
    assert status in (0, 1)
    assert {p.name for p in out.iterdir()} == {"samples.parquet", "runs.csv", "nees.csv", "consistency.png",
                                               "summary.json"}
    summary = json.loads((out / "summary.json").read_text())
    assert summary["runs"] == 2 and summary["dims"] == 18 and summary["scored_from_s"] >= 1.5
    table = pq.read_table(out / "samples.parquet")
    assert set(table.column("seed").to_pylist()) == {0, 1}
    assert np.isfinite(table.column("nees").to_numpy()).all()


def test_the_command_refuses_an_unknown_task_in_one_line(tmp_path, capsys):
    assert main(["no-such-task", "--runs", "2", "--out", str(tmp_path / "c")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and err.count("\n") == 1
