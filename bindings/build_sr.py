"""cffi builder for `bindings._sr`: compiles generated/ and c/ into one extension module."""
import os
import pathlib

import cffi

ROOT = pathlib.Path(__file__).resolve().parent.parent
# Every C file of generated/ and the top level of c/ (examples and C tests live in subfolders).
SOURCES = sorted(str(p.relative_to(ROOT)) for d in ("generated", "c") for p in (ROOT / d).glob("*.c"))
INCLUDE_DIRS = ["generated", "c"]

# The double build of c/spherical_robot.h, as cffi's parser needs it (no preprocessor).
CDEF = """
#define SR_NPARAM 12
#define SR_NX 35
#define SR_NU 2
#define SR_NV 5
#define SR_NE 12
#define SR_OK 0
#define SR_ERR_NULL 1
#define SR_ERR_NONFINITE 2
#define SR_ERR_NOT_ROTATION 3
#define SR_ERR_SINGULAR 4
#define SR_ERR_PARAM 5
#define SR_ERR_ARG 6
#define SR_ERR_CONSTRAINT 7
#define SR_ERR_STEP_SIZE 8
#define SR_ERR_MAX_STEPS 9
#define SR_ERR_ENERGY 10
#define SR_GUARD_INTERVAL 16
#define SR_LIE_EULER 0
#define SR_RKMK4 1
#define SR_CF4 2
#define SR_PROJECT 16
typedef double sr_real;
static const double SR_ROTATION_TOL;
typedef struct sr_model { ...; } sr_model;
const char *sr_status_string(int status);
int sr_model_init(sr_model *model, const sr_real params[]);
int sr_check_state(const sr_model *model, const sr_real x[]);
int sr_check_state_batch(const sr_model *model, long n, const sr_real *x, long *failed_row);
int sr_accel(const sr_model *model, const sr_real x[], const sr_real u[], sr_real a[]);
int sr_accel_batch(const sr_model *model, long n, const sr_real *x, const sr_real *u, sr_real *a, long *failed_row);
int sr_inertia(const sr_model *model, const sr_real x[], sr_real M[]);
int sr_rhs(const sr_model *model, const sr_real x[], const sr_real u[], sr_real f[]);
int sr_energy(const sr_model *model, const sr_real x[], sr_real *energy);
int sr_equilibrium_residual(const sr_model *model, const sr_real x[], sr_real res[]);
int sr_so3_exp(const sr_real w[], sr_real R[]);
int sr_step(const sr_model *model, int method, const sr_real x[], const sr_real u[], sr_real dt, sr_real x_next[]);
int sr_simulate(const sr_model *model, int method, const sr_real x0[], sr_real dt, long steps,
                const sr_real *u, sr_real *traj, long *steps_done);
typedef struct sr_energy_guard {
    sr_real tol;
    int in_stretch;
    sr_real e_start;
    sr_real scale;
    sr_real energy;
} sr_energy_guard;
int sr_simulate_guarded(const sr_model *model, int method, const sr_real x0[], sr_real dt, long steps,
                        const sr_real *u, sr_energy_guard *guard, sr_real *traj, long *steps_done);
typedef struct sr_adaptive_stats {
    long accepted;
    long rejected;
    long evaluations;
    long rows_done;
    sr_real h_next;
} sr_adaptive_stats;
int sr_simulate_adaptive(const sr_model *model, int method, const sr_real x0[], sr_real dt_out,
                         long n_out, const sr_real *u, sr_real rtol, sr_real atol, sr_real h_init,
                         long max_steps, sr_real *traj, sr_adaptive_stats *stats);
#define SR_BATCH_NMETRICS 4
#define SR_BATCH_PATH_LENGTH 0
#define SR_BATCH_MAX_DISTANCE 1
#define SR_BATCH_MAX_SHELL_RATE 2
#define SR_BATCH_FINAL_ENERGY 3
int sr_retract(const sr_model *model, const sr_real x[], const sr_real d[], sr_real y[]);
int sr_local(const sr_model *model, const sr_real x[], const sr_real y[], sr_real d[]);
int sr_retract_batch(const sr_model *model, long n, const sr_real *x, const sr_real *d, sr_real *y, long *failed_row);
int sr_local_batch(const sr_model *model, long n, const sr_real *x, const sr_real *y, sr_real *d, long *failed_row);
int sr_accel_jacobian(const sr_model *model, const sr_real x[], const sr_real u[], sr_real Ja[], sr_real Jb[]);
int sr_accel_jacobian_batch(const sr_model *model, long n, const sr_real *x, const sr_real *u,
                            sr_real *Ja, sr_real *Jb, long *failed_row);
int sr_simulate_batch(int method, long n, const sr_real *params, long params_stride, const sr_real *x0,
                      long x0_stride, sr_real dt, long steps, const sr_real *u, long u_stride,
                      sr_real energy_tol, long chunk_steps, sr_real *work, sr_real *traj,
                      sr_real *x_final, sr_real *metrics, int *status, long *steps_done);
"""

# The single-state entry points of the Python API (runtime/model.py, `Model.accel` and `Model.step`
# on one state): the full state check and the kernel in one C call, so that a call from Python
# crosses the cffi boundary once.  The buffers are `void *`, so that the `char[]` of
# ffi.from_buffer passes without an ffi.cast (each costs about as much as the kernel itself).
# Binding glue only: firmware calls sr_check_state and the kernel itself.
PY_ENTRIES_CDEF = """
int sr_py_accel(const sr_model *model, const void *x, const void *u, void *a);
int sr_py_step(const sr_model *model, int method, const void *x, const void *u, double dt, void *x_next);
"""
PY_ENTRIES_SOURCE = """
static int sr_py_accel(const sr_model *model, const void *x, const void *u, void *a)
{
    int status = sr_check_state(model, (const sr_real *)x);
    return status != SR_OK ? status : sr_accel(model, (const sr_real *)x, (const sr_real *)u, (sr_real *)a);
}

static int sr_py_step(const sr_model *model, int method, const void *x, const void *u, double dt, void *x_next)
{
    int status = sr_check_state(model, (const sr_real *)x);
    return status != SR_OK ? status
                           : sr_step(model, method, (const sr_real *)x, (const sr_real *)u, dt, (sr_real *)x_next);
}
"""

# Portable -O2 by default; SR_NATIVE=1 at install time (`SR_NATIVE=1 pip install -e .`) adds
# -march=native for this machine's vector units (the firmware example then matches the Python
# runs only if it is built with the same flag).
NATIVE = ["-march=native"] if os.environ.get("SR_NATIVE") == "1" else []

# The layout macros (SR_X_*, SR_U_*, SR_P_*, SR_E_* and the error-state size) as the generator wrote them.
LAYOUT = "\n".join(line for line in (ROOT / "generated" / "sr_generated.h").read_text().splitlines()
                   if line.startswith(("#define SR_X_", "#define SR_U_", "#define SR_P_", "#define SR_E_",
                                       "#define SR_GEN_NE ")))

ffibuilder = cffi.FFI()
ffibuilder.cdef(CDEF + LAYOUT + PY_ENTRIES_CDEF)
ffibuilder.set_source(
    "bindings._sr",
    '#include "spherical_robot.h"\n' + PY_ENTRIES_SOURCE,
    sources=SOURCES,
    include_dirs=INCLUDE_DIRS,
    # No FMA contraction: the firmware example (c/examples) must reproduce the Python runs bit for bit.
    extra_compile_args=["-std=c99", "-O2", "-ffp-contract=off", *NATIVE],
)

if __name__ == "__main__":
    ffibuilder.compile(verbose=True)
