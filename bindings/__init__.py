"""cffi (API mode, out of line) build of the generated model and the C runtime.

`bindings._sr` is compiled by `pip install` (setup.py: cffi_modules) from
generated/*.c and c/src/*.c; its declarations are read from c/include/spherical_robot.h
by the C preprocessor (bindings/build_sr.py); nothing is derived at import.
"""
