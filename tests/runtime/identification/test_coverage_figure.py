"""`python -m runtime identify-coverage --figure`: the calibration figure of the fits' intervals."""
import json

from runtime.identification import coverage


def test_the_coverage_command_draws_its_calibration_figure(tmp_path):
    out, figure = tmp_path / "coverage.json", tmp_path / "calibration.png"
    assert coverage.main(["--params", "k_Y", "--fits", "2", "--duration", "1", "--full-state", "--out", str(out),
                          "--figure", str(figure)]) == 0
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    result = json.loads(out.read_text())
    assert len(result["trials"]) == 2
    # the combinations the fitted entry moves are recorded per fit and summarised
    assert set(result["trials"][0]["combinations"]["k_Y"]) >= {"truth", "estimate", "relative_error", "inside"}
    assert result["combinations"]["k_Y"]["fits"] == 2



EXCITATION = """description = "a short torque program"
dt = 0.01
steps = 100

[[torque]]
from_step = 1
to_step = 25
u_Y = 0.3
u_P = -0.1

[[torque]]
from_step = 26
to_step = 50
u_Y = -0.2
u_P = 0.15

[[torque]]
from_step = 51
to_step = 100
u_Y = 0.1
u_P = -0.05
"""


def test_the_coverage_command_fits_sensor_logs_driven_by_an_excitation_file(tmp_path):
    program, out = tmp_path / "excite.toml", tmp_path / "coverage.json"
    program.write_text(EXCITATION)
    assert coverage.main(["--params", "k_Y", "--fits", "1", "--duration", "1", "--excitation", str(program),
                          "--max-evaluations", "3", "--out", str(out)]) == 0
    trial = json.loads(out.read_text())["trials"][0]
    log, _, _ = coverage.simulated_log("k_Y", 1.0, 0, excitation=str(program))
    assert log.torque_at([0.1, 0.3, 0.7]).tolist() == [[0.3, -0.1], [-0.2, 0.15], [0.1, -0.05]]
    assert trial["passed"] in (True, False) and trial["cpu_time_s"] > 0 and trial["sigma"][0] > 0


def test_an_excitation_shorter_than_the_log_is_named(tmp_path, capsys):
    program = tmp_path / "excite.toml"
    program.write_text(EXCITATION)
    assert coverage.main(["--params", "k_Y", "--fits", "1", "--duration", "2", "--excitation", str(program),
                          "--out", str(tmp_path / "c.json")]) == 2
    assert "excitation" in capsys.readouterr().err
