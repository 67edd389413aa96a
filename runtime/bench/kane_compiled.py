"""The Kane model compiled, as a user of each tool would ship it: the strongest
baselines of their kind, C against C and Python call against Python call.

C, each a function `int NAME(const double qw[12], const double u[2], const double p[12], double a[5])`
compiled into the C loop of bench/bench_kernels.c:
  * `kane_casadi_c`: the Kane model's M and F as CasADi SX expressions, a = ca.solve(M, F), through
    CasADi's C code generator (what a CasADi user ships);
  * `kane_sympy_c`: M and F through SymPy's C99 printer after sympy.cse, solved by a generic LU with
    partial pivoting (GENERIC_LU below);
  * `kane_pydy_c`: the C that PyDy's code generator (pydy.codegen.c_code.CMatrixGenerator, the C
    inside its Cython ODE function) writes for M and F, solved by the same LU.
From Python: `kane_casadi_function` (the same CasADi Function called from Python) and
`pydy_cython_rhs` (PyDy's generate_ode_function(generator="cython"), the ODE function whose
speed derivatives are our accel).

Inputs are the Kane model's own coordinates, qw = (psi, theta, phi, th_Y, th_P, x, y, w1, w2, w3,
w_Y, w_P) (KaneModel.coordinates), converted from our states before the timed region: the
conversion is not timed, which flatters the baselines.  Every function computes the two dependent
speeds of the rolling constraint from qw first (part of accel; PyDy's ODE function has them in its
state instead).  Nothing here is timed or trusted before runtime/bench/checks compares its numbers
with our kernel's.
"""
import os
import pathlib

import numpy as np

from ..verification.alternatives import kane as kane_model

#: One generic dense solver for the SymPy and PyDy C: LU with partial pivoting, in place.
GENERIC_LU = r"""
#include <math.h>
/* Solves A x = b in place (A n x n row-major, b -> x) by LU with partial pivoting; 1 if singular. */
static int generic_lu_solve(int n, double *A, double *b)
{
    int i, j, k;
    for (k = 0; k < n; ++k) {
        int p = k;
        for (i = k + 1; i < n; ++i)
            if (fabs(A[i * n + k]) > fabs(A[p * n + k])) p = i;
        if (A[p * n + k] == 0.0) return 1;
        if (p != k) {
            double t;
            for (j = 0; j < n; ++j) { t = A[k * n + j]; A[k * n + j] = A[p * n + j]; A[p * n + j] = t; }
            t = b[k]; b[k] = b[p]; b[p] = t;
        }
        for (i = k + 1; i < n; ++i) {
            double f = A[i * n + k] / A[k * n + k];
            for (j = k + 1; j < n; ++j) A[i * n + j] -= f * A[k * n + j];
            b[i] -= f * b[k];
        }
    }
    for (i = n - 1; i >= 0; --i) {
        double s = b[i];
        for (j = i + 1; j < n; ++j) s -= A[i * n + j] * b[j];
        b[i] = s / A[i * n + i];
    }
    return 0;
}
"""

HEADER = """/* The Kane model's accel compiled three ways (written by runtime/bench/kane_compiled.py). */
int kane_casadi_c(const double qw[12], const double u[2], const double p[12], double a[5]);
int kane_sympy_c(const double qw[12], const double u[2], const double p[12], double a[5]);
int kane_pydy_c(const double qw[12], const double u[2], const double p[12], double a[5]);
/* d(accel)/d(qw, u), 5 x 14 column-major, by CasADi's AD of kane_casadi, through its code generator. */
int kane_casadi_jac_c(const double qw[12], const double u[2], const double p[12], double J[70]);
"""


def kane_inputs(X):
    """The Kane model's coordinates and independent speeds of our states X (n, 35): (n, 12)."""
    return np.array([[*q, *w] for q, w in map(kane_model.KaneModel.coordinates, X)])


def _expressions():
    d = kane_model._derivation()
    (qs, us, uin, par), (M, F) = d["MF"]
    udep = d["udep"][1]
    return qs, us, uin, par, M, F, udep, d["qdot"][1]


# -- CasADi -----------------------------------------------------------------------------------------
def casadi_kane_function():
    """The Kane model's accel as one CasADi Function kane_casadi(qw, u, p) -> a (5): SX, ca.solve(M, F)."""
    import casadi as ca
    import sympy as sm

    qs, us, uin, par, M, F, udep, _ = _expressions()
    to_sx = lambda rows: ca.vertcat(*[ca.horzcat(*row) for row in rows])   # noqa: E731
    functions = {"sin": ca.sin, "cos": ca.cos, "tan": ca.tan, "sqrt": ca.sqrt, "Abs": ca.fabs,
                 "ImmutableDenseMatrix": to_sx, "MutableDenseMatrix": to_sx}
    f_udep = sm.lambdify((qs, us[:5], par), udep, modules=[functions], cse=True)
    f_MF = sm.lambdify((qs, us, uin, par), (M, F), modules=[functions], cse=True)
    qw, u, p = ca.SX.sym("qw", 12), ca.SX.sym("u", 2), ca.SX.sym("p", 12)
    q, w, pp, uu = ([v[i] for i in range(n)] for v, n in ((qw, 7), (qw[7:], 5), (p, 12), (u, 2)))
    ud = f_udep(q, w, pp)
    Mx, Fx = f_MF(q, w + [ud[0], ud[1]], uu, pp)
    accel = ca.solve(Mx, Fx)[:5]
    return ca.Function("kane_casadi", [qw, u, p], [accel])


def casadi_kane_jacobian_function():
    """d(accel)/d(qw, u) of the Kane model by CasADi's AD (what a CasADi user would ship for MPC):
    kane_casadi_jac(qw, u, p) -> J (5 x 14).  Its columns of the speeds (w1, w2, w3, w_Y, w_P: our
    ν, in the shell frame) and of u are those of our accel_jacobian's ν and u blocks."""
    import casadi as ca
    fn = casadi_kane_function()
    qw, u, p = ca.SX.sym("qw", 12), ca.SX.sym("u", 2), ca.SX.sym("p", 12)
    return ca.Function("kane_casadi_jac", [qw, u, p], [ca.densify(ca.jacobian(fn(qw, u, p), ca.vertcat(qw, u)))])


def write_casadi_c(build):
    """Writes the Kane baseline's CasADi-generated C (function and Jacobian) into the folder `build`."""
    fn, jac = casadi_kane_function(), casadi_kane_jacobian_function()
    cwd = os.getcwd()
    try:
        os.chdir(build)
        fn.generate("kane_casadi.c", {"with_header": True, "casadi_real": "double"})
        jac.generate("kane_casadi_jac.c", {"with_header": True, "casadi_real": "double"})
    finally:
        os.chdir(cwd)
    (build / "kane_casadi_wrapper.c").write_text("""#include "kane_casadi.h"
#include "kane_baselines.h"
/* CasADi's calling convention around kane_casadi: its work arrays live on the stack. */
int kane_casadi_c(const double qw[12], const double u[2], const double p[12], double a[5])
{
    const casadi_real *arg[KANE_CASADI_SZ_ARG];
    casadi_real *res[KANE_CASADI_SZ_RES];
    casadi_int iw[KANE_CASADI_SZ_IW + 1];
    casadi_real w[KANE_CASADI_SZ_W + 1];
    arg[0] = qw; arg[1] = u; arg[2] = p; res[0] = a;
    return kane_casadi(arg, res, iw, w, 0);
}
""")
    (build / "kane_casadi_jac_wrapper.c").write_text("""#include "kane_casadi_jac.h"
#include "kane_baselines.h"
int kane_casadi_jac_c(const double qw[12], const double u[2], const double p[12], double J[70])
{
    const casadi_real *arg[KANE_CASADI_JAC_SZ_ARG];
    casadi_real *res[KANE_CASADI_JAC_SZ_RES];
    casadi_int iw[KANE_CASADI_JAC_SZ_IW + 1];
    casadi_real w[KANE_CASADI_JAC_SZ_W + 1];
    arg[0] = qw; arg[1] = u; arg[2] = p; res[0] = J;
    return kane_casadi_jac(arg, res, iw, w, 0);
}
""")
    defines = {}
    for prefix, f in (("KANE_CASADI", fn), ("KANE_CASADI_JAC", jac)):
        defines.update({f"{prefix}_SZ_ARG": f.sz_arg(), f"{prefix}_SZ_RES": f.sz_res(),
                        f"{prefix}_SZ_IW": f.sz_iw(), f"{prefix}_SZ_W": f.sz_w()})
    return [build / "kane_casadi.c", build / "kane_casadi_wrapper.c", build / "kane_casadi_jac.c",
            build / "kane_casadi_jac_wrapper.c"], defines


# -- SymPy's C printer ----------------------------------------------------------------------------
def write_sympy_c(build):
    """Writes the Kane baseline as C printed by SymPy (with a generic LU solve) into the folder `build`."""
    import sympy as sm

    qs, us, uin, par, M, F, udep, _ = _expressions()
    from sympy.printing.c import C99CodePrinter
    printer = C99CodePrinter()
    lines = ['#include "kane_baselines.h"', GENERIC_LU,
             "int kane_sympy_c(const double qw[12], const double u[2], const double p[12], double a[5])", "{"]
    lines += [f"    const double {s} = qw[{i}];" for i, s in enumerate(list(qs) + list(us[:5]))]
    lines += [f"    const double {s} = u[{i}];" for i, s in enumerate(uin)]
    lines += [f"    const double {s} = p[{i}];" for i, s in enumerate(par)]
    lines.append("    double M[49], F[7];")
    temps, (ud,) = sm.cse([udep], symbols=sm.numbered_symbols("d"))
    lines += [f"    const double {t} = {printer.doprint(e)};" for t, e in temps]
    lines += [f"    const double {us[5 + i]} = {printer.doprint(e)};" for i, e in enumerate(ud)]
    temps, (Mr, Fr) = sm.cse([M, F], symbols=sm.numbered_symbols("t"))
    lines += [f"    const double {t} = {printer.doprint(e)};" for t, e in temps]
    lines += [f"    M[{i}] = {printer.doprint(e)};" for i, e in enumerate(Mr)]
    lines += [f"    F[{i}] = {printer.doprint(e)};" for i, e in enumerate(Fr)]
    lines += ["    if (generic_lu_solve(7, M, F)) return 1;",
              "    for (int i = 0; i < 5; ++i) a[i] = F[i];", "    return 0;", "}", ""]
    path = build / "kane_sympy.c"
    path.write_text("\n".join(lines))
    return [path]


# -- PyDy's C -------------------------------------------------------------------------------------
def write_pydy_c(build):
    """Writes the Kane baseline as C generated by PyDy into the folder `build`; returns the files written."""
    from pydy.codegen.c_code import CMatrixGenerator

    qs, us, uin, par, M, F, udep, _ = _expressions()
    files = []
    for prefix, arguments, matrices in (("kane_pydy_udep", [list(qs), list(us[:5]), list(par)], [udep]),
                                        ("kane_pydy_mf", [list(qs), list(us), list(uin), list(par)], [M, F])):
        header, source = CMatrixGenerator(arguments, matrices).doprint(prefix=prefix)
        (build / f"{prefix}.h").write_text(header.replace("void evaluate(", f"void {prefix}("))
        (build / f"{prefix}.c").write_text(source.replace("void evaluate(", f"void {prefix}("))
        files.append(build / f"{prefix}.c")
    (build / "kane_pydy.c").write_text('#include <string.h>\n#include "kane_baselines.h"\n'
                                       '#include "kane_pydy_udep.h"\n#include "kane_pydy_mf.h"\n' + GENERIC_LU + """
/* PyDy's evaluate functions for the dependent speeds and for M, F; then the generic LU. */
int kane_pydy_c(const double qw[12], const double u[2], const double p[12], double a[5])
{
    double q[7], s[7], uu[2], pp[12], ud[2], M[49], F[7];
    memcpy(q, qw, sizeof q);
    memcpy(s, qw + 7, 5 * sizeof s[0]);
    memcpy(uu, u, sizeof uu);
    memcpy(pp, p, sizeof pp);
    kane_pydy_udep(q, s, pp, ud);
    s[5] = ud[0];
    s[6] = ud[1];
    kane_pydy_mf(q, s, uu, pp, M, F);
    if (generic_lu_solve(7, M, F)) return 1;
    memcpy(a, F, 5 * sizeof a[0]);
    return 0;
}
""")
    return files + [build / "kane_pydy.c"]


def write_kane_c(build):
    """Every Kane C baseline into `build`; returns (C sources, macro definitions)."""
    build = pathlib.Path(build)
    (build / "kane_baselines.h").write_text(HEADER)
    casadi_sources, defines = write_casadi_c(build)
    return casadi_sources + write_sympy_c(build) + write_pydy_c(build), defines


# -- From Python --------------------------------------------------------------------------------------
def pydy_cython_rhs(build):
    """PyDy's ODE function, compiled by Cython: rhs(x, t, r, p) with x = (q (7), all seven speeds),
    r = (u_Y, u_P), p the 12 parameters; returns (q', u') of 14 entries, u'[:5] our accel."""
    from pydy.codegen.ode_function_generators import generate_ode_function

    qs, us, uin, par, M, F, udep, qdot = _expressions()
    return generate_ode_function(F, list(qs), list(us), list(par), mass_matrix=M, coordinate_derivatives=qdot,
                                 specifieds=list(uin), generator="cython", tmp_dir=str(build))


def dependent_speeds(qw, p):
    """The two dependent speeds (x', y') of the rolling constraint at Kane coordinates qw (n, 12)."""
    f = kane_model._lambdified(True, "numpy")["f_udep"]
    return np.array([np.asarray(f(tuple(row[:7]), tuple(row[7:]), tuple(p)), dtype=float).reshape(2) for row in qw])
