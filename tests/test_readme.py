"""README.md is the front door: short, and everything it shows is checked.

* it has at most 250 lines and links every page of docs/;
* its Python and C quick starts (the fenced blocks after `<!-- quickstart:python -->` and
  `<!-- quickstart:c -->`) run: the Python one in this interpreter's environment, the C one compiled
  with the project's warnings as errors against the library that c/Makefile builds;
* the headline table, and docs/performance.md's tables, are what `python -m runtime bench-table`
  renders from the pinned reference run, so they change only when the reference does.
"""
import json
import os
import re
import shutil
import subprocess
import sys

import pytest

from c_build import make_shared
from conftest import ROOT
from runtime.bench import headline

README = ROOT / "README.md"
MAKE = shutil.which("make")
CC = os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")


def fenced_block(text, marker, language):
    """The fenced block of `language` right after the line `<!-- marker -->`."""
    match = re.search(rf"<!-- {re.escape(marker)} -->\n```{language}\n(.*?)\n```", text, re.S)
    assert match, f"README.md: no ```{language} block right after <!-- {marker} -->"
    return match.group(1)


def readme():
    return README.read_text(encoding="utf-8")


def test_readme_has_at_most_250_lines():
    assert len(readme().splitlines()) <= 250


def test_readme_links_every_docs_page():
    linked = set(re.findall(r"\]\((docs/[^)#\s]+\.md)", readme()))
    pages = {f"docs/{p.name}" for p in (ROOT / "docs").glob("*.md")}
    assert pages - linked == set()


def test_python_quick_start_is_at_most_15_lines():
    assert len(fenced_block(readme(), "quickstart:python", "python").splitlines()) <= 15


def test_c_quick_start_is_at_most_20_lines():
    assert len(fenced_block(readme(), "quickstart:c", "c").splitlines()) <= 20


def test_python_quick_start_runs(tmp_path):
    script = tmp_path / "quickstart.py"
    script.write_text(fenced_block(readme(), "quickstart:python", "python") + "\n")
    # Run from an empty folder, as a user would: the package must come from the installation.
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    result = subprocess.run([sys.executable, str(script)], cwd=tmp_path, env=env, capture_output=True, text=True,
                            timeout=300)
    assert result.returncode == 0, result.stderr[-3000:]
    assert re.search(r"shell centre after 5 s: \[.*\] m", result.stdout), result.stdout


def c_include_dirs():
    """The public header's folder (c/include once the C is laid out by kind, c/ before), and generated/."""
    public = ROOT / "c" / "include"
    return [public if (public / "spherical_robot.h").exists() else ROOT / "c", ROOT / "generated"]


@pytest.mark.skipif(not (MAKE and CC), reason="needs make and a C compiler")
def test_c_quick_start_compiles_without_warnings_and_runs(tmp_path_factory, tmp_path):
    build, made = make_shared(tmp_path_factory, "lib")
    assert made.returncode == 0, made.stderr[-3000:]
    source = tmp_path / "quickstart.c"
    source.write_text(fenced_block(readme(), "quickstart:c", "c") + "\n")
    program = tmp_path / "quickstart"
    flags = ["-std=c99", "-Wall", "-Wextra", "-Wpedantic", "-Werror", "-O2"]
    compiled = subprocess.run([CC, *flags, *(f"-I{d}" for d in c_include_dirs()), str(source),
                               str(build / "libsphericalrobot.a"), "-lm", "-o", str(program)],
                              capture_output=True, text=True)
    assert compiled.returncode == 0, compiled.stderr[-3000:]
    ran = subprocess.run([str(program)], capture_output=True, text=True, timeout=60)
    assert ran.returncode == 0, ran.stderr
    assert re.fullmatch(r"shell centre after 1 s: \(-?\d+\.\d{4}, -?\d+\.\d{4}\) m\n", ran.stdout), ran.stdout


def reference():
    return json.loads(headline.REFERENCE.read_text())


@pytest.mark.parametrize("section", sorted(headline.DOCUMENTS))
def test_quoted_tables_are_rendered_from_the_pinned_reference(section):
    document = headline.DOCUMENTS[section]
    quoted = headline.quoted_block(document.read_text(encoding="utf-8"), section)
    assert quoted is not None, f"{document.name}: no {headline.begin_marker(section)} block"
    assert quoted == headline.render(section, reference()), (
        f"{document.name} does not quote bench/results/reference.json: "
        f"run `python -m runtime bench-table --section {section} --write`")


@pytest.mark.parametrize("section", sorted(headline.DOCUMENTS))
def test_quoted_tables_no_longer_match_when_the_reference_changes(section):
    changed = reference()
    changed["c_loop"]["accel"]["ns"] *= 1.5
    quoted = headline.quoted_block(headline.DOCUMENTS[section].read_text(encoding="utf-8"), section)
    assert quoted != headline.render(section, changed)


def test_the_reference_is_one_of_the_stored_runs():
    """The pinned file is a copy of a run of `make bench`, not a file written by hand."""
    pinned = headline.REFERENCE.read_bytes()
    runs = [p for p in headline.REFERENCE.parent.glob("*.json") if p != headline.REFERENCE]
    assert any(p.read_bytes() == pinned for p in runs)
