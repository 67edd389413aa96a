"""The import structure of runtime/: no import cycle, and the independent models load no kernels and no derivation."""
import ast
import pathlib
import subprocess
import sys

from conftest import ROOT

#: Modules that must import without `bindings` (the compiled kernels) and without `derive`.
INDEPENDENT = ("runtime.so3", "runtime.verification.reference", "runtime.verification.alternatives.kane",
               "runtime.verification.contact", "runtime.verification.steppers",
               "runtime.verification.sensor_reference")

#: Run in a fresh interpreter: any import of bindings or derive raises ImportError.
_BLOCKER = """
import importlib.abc, sys
class Blocked(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path, target=None):
        if name.split(".")[0] in ("bindings", "derive"):
            raise ImportError("blocked: " + name)
sys.meta_path.insert(0, Blocked())
"""


def module_name(path, root):
    parts = list(path.relative_to(root).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def import_graph(package_dir):
    """{module: set of modules of the same top-level package it imports}, from the source (every
    import statement, also those inside functions).  `from .x import y` counts x.y when y is a module."""
    root = package_dir.parent
    top = package_dir.name
    modules = {module_name(p, root): p for p in package_dir.rglob("*.py")}
    graph = {}
    for name, path in modules.items():
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        edges = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                targets = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    anchor = package.split(".")[:len(package.split(".")) - (node.level - 1)]
                    base = ".".join(anchor + ([base] if base else []))
                targets = [base] + [f"{base}.{alias.name}" for alias in node.names]
            else:
                continue
            edges |= {t for t in targets if t in modules and t.split(".")[0] == top and t != name}
        graph[name] = edges
    return graph


def find_cycle(graph):
    """One import cycle as a list of modules [a, b, ..., a], or None."""
    state = {}

    def visit(node, stack):
        state[node] = "open"
        stack.append(node)
        for nxt in sorted(graph[node]):
            if state.get(nxt) == "open":
                return stack[stack.index(nxt):] + [nxt]
            if nxt not in state:
                found = visit(nxt, stack)
                if found:
                    return found
        stack.pop()
        state[node] = "done"
        return None

    for node in sorted(graph):
        if node not in state:
            found = visit(node, [])
            if found:
                return found
    return None


def test_runtime_has_no_import_cycle():
    graph = import_graph(ROOT / "runtime")
    assert "runtime.model" in graph and "runtime.validation" in graph["runtime.model"]
    assert find_cycle(graph) is None, " -> ".join(find_cycle(graph))


def test_the_cycle_finder_finds_a_cycle_through_a_relative_import(tmp_path):
    package = tmp_path / "pkg"
    (package / "sub").mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "sub" / "__init__.py").write_text("")
    (package / "a.py").write_text("from .sub import b\n")
    (package / "sub" / "b.py").write_text("def f():\n    from ..a import g\n")
    assert find_cycle(import_graph(package)) == ["pkg.a", "pkg.sub.b", "pkg.a"]
    (package / "sub" / "b.py").write_text("import math\n")
    assert find_cycle(import_graph(package)) is None


def _import_blocked(modules):
    code = _BLOCKER + "".join(f"import {m}\n" for m in modules) + (
        "print(sorted(m for m in sys.modules if m.split('.')[0] in ('bindings', 'derive')))\n")
    return subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True)


def test_the_independent_models_import_without_the_kernels_and_the_derivation():
    out = _import_blocked(INDEPENDENT)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[]"


def test_the_blocker_does_stop_a_module_that_needs_the_kernels():
    out = _import_blocked(["runtime.state"])
    assert out.returncode != 0 and "blocked: bindings" in out.stderr


def test_the_public_api_is_importable_from_the_package():
    code = "from runtime import *; import runtime; print(sorted(runtime.__all__))"
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert "Model" in out.stdout and "project_state" in out.stdout


def test_a_misspelled_api_name_is_an_attribute_error():
    import runtime
    try:
        runtime.Modle
    except AttributeError as exc:
        assert "Modle" in str(exc)
    else:
        raise AssertionError("runtime.Modle did not raise")


def test_every_module_under_runtime_is_in_the_graph():
    graph = import_graph(ROOT / "runtime")
    files = list(pathlib.Path(ROOT / "runtime").rglob("*.py"))
    assert len(graph) == len(files)
