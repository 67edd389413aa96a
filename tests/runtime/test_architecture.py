"""runtime/ is a core and applications beside it: the import-linter contracts of pyproject.toml hold,
they fail for a planted violation, they cover every module of runtime/, and `python -m runtime` is
the one command-line entry."""
import ast
import os
import pathlib
import shutil
import subprocess
import sys
import tomllib

import pytest

from conftest import ROOT

CONFIG = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]
CONTRACTS = {c["id"]: c for c in CONFIG["contracts"]}
CORE = CONTRACTS["core"]["source_modules"]
APPLICATIONS = CONTRACTS["applications"]["modules"]


def lint_imports(package_parent):
    """(exit code, output) of lint-imports with the project's contracts, on the `runtime` found in `package_parent`."""
    shutil.copy(ROOT / "pyproject.toml", package_parent / "pyproject.toml")
    env = dict(os.environ, PYTHONPATH=str(package_parent))
    run = subprocess.run([sys.executable, "-c", "import sys; from importlinter.cli import lint_imports_command; "
                          "sys.exit(lint_imports_command())", "--no-cache"],
                         cwd=package_parent, env=env, capture_output=True, text=True)
    return run.returncode, run.stdout + run.stderr


def test_runtime_keeps_its_import_contracts(tmp_path):
    shutil.copytree(ROOT / "runtime", tmp_path / "runtime", ignore=shutil.ignore_patterns("__pycache__"))
    code, output = lint_imports(tmp_path)
    assert code == 0, output


@pytest.mark.parametrize("module, line, contract", [
    ("model.py", "import runtime.control", "The core imports no application"),
    ("scenario.py", "from .scenarios import report", "The core imports no application"),
    ("control/geometry.py", "import runtime.verification.sampling", "Applications import one another only"),
    ("verification/flow.py", "from ..control import geometry", "Applications import one another only"),
    ("sweep/task.py", "import runtime.verification", "Applications import one another only"),
    ("scenarios/outline.py", "import runtime.sweep", "Applications import one another only"),
])
def test_the_contracts_fail_for_a_planted_violation(tmp_path, module, line, contract):
    shutil.copytree(ROOT / "runtime", tmp_path / "runtime", ignore=shutil.ignore_patterns("__pycache__"))
    path = tmp_path / "runtime" / module
    path.write_text(path.read_text() + f"\n{line}  # planted\n")
    code, output = lint_imports(tmp_path)
    assert code != 0
    assert f"{contract}" in output and "BROKEN" in output, output


def test_every_module_of_runtime_is_in_the_core_or_an_application():
    """A module in neither list would be bound by no contract."""
    top = {p.stem for p in (ROOT / "runtime").glob("*.py")} - {"__init__", "__main__"}
    packages = {p.parent.name for p in (ROOT / "runtime").glob("*/__init__.py")}
    assert sorted(f"runtime.{m}" for m in top) == sorted(CORE)
    assert sorted(f"runtime.{p}" for p in packages) == sorted(APPLICATIONS)
    assert sorted(CONTRACTS["core"]["forbidden_modules"]) == sorted(APPLICATIONS)


def script_entries(source):
    """Line numbers of `if __name__ == "__main__":` blocks in `source`."""
    return [node.lineno for node in ast.walk(ast.parse(source))
            if isinstance(node, ast.If) and isinstance(node.test, ast.Compare)
            and isinstance(node.test.left, ast.Name) and node.test.left.id == "__name__"
            and any(isinstance(c, ast.Constant) and c.value == "__main__" for c in node.test.comparators)]


def test_a_script_entry_is_recognised():
    assert script_entries('import sys\n\nif __name__ == "__main__":\n    sys.exit(main())\n') == [3]
    assert script_entries("if __name__ == '__main__': main()\n") == [1]


def test_python_m_runtime_is_the_only_command_line_entry():
    found = {str(p.relative_to(ROOT)): script_entries(p.read_text(encoding="utf-8"))
             for p in (ROOT / "runtime").rglob("*.py")}
    assert {path: lines for path, lines in found.items() if lines} == {"runtime/__main__.py": [found["runtime/__main__.py"][0]]}


def test_every_command_names_a_module_with_main():
    import importlib

    from runtime.__main__ import COMMANDS
    for command, (module, _) in COMMANDS.items():
        assert callable(getattr(importlib.import_module(module), "main", None)), command
