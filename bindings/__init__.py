"""cffi (API mode, out of line) build of the generated model and the C runtime.

`bindings._sr` is compiled by `pip install` (setup.py: cffi_modules) from
generated/sr_generated.c and c/sr_runtime.c; nothing is derived at import.
"""
