"""The linear surrogate of a consistency run (runtime/estimation/surrogate.py): the recording NumPy
reference is the C filter over a short line run; the draws of the recorded linear system have the
filter's covariance (their NEES averages to the dimension within its standard error), and that
check fails when one recorded noise or map is left out; blocks of draws are scored as
`consistency` scores runs; driven by the truth's own draws the recorded linear system tracks the
run's own error, and does not without one of those draws; driven source by source, the draws of
the sources' models together have the filter's covariance, and do not with one source left out;
a redrawn log's IMU noise is a new draw of the sensor's σ; the command writes the blocks and
the trace, and refuses a bad block size or number of draws."""
import json

import numpy as np
import pytest

from runtime.estimation.consistency import nees, nees_band, run_once
from runtime.estimation.surrogate import (SOURCES, RecordingReference, block_statistics, driven, main, record_run,
                                          redrawn_imu, simulate, simulated_log, sources, truth_draws)
from runtime.verification.ekf_reference import NB

from .test_tasks import short

DRAWS = 600


@pytest.fixture(scope="module")
def recorded():
    return record_run(short("line"), None, seed=0)


def test_the_recording_reference_is_the_c_filter_over_a_short_line_run(recorded):
    c = run_once(short("line"), None, seed=0)
    sigma = np.sqrt(np.diagonal(c["P"], axis1=1, axis2=2))
    assert np.max(np.abs(np.sqrt(np.diagonal(recorded["P"], axis1=1, axis2=2)) - sigma) / sigma) <= 1e-8
    assert np.max(np.abs(recorded["e"] - c["e"]) / sigma) <= 1e-8


def in_band(rec, e):
    """The share of the scored samples whose average NEES over the draws lies in its 95 % band."""
    anees = np.mean([nees(draw, rec["P"]) for draw in e], axis=0)
    low, high = nees_band(18, len(e))
    return float(np.mean((anees >= low) & (anees <= high)))


def nees_offset(rec, e):
    """How far the draws' NEES, averaged over the scored samples and the draws, lies from the 18
    of a consistent filter, in standard errors (the draws are independent, the samples of one
    draw are not: the standard error is the spread of the draws' own averages over √draws)."""
    per_draw = np.array([nees(draw, rec["P"]).mean() for draw in e])
    return float((per_draw.mean() - 18.0) / (per_draw.std(ddof=1) / np.sqrt(len(per_draw))))


def test_the_surrogates_draws_have_the_filters_covariance(recorded):
    assert abs(nees_offset(recorded, simulate(recorded, DRAWS, seed=1))) <= 4.0


def test_blocks_of_the_surrogate_are_scored_as_consistency_scores_runs(recorded):
    e = simulate(recorded, 100, seed=1)
    blocks = block_statistics(recorded, e, block=50)
    assert len(blocks) == 2
    assert blocks[0]["inside"] == pytest.approx(in_band(recorded, e[:50]))


class Muted(RecordingReference):
    """Records nothing of `kind` ("noise" or "linear") while the methods `within` run."""
    within, kind = (), None

    def __getattribute__(self, name):
        attr = super().__getattribute__(name)
        if name in type(self).within:
            def muted(*args, **kwargs):
                self.muting = True
                try:
                    return attr(*args, **kwargs)
                finally:
                    self.muting = False
            return muted
        return attr

    def noise(self, rows, C, gain=None):
        if not (getattr(self, "muting", False) and self.kind == "noise" and len(rows) > 5):
            super().noise(rows, C, gain)

    def linear(self, T):
        if not (getattr(self, "muting", False) and self.kind == "linear"):
            super().linear(T)


class WithoutUpdateNoise(Muted):
    """The updates' K R Kᵀ left out (the held disturbance's own prior kept)."""
    within, kind = ("_update", "update_imu_held"), "noise"


class WithoutPredictMap(Muted):
    """The predicts' maps left out: the error stays where it was, their noise added."""
    within, kind = ("predict",), "linear"


@pytest.mark.parametrize("broken", [WithoutUpdateNoise, WithoutPredictMap])
def test_the_covariance_check_fails_for_a_surrogate_without_one_term(broken, monkeypatch):
    from runtime.estimation import surrogate
    monkeypatch.setattr(surrogate, "RecordingReference", broken)
    rec = record_run(short("line"), None, seed=0)
    assert abs(nees_offset(rec, simulate(rec, DRAWS, seed=1))) > 10.0


def test_the_command_writes_the_blocks_and_their_summary(tmp_path):
    out = tmp_path / "surrogate.json"
    assert main(["line", "--duration", "4", "--draws", "100", "--block", "50", "--out", str(out)]) == 0
    report = json.loads(out.read_text())
    assert len(report["blocks"]) == report["summary"]["blocks"] == 2
    assert report["summary"]["inside_mean"] == pytest.approx(np.mean([b["inside"] for b in report["blocks"]]))


def test_the_command_refuses_fewer_draws_than_a_block(capsys):
    assert main(["line", "--draws", "10", "--block", "50"]) == 2
    assert "--draws" in capsys.readouterr().err


@pytest.fixture(scope="module")
def draws():
    return truth_draws(short("line"), None, seed=0)


def tracking(rec, lin):
    """The RMS over the samples and the components of the run's error less the linear system's, in σ."""
    sigma = np.sqrt(np.diagonal(rec["P"], axis1=1, axis2=2))
    return float(np.sqrt(np.mean(((rec["e"] - lin) / sigma) ** 2)))


def test_driven_by_the_truths_draws_the_linear_model_tracks_the_runs_error(recorded, draws):
    assert tracking(recorded, driven(recorded, draws)) <= 0.25


@pytest.mark.parametrize("left_out", ["imu", "encoders", "a"])
def test_the_tracking_fails_without_one_of_the_truths_draws(recorded, draws, left_out):
    assert tracking(recorded, driven(recorded, {**draws, left_out: 0 * draws[left_out]})) > 0.25


def test_the_command_compares_a_run_with_its_driven_linear_model(tmp_path):
    out = tmp_path / "driven.json"
    assert main(["line", "--duration", "4", "--driven", "1", "--out", str(out)]) == 0
    report = json.loads(out.read_text())
    assert report["seeds"] == [0]
    k = report["components"].index("tilt_x")
    assert report["mean"]["tilt_x"] == pytest.approx([report["run"][0][k], report["linear"][0][k]])


def sources_nees_offset(rec, draws, model_draws=300):
    """How far the NEES of the sources' model draws summed, averaged over the samples and the
    draws, lies from 18, in standard errors of the draws' own averages."""
    total = sources(rec, draws, model_draws, seed=1)[:, 1:].sum(axis=0)
    per_draw = np.array([nees(draw, rec["P"]).mean() for draw in total])
    return float((per_draw.mean() - 18.0) / (per_draw.std(ddof=1) / np.sqrt(len(per_draw))))


def test_the_sources_models_together_have_the_filters_covariance(recorded, draws):
    assert abs(sources_nees_offset(recorded, draws)) <= 4.0


def test_the_covariance_check_fails_with_one_source_left_out(recorded, draws, monkeypatch):
    from runtime.estimation import surrogate
    monkeypatch.setitem(surrogate._READINGS, "imu", surrogate._READINGS["imu"][:3])   # no accel_z
    assert sources_nees_offset(recorded, draws) < -10.0


def test_the_command_traces_a_run_source_by_source(tmp_path):
    out = tmp_path / "trace.json"
    assert main(["line", "--duration", "4", "--trace", "1", "--model-draws", "3", "--redraw", "--out", str(out)]) == 0
    report = json.loads(out.read_text())
    assert report["sources"] == list(SOURCES)
    assert np.shape(report["redrawn"]) == np.shape(report["redrawn_sigma"]) == (1, 18)
    assert np.shape(report["own"]) == np.shape(report["of_model"]) == (1, len(SOURCES), 18)
    k = report["components"].index("tilt_x")
    assert report["mean"]["linear"]["tilt_x"] == pytest.approx(report["linear"][0][k], abs=1e-4)


def test_the_command_refuses_fewer_than_two_model_draws(capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["line", "--trace", "1", "--model-draws", "1"])
    assert exit_.value.code == 2
    assert "--model-draws" in capsys.readouterr().err


def test_a_redrawn_logs_imu_noise_is_a_new_draw_of_the_sensors_sigma(draws):
    log = simulated_log(short("line"), None, seed=0)
    new = truth_draws(None, None, 0, log=redrawn_imu(log, draws, 5))["imu"]
    sigma = np.repeat([log.sensors.imu.gyro_noise, log.sensors.imu.accel_noise], 3)
    assert np.allclose(new.std(axis=0) / sigma, 1.0, atol=0.1)
    assert max(abs(np.corrcoef(new[:, j], draws["imu"][:, j])[0, 1]) for j in range(6)) < 0.15
