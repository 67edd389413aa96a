"""`python -m runtime identify-coverage --figure`: the calibration figure of the fits' intervals."""
import json

from runtime.identification import coverage


def test_the_coverage_command_draws_its_calibration_figure(tmp_path):
    out, figure = tmp_path / "coverage.json", tmp_path / "calibration.png"
    assert coverage.main(["--params", "k_Y", "--fits", "2", "--duration", "1", "--full-state", "--out", str(out),
                          "--figure", str(figure)]) == 0
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert len(json.loads(out.read_text())["trials"]) == 2

