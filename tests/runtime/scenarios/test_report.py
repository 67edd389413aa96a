"""The outputs of a run (runtime/scenarios/report.py): the summary's numbers and atomic writing."""
import math
import pathlib

import pytest

from runtime import Params
from runtime.scenarios import report
from runtime.scenario import load_scenario, run_scenario


def test_summary_energy_balance_for_the_tilted_pendulum(results):
    """Motors off: the energy lost is m_P g (l/2)(1 − cos π/4) (pendulum from π/4 to hanging).

    The summary's damping integral exceeds it at dt = 0.01 (measured by 10%):
    explicit Lie-Euler feeds energy into the oscillation and the dampers take
    it out again.  The balance residual (initial − dissipated − final) must
    therefore vanish at first order: halve with dt (measured ratios 2.12, 2.06).
    """
    p = Params.paper_simulation()
    expected = p.m_P * p.g * (p.paper_params.l / 2) * (1 - math.cos(math.pi / 4))
    energy = report.summary(results["tilted-pendulum"])["energy_J"]
    assert energy["initial"] - energy["final"] == pytest.approx(expected, rel=1e-9)
    assert energy["motor_work"] == 0.0
    assert expected < energy["dissipated"] < 1.15 * expected
    base = load_scenario("tilted-pendulum")
    residuals = [report.summary(run_scenario(base.with_overrides(dt=base.dt / k)))["energy_J"]["balance_residual"]
                 for k in (1, 2, 4)]
    assert residuals[0] == energy["balance_residual"]
    assert 1.7 < residuals[0] / residuals[1] < 2.4 and 1.7 < residuals[1] / residuals[2] < 2.4


# -- atomic writing -------------------------------------------------------------------------------------------
def test_rendering_failure_leaves_no_partial_file(tmp_path, monkeypatch, results):
    folder = tmp_path / "run"
    folder.mkdir()
    (folder / "trajectory.png").write_bytes(b"old figure")

    def failing_savefig(self, fname, *args, **kwargs):
        pathlib.Path(fname).write_bytes(b"\x89PNG half a file")
        raise RuntimeError("renderer crashed")

    monkeypatch.setattr("matplotlib.figure.Figure.savefig", failing_savefig)
    with pytest.raises(RuntimeError, match="renderer crashed"):
        report.write_outputs(results["tilted-yoke"], folder, gif=False)
    assert (folder / "trajectory.png").read_bytes() == b"old figure"    # untouched
    assert sorted(p.name for p in folder.iterdir()) == ["trajectory.csv", "trajectory.png"]  # no temporaries
