"""`python -m runtime COMMAND` run in-process with wrong commands, options and option values: exit
status 2 and a last line on stderr that names the option, never a traceback (the options are
refused before anything runs, so no case starts a long run)."""
import contextlib
import io

import pytest
from hypothesis import given
from hypothesis import strategies as st
from wrong_inputs import SETTINGS

from runtime.__main__ import COMMANDS, main

NOT_A_NUMBER = ["abc", "", "nan", "inf", "-inf", "0x", "1,5"]
NOT_POSITIVE = ["0", "-1", "-1e308", "-0.0"]
NOT_AN_INTEGER = ["1.5", "1e3", "2.0"]

#: command -> (arguments that make the rest valid, {option: wrong values}).
OPTIONS = {
    "soak": ([], {"--steps": NOT_A_NUMBER + NOT_POSITIVE + NOT_AN_INTEGER,
                  "--states": NOT_A_NUMBER + NOT_POSITIVE + NOT_AN_INTEGER,
                  "--chunk": NOT_A_NUMBER + NOT_POSITIVE + NOT_AN_INTEGER,
                  "--seed": NOT_A_NUMBER + ["-1", "-5"] + NOT_AN_INTEGER,
                  "--dt": NOT_A_NUMBER + NOT_POSITIVE,
                  "--max-speed": NOT_A_NUMBER + ["-1", "-1e308"],
                  "--method": ["", "euler", "RKMK4"]}),
    "run": (["tilted-pendulum", "--out", "{tmp}"], {"--dt": NOT_A_NUMBER + NOT_POSITIVE + ["2", "1e-10"],
                                                     "--steps": NOT_A_NUMBER + NOT_POSITIVE + NOT_AN_INTEGER
                                                                + ["10000001"],
                                                     "--method": ["", "euler", "RKMK4"]}),
    "control": (["--tasks", "circle", "--out", "{tmp}"], {"--duration": ["abc", "", "nan", "-inf"] + NOT_POSITIVE,
                                                         "--tasks": ["", ",", "no-such-task", "{tmp}"]}),
    "sweep": (["t-shape-uncertainty", "--out", "{tmp}/sweep"],
              {"--samples": NOT_A_NUMBER + NOT_POSITIVE + NOT_AN_INTEGER,
               "--workers": NOT_A_NUMBER + NOT_POSITIVE + NOT_AN_INTEGER,
               "--samples-per-task": NOT_A_NUMBER + NOT_POSITIVE + NOT_AN_INTEGER,
               "--connect-timeout": NOT_A_NUMBER + NOT_POSITIVE,
               "--scheduler": ["localhost:notaport", "localhost:99999", ":", "tcp://"]}),
    "bench": ([], {"--states": NOT_A_NUMBER + NOT_POSITIVE + NOT_AN_INTEGER,
                   "--loop-steps": NOT_A_NUMBER + NOT_POSITIVE + NOT_AN_INTEGER}),
    "estimate": (["{tmp}/log", "--out", "{tmp}/est"], {"--heading": NOT_A_NUMBER}),
    "identify": (["{tmp}/log", "--params", "k_Y", "--out", "{tmp}/fit"],
                 {"--segment": NOT_A_NUMBER + NOT_POSITIVE,
                  "--max-evaluations": NOT_A_NUMBER + NOT_POSITIVE + NOT_AN_INTEGER}),
    "identify-coverage": (["--params", "k_Y", "--out", "{tmp}/coverage.json"],
                          {"--fits": NOT_A_NUMBER + NOT_POSITIVE + NOT_AN_INTEGER,
                           "--duration": NOT_A_NUMBER + NOT_POSITIVE}),
    "identify-bench": (["--out", "{tmp}/bench"], {"--rounds": NOT_A_NUMBER + NOT_POSITIVE + NOT_AN_INTEGER,
                                                  "--duration": NOT_A_NUMBER + NOT_POSITIVE}),
    "surrogate": (["line", "--draws", "2", "--block", "2"], {"--draws": NOT_A_NUMBER + ["0", "1", "-1"] + NOT_AN_INTEGER,
                                                             "--block": NOT_A_NUMBER + ["0", "1", "-1"] + NOT_AN_INTEGER,
                                                             "--seed": NOT_A_NUMBER + ["-1"] + NOT_AN_INTEGER,
                                                             "--duration": NOT_A_NUMBER + NOT_POSITIVE,
                                                             "--driven": NOT_A_NUMBER + ["0", "-1"] + NOT_AN_INTEGER,
                                                             "--trace": NOT_A_NUMBER + ["0", "-1"] + NOT_AN_INTEGER,
                                                             "--model-draws": NOT_A_NUMBER + ["0", "1", "-1"]
                                                             + NOT_AN_INTEGER}),
    "consistency": (["circle", "--out", "{tmp}/c"], {"--runs": NOT_A_NUMBER + ["0", "1", "-1"] + NOT_AN_INTEGER,
                                                     "--first-seed": NOT_A_NUMBER + ["-1"] + NOT_AN_INTEGER,
                                                     "--workers": NOT_A_NUMBER + ["0", "-1"] + NOT_AN_INTEGER,
                                                     "--duration": NOT_A_NUMBER + NOT_POSITIVE,
                                                     "--scheduler": ["nowhere", "tcp://host:0"]}),
    "sense": (["t-shape", "--out", "{tmp}/log"], {"--seed": NOT_A_NUMBER + ["-1", "-5"] + NOT_AN_INTEGER,
                                                   "--duration": NOT_A_NUMBER + NOT_POSITIVE}),
    "export": (["mjcf", "--out", "{tmp}/robot.xml"], {"--u-max": NOT_A_NUMBER + NOT_POSITIVE}),
    "compare-mujoco": (["tilted-yoke", "--out", "{tmp}"], {"--timesteps": NOT_A_NUMBER + NOT_POSITIVE + ["0.5", "1e-3,"]}),
    "excite": (["--params", "k_S", "--duration", "2", "--out", "{tmp}/p.toml"],
               {"--duration": NOT_A_NUMBER + NOT_POSITIVE, "--harmonics": NOT_A_NUMBER + NOT_POSITIVE + NOT_AN_INTEGER,
                "--iterations": NOT_A_NUMBER + NOT_POSITIVE + NOT_AN_INTEGER,
                "--seed": NOT_A_NUMBER + ["-1", "-5"] + NOT_AN_INTEGER, "--params": ["", ",", "k_X", "k_S,k_S"]}),
    "noise-floor": ([], {"--hold": NOT_A_NUMBER + NOT_POSITIVE + ["inf", "nan", "1e9"], "--sensors": ["no-such-set", ""]}),
    "heading-seeds": ([], {"--seeds": ["3-1", "a-b", "-1-2", ""], "--kind": ["pid", ""],
                           "--set": ["x", "heading_rad", "heading_rad=abc", "no_such_gain=1", "heading_rad=-1"]}),
    "sweep-bench": ([], {"--samples": NOT_A_NUMBER + NOT_POSITIVE, "--samples-per-task": NOT_A_NUMBER + NOT_POSITIVE,
                         "--noop-tasks": NOT_A_NUMBER + NOT_POSITIVE, "--rounds": NOT_A_NUMBER + NOT_POSITIVE}),
}
CASES = [(command, option) for command, (_, options) in OPTIONS.items() for option in options]


def cli(argv):
    """(exit status, stderr) of `python -m runtime ...` run in-process; a traceback fails the test."""
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            status = main(argv)
        except SystemExit as exit_:
            status = exit_.code
    return status, err.getvalue()


@pytest.mark.parametrize("command, option", CASES, ids=[f"{c}{o}" for c, o in CASES])
@SETTINGS
@given(data=st.data())
def test_a_wrong_option_value_is_refused_in_one_line_naming_the_option(tmp_path_factory, command, option, data):
    tmp = str(tmp_path_factory.mktemp("cli"))
    base, options = OPTIONS[command]
    value = data.draw(st.sampled_from(options[option])).replace("{tmp}", tmp)
    status, err = cli([command] + [a.replace("{tmp}", tmp) for a in base] + [f"{option}={value}"])
    last = err.strip().splitlines()[-1] if err.strip() else ""
    assert status == 2, err
    assert "Traceback" not in err and (option.lstrip("-") in last or value in last), err


@pytest.mark.parametrize("command", sorted(COMMANDS))
@SETTINGS
@given(option=st.from_regex(r"\A--[a-z][a-z-]{0,12}\Z"))
def test_an_unknown_option_is_refused_naming_it(tmp_path_factory, command, option):
    tmp = str(tmp_path_factory.mktemp("cli"))
    base = [a.replace("{tmp}", tmp) for a in OPTIONS.get(command, ([],))[0]] if command != "view" else [tmp]
    status, err = cli([command] + base + [f"{option}-no-such-option"])
    assert status == 2 and "Traceback" not in err
    assert f"{option}-no-such-option" in err.strip().splitlines()[-1]


@SETTINGS
@given(command=st.text(max_size=20).filter(lambda c: c not in COMMANDS and c not in ("-h", "--help")))
def test_an_unknown_command_prints_the_usage_with_status_2(command):
    status, err = cli([command])
    assert status == 2 and err.startswith("usage: python -m runtime COMMAND")


@SETTINGS
@given(name=st.text(st.characters(blacklist_characters="\x00/"), min_size=1, max_size=20))
def test_view_of_anything_but_a_replay_page_is_refused_naming_it(tmp_path_factory, name):
    folder = tmp_path_factory.mktemp("view")
    status, err = cli(["view", str(folder / name)])
    assert status == 2 and "Traceback" not in err and name in err


@pytest.mark.parametrize("command", ["stability", "envelope", "climbing"])
@pytest.mark.parametrize("where", ["{tmp}/no-such-folder/figure.png", "{tmp}", "{tmp}/file.txt/figure.png"])
def test_a_figure_that_cannot_be_written_is_refused_before_anything_runs(tmp_path, command, where):
    (tmp_path / "file.txt").write_text("a file, not a folder")
    target = where.replace("{tmp}", str(tmp_path))
    status, err = cli([command, target])
    assert status == 2 and "Traceback" not in err and target in err.strip().splitlines()[-1]


@pytest.mark.parametrize("content", [b"not json", b"\xff\xfe", None])
def test_bench_names_a_markdown_result_it_cannot_read(tmp_path, content):
    path = tmp_path / "result.json"
    if content is not None:
        path.write_bytes(content)
    status, err = cli(["bench", "--markdown", str(path)])
    assert status == 2 and "Traceback" not in err and f"--markdown: cannot read {path}" in err.strip().splitlines()[-1]
