"""Scenario, robot, task and sweep files made wrong in every way a file can be (bytes that are not
UTF-8, text that is not TOML, a value of the wrong TOML type, a NaN, an overflow-size number, a
key that is not there): loading gives a ValueError naming the file, or a valid object; through
the CLI, one line on stderr naming the file and exit status 2, never a traceback."""
import contextlib
import io
import pathlib
import re
import shutil

import pytest
from hypothesis import given
from hypothesis import strategies as st
from wrong_inputs import SETTINGS

from runtime.__main__ import main
from runtime.control.task import load_task, task_dir
from runtime.scenario import load_scenario
from runtime.sweep.spec import load_sweep

RUNTIME = pathlib.Path(__file__).resolve().parents[2] / "runtime"
#: (loader, a shipped file, how the CLI reads such a file).
KINDS = {
    "scenario": (load_scenario, RUNTIME / "scenarios" / "t-shape.toml", lambda p, out: ["run", str(p), "--out", str(out)]),
    "robot scenario": (load_scenario, RUNTIME / "scenarios" / "battery-geared.toml",
                       lambda p, out: ["run", str(p), "--out", str(out)]),
    "task": (load_task, task_dir() / "circle.toml", lambda p, out: ["control", "--tasks", str(p), "--out", str(out)]),
    "sweep": (load_sweep, RUNTIME / "sweep" / "t-shape-uncertainty.toml",
              lambda p, out: ["sweep", str(p), "--out", str(out)]),
}
WRONG_VALUES = ['"text"', "true", "false", "[1, \"a\"]", "{ a = 1 }", "nan", "inf", "-inf", "1e308", "-1e308",
                "-1", "0", "1979-05-27", "[]", "[[1.0]]", "1e-320", "\"\"", "9223372036854775807"]
ASSIGNMENT = re.compile(r"^(\s*[A-Za-z_][\w-]*\s*=\s*)(.+)$", re.M)


def copy_kind(kind, folder):
    """A writable copy of the shipped file of `kind` in `folder` (with the robot file it names)."""
    source = KINDS[kind][1]
    target = folder / source.name
    shutil.copy(source, target)
    if kind == "robot scenario":
        (folder / "robots").mkdir(exist_ok=True)
        shutil.copy(RUNTIME / "scenarios" / "robots" / "battery-geared.toml", folder / "robots" / "battery-geared.toml")
    return target


def mutated(text, draw):
    """`text` with one value, chosen by position, replaced by a wrong one (or a line cut in two)."""
    lines = list(ASSIGNMENT.finditer(text))
    match = lines[draw(st.integers(0, len(lines) - 1))]
    how = draw(st.sampled_from(["value", "value", "value", "cut", "duplicate"]))
    if how == "cut":
        return text[:match.start(2)] + "\n" + text[match.start(2):]
    if how == "duplicate":
        return text[:match.end()] + "\n" + match.group(0) + text[match.end():]
    return text[:match.start(2)] + draw(st.sampled_from(WRONG_VALUES)) + text[match.end(2):]


def refused_naming(loader, path, names):
    """Load `path`: a valid object, or a one-line ValueError that starts with the file's path and
    mentions every one of `names`."""
    try:
        return loader(str(path))
    except ValueError as exc:
        message = str(exc)
        assert message.startswith(str(path)), message
        assert all(name in message for name in names), message
        assert "\n" not in message.strip(), message
        return None


def cli(argv):
    """(exit status, stderr) of `python -m runtime ...` run in-process; a traceback fails the test."""
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            status = main(argv)
        except SystemExit as exit_:
            status = exit_.code
    return status, err.getvalue()


@pytest.mark.parametrize("kind", sorted(KINDS))
@SETTINGS
@given(data=st.data())
def test_a_file_with_a_wrong_value_loads_or_is_refused_naming_the_file(tmp_path_factory, kind, data):
    folder = tmp_path_factory.mktemp("files")
    path = copy_kind(kind, folder)
    path.write_text(mutated(path.read_text(), data.draw))
    refused_naming(KINDS[kind][0], path, [])


@SETTINGS
@given(data=st.data())
def test_a_robot_file_with_a_wrong_value_is_refused_naming_both_files(tmp_path_factory, data):
    folder = tmp_path_factory.mktemp("robot")
    path = copy_kind("robot scenario", folder)
    robot = folder / "robots" / "battery-geared.toml"
    robot.write_text(mutated(robot.read_text(), data.draw))
    if refused_naming(load_scenario, path, []) is None:
        refused_naming(load_scenario, path, [str(robot)])


NOT_UTF8 = [b"\xff\xfe\x00", b"dt = 0.01\n\xc3\x28 = 1\n", b"description = \"caf\xe9\"\n", b"\x80"]
NOT_TOML = [b"dt = \n", b"[params\n", b"= 1\n", b"dt = 0.01\ndt = 0.02\n", b"a = [1, 2\n"]


@pytest.mark.parametrize("content", NOT_UTF8 + NOT_TOML)
@pytest.mark.parametrize("kind", sorted(KINDS))
def test_bytes_that_are_not_toml_are_refused_naming_the_file(tmp_path, kind, content):
    path = copy_kind(kind, tmp_path)
    path.write_bytes(content)
    with pytest.raises(ValueError, match=rf"^{re.escape(str(path))}: ") as info:
        KINDS[kind][0](str(path))
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("content", NOT_UTF8 + NOT_TOML)
def test_a_robot_file_that_is_not_toml_is_named(tmp_path, content):
    path = copy_kind("robot scenario", tmp_path)
    robot = tmp_path / "robots" / "battery-geared.toml"
    robot.write_bytes(content)
    with pytest.raises(ValueError, match=rf"^{re.escape(str(path))}: params: robot: .*{re.escape(str(robot))}"):
        load_scenario(str(path))


@pytest.mark.parametrize("content", [NOT_UTF8[0], NOT_TOML[1], b'dt = "0.01"\n'])
@pytest.mark.parametrize("kind", ["scenario", "task", "sweep"])
def test_the_cli_names_a_bad_file_in_one_line_with_status_2(tmp_path, kind, content):
    path = copy_kind(kind, tmp_path)
    path.write_bytes(content)
    status, err = cli(KINDS[kind][2](path, tmp_path / "out"))
    assert status == 2, err
    assert "Traceback" not in err and str(path) in err.strip().splitlines()[-1]


@pytest.mark.parametrize("kind", ["scenario", "task", "sweep"])
def test_the_cli_names_a_missing_file(tmp_path, kind):
    status, err = cli(KINDS[kind][2](tmp_path / "no-such-file.toml", tmp_path / "out"))
    assert status == 2 and "Traceback" not in err and "no-such-file.toml" in err.strip().splitlines()[-1]


def test_control_names_an_unknown_shipped_task():
    status, err = cli(["control", "--tasks", "no-such-task"])
    assert status == 2 and "Traceback" not in err
    assert "no-such-task: no such task file" in err.strip().splitlines()[-1]
