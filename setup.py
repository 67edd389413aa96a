"""Build hook: setuptools reads everything else from pyproject.toml; this wires cffi's extension
(bindings/build_sr.py) and the one-state fast path of Model.accel / Model.step (bindings/fastcall.c,
NumPy's C API)."""
import numpy
from setuptools import Extension, setup

fastcall = Extension(
    "bindings._fastcall",
    sources=["bindings/fastcall.c"],
    include_dirs=["c/include", "generated", numpy.get_include()],
    extra_compile_args=["-std=c99", "-O2"],
)

setup(cffi_modules=["bindings/build_sr.py:ffibuilder"], ext_modules=[fastcall])
