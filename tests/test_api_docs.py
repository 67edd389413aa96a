"""The API reference (make docs) covers every public name: each has documentation to render.

Python: every public module of `runtime` (no leading underscore in its dotted name, no
`__main__`) has a docstring, and so has every public function, class, method and property in it,
as pdoc sees them (pdoc's own model of the modules, so the test and the rendered pages agree on
what is public: a module's `__all__` where it has one, else the names without a leading
underscore).  C: Doxygen, run with docs/Doxyfile (WARN_IF_UNDOCUMENTED, warnings fatal), prints
no warning for the public headers.  Each check is shown to fail on a planted undocumented name.
"""
import functools
import inspect
import os
import shutil
import subprocess
import sys
import warnings

import pytest

from conftest import ROOT

pdoc_doc = pytest.importorskip("pdoc.doc", reason="pdoc is not installed (pip install -e '.[docs]')")

sys.path.insert(0, str(ROOT / "docs"))
from build_python_api import public_modules  # noqa: E402  (docs/ holds the build script, not a package)

DOXYFILE = ROOT / "docs" / "Doxyfile"
INSTALL_DOXYGEN = ROOT / ".ci" / "install-doxygen"


def _is_property(namespace, name):
    return isinstance(namespace, pdoc_doc.Class) and isinstance(
        inspect.getattr_static(namespace.obj, name, None), (property, functools.cached_property))


def _undocumented_members(namespace, prefix, documented_values):
    """Public functions, classes, methods and properties of `namespace` without a docstring; and the
    constants its `__all__` names, unless documented here or, for one it imports, where it is
    defined (`documented_values`: ids of the values of documented module constants)."""
    missing = []
    exported = getattr(namespace.obj, "__all__", ()) if isinstance(namespace, pdoc_doc.Module) else ()
    for name, member in namespace.members.items():
        if name.startswith("_"):
            continue
        if isinstance(member, pdoc_doc.Variable):
            if _is_property(namespace, name) and not member.docstring.strip():
                missing.append(f"{prefix}{name}")
            elif name in exported and not member.docstring.strip() \
                    and id(getattr(namespace.obj, name)) not in documented_values:
                missing.append(f"{prefix}{name}")
            continue
        if not isinstance(member, (pdoc_doc.Function, pdoc_doc.Class)):
            continue
        # Names imported from outside the namespace's own package are documented where they live.
        if not member.modulename.startswith(namespace.modulename.split(".")[0]):
            continue
        if isinstance(namespace, pdoc_doc.Class) and member.taken_from[0] != namespace.modulename:
            continue
        if not member.docstring.strip():
            missing.append(f"{prefix}{name}")
        if isinstance(member, pdoc_doc.Class):
            missing += _undocumented_members(member, f"{prefix}{name}.", documented_values)
    return missing


def undocumented(package):
    """Public names of `package`'s public modules without documentation, as 'module: name'."""
    with warnings.catch_warnings():
        # What pdoc warns about (a name of __all__ it cannot find) fails the build: here too.
        warnings.simplefilter("error", UserWarning)
        modules = {name: pdoc_doc.Module(sys.modules[name]) for name in public_modules(package)}
        documented_values = {id(var.default_value) for module in modules.values()
                             for var in module.variables if var.docstring.strip()}
        missing = []
        for name, module in modules.items():
            if not module.docstring.strip():
                missing.append(f"{name}: (module docstring)")
            missing += [f"{name}: {member}" for member in _undocumented_members(module, "", documented_values)]
    return missing


def test_every_public_python_name_of_runtime_has_a_docstring():
    assert undocumented("runtime") == []


def test_the_python_check_names_a_planted_undocumented_function(tmp_path, monkeypatch):
    package = tmp_path / "planted_api"
    package.mkdir()
    (package / "__init__.py").write_text('"""A package."""\n__all__ = ["LIMIT", "SCALE"]\n'
                                         'LIMIT = 3.5\n"""The limit."""\n\nSCALE = [2.0]\n')
    (package / "tool.py").write_text('"""A module."""\n\n'
                                     'def documented():\n    """Does something."""\n\n\n'
                                     'def undocumented_helper():\n    return 1\n\n\n'
                                     'def _private():\n    return 2\n\n\n'
                                     'class Thing:\n    """A thing."""\n\n'
                                     '    def method(self):\n        return 3\n\n'
                                     '    @property\n    def size(self):\n        return 4\n')
    monkeypatch.syspath_prepend(str(tmp_path))
    assert undocumented("planted_api") == ["planted_api: SCALE", "planted_api.tool: undocumented_helper",
                                           "planted_api.tool: Thing.method", "planted_api.tool: Thing.size"]


def _doxygen_or_skip():
    if shutil.which("doxygen") is None and os.geteuid() == 0 and shutil.which("apt-get"):
        subprocess.run(["bash", str(INSTALL_DOXYGEN)], check=False, timeout=900)
    if shutil.which("doxygen") is None:
        pytest.skip("doxygen is not installed, and cannot be installed here (not root, or no apt-get)")


def run_doxygen(out, **overrides):
    """Doxygen with docs/Doxyfile (and `overrides` of its tags), output under `out`; its result."""
    config = DOXYFILE.read_text() + f"OUTPUT_DIRECTORY = {out}\n"
    config += "".join(f"{tag} = {value}\n" for tag, value in overrides.items())
    return subprocess.run(["doxygen", "-"], input=config, cwd=ROOT, capture_output=True, text=True, timeout=300)


def test_doxygen_documents_every_public_c_function_without_a_warning(tmp_path):
    _doxygen_or_skip()
    result = run_doxygen(tmp_path)
    assert (result.returncode, result.stdout + result.stderr) == (0, "")
    page = (tmp_path / "c" / "spherical__robot_8h.html").read_text()
    assert "sr_simulate_batch" in page and "sr_lqr_control" in page


def test_doxygen_fails_on_a_planted_undocumented_function(tmp_path):
    _doxygen_or_skip()
    include = tmp_path / "include"
    shutil.copytree(ROOT / "c" / "include", include)
    header = include / "spherical_robot.h"
    text = header.read_text()
    end = text.rindex("#ifdef __cplusplus")
    header.write_text(text[:end] + "int sr_planted(int n);\n\n" + text[end:])
    result = run_doxygen(tmp_path / "out", INPUT=include, EXCLUDE=include / "sr_real.h")
    assert result.returncode != 0
    assert "sr_planted" in result.stderr and "is not documented" in result.stderr
