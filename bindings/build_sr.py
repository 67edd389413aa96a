"""cffi builder for `bindings._sr`: compiles generated/ and c/src/ into one extension module."""
import os
import pathlib
import re
import shlex
import subprocess
import sysconfig

import cffi

ROOT = pathlib.Path(__file__).resolve().parent.parent
# Every C file of generated/ and c/src/ (the library; its public headers are in c/include/).
SOURCES = sorted(str(p.relative_to(ROOT)) for d in ("generated", "c/src") for p in (ROOT / d).glob("*.c"))
INCLUDE_DIRS = ["generated", "c/include"]

#: The public headers of c/include/ whose declarations the module exposes, in include order.
HEADERS = ("spherical_robot.h", "sr_sensors.h", "sr_ekf.h", "sr_nmpc.h", "sr_sim.h", "sr_loop.h", "sr_ident.h")
INCLUDES = "".join(f'#include "{name}"\n' for name in HEADERS)


def compiler():
    """The C compiler that setuptools will use for the extension (CC, else Python's own)."""
    return shlex.split(os.environ.get("CC") or sysconfig.get_config_var("CC") or "cc")


def preprocessed_header():
    """(file, line) pairs of the double build of the public headers (HEADERS) after the C
    preprocessor, the #define lines kept in place (-dD); file is the header each line comes from."""
    out = subprocess.run([*compiler(), "-E", "-dD", "-std=c99", f"-I{ROOT / 'c' / 'include'}", f"-I{ROOT / 'generated'}",
                          "-x", "c", "-"], input=INCLUDES, check=True, capture_output=True, text=True).stdout
    current, lines = None, []
    for line in out.splitlines():
        marker = re.match(r'# \d+ "([^"]+)"', line)
        if marker:
            current = marker.group(1)
        elif line.strip():
            lines.append((current, line))
    return lines


_INT = re.compile(r"^\(?\s*([-+]?(?:0[xX][0-9a-fA-F]+|\d+))[uUlL]*\s*\)?$")
_FLOAT = re.compile(r"^\(?\s*(?:SR_C\()?\s*[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?[fFlL]?\s*\)?\s*\)?$")


def header_cdef():
    """The cdef cffi needs, read from the checked-in headers (no hand copy): the declarations
    of c/include/ and generated/ as the preprocessor leaves them, every object-like SR_* macro whose
    value is an integer (directly or through other macros: SR_NX -> SR_GEN_NX -> 35) as a
    #define, and every one whose value is a floating literal (SR_ROTATION_TOL) as a
    `static const double` that cffi reads from the compiled module."""
    ours = {str(d) for d in (ROOT / "c" / "include", ROOT / "generated")}
    macros, declarations = {}, []
    for path, line in preprocessed_header():
        if not path or not any(os.path.abspath(path).startswith(d) for d in ours):
            continue
        define = re.match(r"#define (SR_\w+)(\(?)\s*(.*)$", line)
        if define:
            name, function_like, body = define.groups()
            if not function_like:
                macros[name] = body.strip()
        elif not line.startswith("#"):
            declarations.append(line)

    def integer(name, seen=()):
        body = macros.get(name)
        if body is None or name in seen:
            return None
        literal = _INT.match(body)
        if literal:
            return int(literal.group(1), 0)
        return integer(body, seen + (name,)) if re.fullmatch(r"SR_\w+", body) else None

    defines, constants = [], []
    for name, body in macros.items():
        value = integer(name)
        if value is not None:
            defines.append(f"#define {name} {value}")
        elif _FLOAT.match(body):
            constants.append(f"static const double {name};")
    return "\n".join(defines + constants + declarations) + "\n"


CDEF = header_cdef()

# The single-state entry points of the Python API (runtime/model.py, `Model.accel` and `Model.step`
# on one state): the full state check and the kernel in one C call, so that a call from Python
# crosses the cffi boundary once.  The buffers are `void *`, so that the `char[]` of
# ffi.from_buffer passes without an ffi.cast (each costs about as much as the kernel itself).
# Binding glue only: firmware calls sr_check_state and the kernel itself.
PY_ENTRIES_CDEF = """
int sr_py_accel(const sr_model *model, const void *x, const void *u, void *a);
int sr_py_step(const sr_model *model, int method, const void *x, const void *u, double dt, void *x_next);
int sr_py_inertia_batch(const sr_model *model, long n, const double *x, double *M, long *failed_row);
"""
PY_ENTRIES_SOURCE = """
static int sr_py_accel(const sr_model *model, const void *x, const void *u, void *a)
{
    int status = sr_check_state(model, (const sr_real *)x);
    return status != SR_OK ? status : sr_accel(model, (const sr_real *)x, (const sr_real *)u, (sr_real *)a);
}

static int sr_py_step(const sr_model *model, int method, const void *x, const void *u, double dt, void *x_next)
{
    /* sr_step checks x in full itself (sr_check_state): no second check here. */
    return sr_step(model, method, (const sr_real *)x, (const sr_real *)u, dt, (sr_real *)x_next);
}

/* sr_inertia on n states (x n x SR_NX, M n x 25), stopping at the first failing row (its index in
 * *failed_row, else -1): Model.inertia_batch's loop in C instead of one cffi call a state. */
static int sr_py_inertia_batch(const sr_model *model, long n, const double *x, double *M, long *failed_row)
{
    long i;
    *failed_row = -1;
    for (i = 0; i < n; ++i) {
        const int status = sr_inertia(model, x + i * SR_NX, M + i * SR_NV * SR_NV);
        if (status != SR_OK) {
            *failed_row = i;
            return status;
        }
    }
    return SR_OK;
}
"""

# Portable -O2 by default; SR_NATIVE=1 at install time (`SR_NATIVE=1 pip install -e .`) adds
# -march=native for this machine's vector units (the firmware example then matches the Python
# runs only if it is built with the same flag).
NATIVE = ["-march=native"] if os.environ.get("SR_NATIVE") == "1" else []

#: GCC's limit of run-time alias tests per vectorised loop (--param vect-max-version-for-alias-checks),
#: raised for the lanes kernels; other compilers have no such parameter (clang warns on it).
VECT_ALIAS_CHECKS = (["--param=vect-max-version-for-alias-checks=100"]
                     if "Free Software Foundation" in subprocess.run([*compiler(), "--version"], capture_output=True,
                                                                     text=True).stdout else [])

COMPILE_ARGS = ["-std=c99", "-O3", "-ffp-contract=off", "-DSR_CLONES", *VECT_ALIAS_CHECKS, *NATIVE]

ffibuilder = cffi.FFI()
ffibuilder.cdef(CDEF + PY_ENTRIES_CDEF)
ffibuilder.set_source(
    "bindings._sr",
    INCLUDES + PY_ENTRIES_SOURCE,
    sources=SOURCES,
    include_dirs=INCLUDE_DIRS,
    # No FMA contraction: the firmware example (c/examples) must reproduce the Python runs bit for bit.
    # -O3: GCC vectorises the batch calls' lanes loops (sr_gen_accel_lanes) only with its full cost
    # model; without -ffast-math it changes no result (tests/bindings: batch == single, bit for bit).
    # -DSR_CLONES: the batch loops also for AVX2, picked at load time (c/include/sr_real.h, SR_LANES_CLONES).
    # The alias checks: the lanes kernels of several output arrays (sr_gen_general_accel_jacobian_terms_lanes,
    # five) need more run-time alias tests than GCC 12 makes by default (10); below that their loop stays scalar.
    extra_compile_args=COMPILE_ARGS,
)

if __name__ == "__main__":
    ffibuilder.compile(verbose=True)
