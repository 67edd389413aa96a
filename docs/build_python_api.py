"""Renders the Python API reference with pdoc: `python docs/build_python_api.py OUT_DIR [PACKAGE ...]`.

Every public module of each package (no part of its dotted name with a leading underscore, so no
`__main__`), each rendered page listing the module's public names: its `__all__` where it has
one, else the names without a leading underscore.  A warning of pdoc's (a name of `__all__` it
cannot resolve, a module it cannot import) is an error: the exit status is then non-zero.
`tests/test_api_docs.py` uses `public_modules` to check that every name rendered is documented.
"""
import importlib
import pathlib
import pkgutil
import re
import sys
import warnings


def public_modules(package):
    """The dotted names of `package` and of its public submodules, each imported, with the names of
    its `__all__` resolved.

    pdoc lists only the submodules a package's `__all__` names and looks for the names of
    `__all__` in the module's namespace; a package that imports them on first use (PEP 562, as
    runtime/__init__.py does) has them resolved here, as a user's `from runtime import Model` would."""
    pkg = importlib.import_module(package)
    names = [package] + [info.name for info in pkgutil.walk_packages(pkg.__path__, prefix=package + ".")
                         if not any(part.startswith("_") for part in info.name.split("."))]
    for name in names:
        module = importlib.import_module(name)
        for public in getattr(module, "__all__", ()):
            getattr(module, public)
    return names


def main(argv):
    import pdoc
    import pdoc.extract

    out, packages = pathlib.Path(argv[0]), argv[1:] or ["runtime"]
    with warnings.catch_warnings():
        warnings.simplefilter("error", UserWarning)
        modules = [name for package in packages for name in public_modules(package)]
        # pdoc walks a package's submodules itself (those of its __all__, if it has one): each
        # module is given once, and what the walks add beyond the public modules is dropped.
        specs, walked = [], set()
        for name in modules:
            if name not in walked:
                specs.append(name)
                walked.update(pdoc.extract.walk_specs([name]))
        pdoc.pdoc(*specs, *(f"!{re.escape(name)}$" for name in walked - set(modules)), output_directory=out)
    print(f"pdoc: {len(modules)} modules -> {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
