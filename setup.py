"""Build hook: setuptools reads everything else from pyproject.toml; this only wires cffi's extension."""
from setuptools import setup

setup(cffi_modules=["bindings/build_sr.py:ffibuilder"])
