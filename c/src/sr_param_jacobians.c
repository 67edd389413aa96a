/*
 * sr_param_jacobians.c -- derivatives in the parameters: of the accelerations, of one step of
 * Lie-Euler or RKMK4, and the regressor form of the equations of motion.
 *
 * With the state and the torques held, M nu' = f gives d(nu')/dp = -M^-1 d(M nu' - f)/dp, nu'
 * held in the bracket (derive/param_derivatives.py): one generated kernel for the bracket, the
 * general robot's M and f and its Cholesky factor for the solve.  A robot of the paper's geometry
 * is evaluated with the general kernels too (its general constants computed per call), so that
 * every parameter, the ones the paper's kernels fold into constants included, has its column.
 *
 * A step's sensitivity follows the stages of sr_steppers.c with the state held (x fixed, so its
 * error enters nowhere): for the action y = x . exp(th), y (-) y0 = B(th) dth with B of
 * sr_step_jacobians.c; for the vector field at a stage state y, df = J_f(y) dy + df/dp(y), where
 * df/dp has the accelerations' rows and, since q' = r (R_S w) x e_z, q'/r in the column of r;
 * and RKMK4's dexp^-1 on the SO(3) block, dk_S = P df_S + Q dth_S (sr_dexpinv.h).
 *
 * The columns are independent all the way: a sensitivity to a few parameters (the free ones of a
 * fit) runs the same stages on those columns only.  The step's state Jacobian F is more columns of
 * the same stages (the directions of the start state's error, which the actions move by A(th) as
 * well): asked for with the parameter columns at the same states, it shares each stage's
 * derivative kernel, factorisation and solve with them instead of running its own stages.
 *
 * A batch of RKMK4 sensitivities of a general robot on free columns (a fit's) runs blocks of
 * states through the stages in lockstep (rkmk4_param_lanes): each stage's two generated kernels in
 * their lanes forms, vectorised across the block, everything else state by state in the same order
 * as one state's path, so each state's result is that path's.
 */
#include "sr_checks.h"
#include "sr_dexpinv.h"
#include "sr_finite.h"
#include "sr_jacobians.h"
#include "sr_kernels.h"
#include "sr_steppers.h"
#include "sr_argcheck.h"

#include <string.h>

#define NP SR_NPARAM
/* The state directions a step's F carries: every error direction but dq's.  Nothing in a step
 * depends on where the robot stands, so F's dq columns are the identity's (as in
 * sr_step_jacobians.c); carried column a is error direction a before SR_E_q, a + 2 after. */
#define NS (SR_NE - 2)
#define NW (NS + NP)
#define state_row(a) ((a) < SR_E_q ? (a) : (a) + 2)

typedef sr_real tangent_p[SR_NT][NW];   /* d(13-vector)/d(d, p), the carried columns */
typedef sr_real error_p[SR_NE][NW];     /* d(state error)/d(d, p) */

/* d(pi)/dp_j of one parameter that moves only pi (runtime.param_derivatives.inertial_parameters):
 * the n entries k[e] of pi it moves, by v[e] (a body's mass moves ten). */
typedef struct {
    int n;
    unsigned char k[10];
    sr_real v[10];
} pi_column;

/* The columns computed: n of them, the first ns (0 or NS) the start state's directions, then the
 * parameters: cols[c] the SR_P_* of column ns + c, or cols NULL for all in order; r_col the column
 * of r, or -1.  pi not NULL: every parameter column moves pi alone, pi[c] its d(pi)/dp, and the
 * bracket comes from the regressor (see residual_columns). */
typedef struct {
    int n, ns, r_col;
    const int *cols;
    const pi_column *pi;
} colset;

static const colset ALL_COLUMNS = {NP, 0, SR_P_r, NULL, NULL};

/* d(pi)/dp_j into d; 0 for a parameter that the regressor Y itself depends on (r, n_Y, n_P, g,
 * slope), else 1.  A body's entries run m, c (3), J (xx yy zz xy xz yz), k in p and m, m c,
 * J_O = J + m (|c|^2 I - c c^T) (the same six), k in pi. */
static int pi_derivative(const sr_real p[NP], int j, pi_column *d)
{
    typedef char same_layout[(SR_P_k_Y - SR_P_m_Y == 10 && SR_P_k_P - SR_P_m_P == 10 && SR_PI_k_Y - SR_PI_m_Y == 10
                              && SR_PI_k_P - SR_PI_m_P == 10) ? 1 : -1];
    static const unsigned char single[][2] = {{SR_P_m_S, SR_PI_m_S}, {SR_P_j_S, SR_PI_j_S}, {SR_P_k_S, SR_PI_k_S},
                                              {SR_P_j_mY, SR_PI_j_mY}, {SR_P_j_mP, SR_PI_j_mP}};
    /* per axis a of c: the off-diagonal entries of J_O (xy 3, xz 4, yz 5) with the other axis, and
     * the diagonal entries it enters squared */
    static const unsigned char off[3][2][2] = {{{3, 1}, {4, 2}}, {{3, 0}, {5, 2}}, {{4, 0}, {5, 1}}};
    int b, e, a;
    sr_real m;
    const sr_real *c;
    (void)sizeof(same_layout);
    d->n = 0;
    for (e = 0; e < 5; ++e)
        if (j == single[e][0]) {
            d->n = 1;
            d->k[0] = single[e][1];
            d->v[0] = 1;
            return 1;
        }
    if (j >= SR_P_m_Y && j <= SR_P_k_Y) b = 0;
    else if (j >= SR_P_m_P && j <= SR_P_k_P) b = 1;
    else return 0;
    {
        const int p0 = b ? SR_P_m_P : SR_P_m_Y, q0 = b ? SR_PI_m_P : SR_PI_m_Y, o = j - p0;
        m = p[p0];
        c = p + p0 + 1;
        if (o == 0) {   /* the mass: m, m c and J_O */
            d->k[0] = (unsigned char)q0;
            d->v[0] = 1;
            for (a = 0; a < 3; ++a) {
                d->k[1 + a] = (unsigned char)(q0 + 1 + a);
                d->v[1 + a] = c[a];
            }
            d->k[4] = (unsigned char)(q0 + 4);
            d->v[4] = c[1] * c[1] + c[2] * c[2];
            d->k[5] = (unsigned char)(q0 + 5);
            d->v[5] = c[0] * c[0] + c[2] * c[2];
            d->k[6] = (unsigned char)(q0 + 6);
            d->v[6] = c[0] * c[0] + c[1] * c[1];
            d->k[7] = (unsigned char)(q0 + 7);
            d->v[7] = -c[0] * c[1];
            d->k[8] = (unsigned char)(q0 + 8);
            d->v[8] = -c[0] * c[2];
            d->k[9] = (unsigned char)(q0 + 9);
            d->v[9] = -c[1] * c[2];
            d->n = 10;
        } else if (o <= 3) {   /* c_a: m c_a, the two diagonal entries of J_O without a, two off-diagonal */
            a = o - 1;
            d->k[0] = (unsigned char)(q0 + o);
            d->v[0] = m;
            d->n = 1;
            for (e = 0; e < 3; ++e)
                if (e != a) {
                    d->k[d->n] = (unsigned char)(q0 + 4 + e);
                    d->v[d->n++] = 2 * m * c[a];
                }
            for (e = 0; e < 2; ++e) {
                d->k[d->n] = (unsigned char)(q0 + 4 + off[a][e][0]);
                d->v[d->n++] = -m * c[off[a][e][1]];
            }
        } else {   /* J's entries and k: their own */
            d->n = 1;
            d->k[0] = (unsigned char)(q0 + o);
            d->v[0] = 1;
        }
    }
    return 1;
}

/* The set of ns state columns then the ncols columns cols (checked by the caller: 1 <= ncols <= NP,
 * each an index of p); pi[0..ncols) filled and used where every column moves pi alone. */
static colset columns_of(const sr_model *model, int ns, int ncols, const int *cols, pi_column pi[NP])
{
    colset s;
    int c, linear = 1;
    s.n = ns + ncols;
    s.ns = ns;
    s.cols = cols;
    s.r_col = -1;
    for (c = ncols - 1; c >= 0; --c)
        if (cols[c] == SR_P_r) s.r_col = ns + c;
    for (c = 0; c < ncols && linear; ++c) linear = pi_derivative(model->p, cols[c], pi + c);
    s.pi = linear ? pi : NULL;
    return s;
}

/* SR_OK if 1 <= ncols <= NP, cols not NULL and each of its entries an index of p. */
static int arg_columns(int ncols, const int *cols)
{
    int c;
    if (!cols) return SR_ERR_NULL;
    if (ncols < 1 || ncols > NP) return SR_ERR_ARG;
    for (c = 0; c < ncols; ++c)
        if (cols[c] < 0 || cols[c] >= NP) return SR_ERR_ARG;
    return SR_OK;
}

/* The general kernels' constants of any robot: the model's own for a general one; the paper's
 * kernels fold parameters into constants, so for its robot they are computed (once per call of an
 * entry point: a step's stages share them). */
static const sr_real *general_constants(const sr_model *model, sr_real cg[SR_GEN_GENERAL_NCONST])
{
    if (model->general) return model->cg;
    sr_gen_general_constants(model->p, cg);
    return cg;
}

/* -d(M nu' - f)/d(d, p) with the state held on the columns cs (its first cs->n columns; the state
 * columns 0), nu' = a held.  Where every column moves pi alone, from the regressor: M nu' - f =
 * Y(x, nu') pi - B u with B of the gear ratios only, so the bracket is Y d(pi)/dp, and Y (about half
 * the bracket's operations, SR_GEN_REGRESSOR_FLOPS) serves any number of columns at a few products
 * each; otherwise the generated bracket, its chosen columns moved into place. */
/* -d(M nu' - f)/d(d, p) = -Y d(pi)/dp on the columns cs (every one moving pi alone), Y the regressor. */
static void regressor_columns(const colset *cs, const sr_real Y[SR_NV * SR_NPI], sr_real D[SR_NV][NW])
{
    int i, c, e;
    for (i = 0; i < SR_NV; ++i)
        for (c = 0; c < cs->ns; ++c) D[i][c] = 0;
    for (c = cs->ns; c < cs->n; ++c) {   /* a column's five rows at once, each summed over e in order */
        const pi_column *d = cs->pi + (c - cs->ns);
        sr_real t[SR_NV] = {0, 0, 0, 0, 0};
        for (e = 0; e < d->n; ++e) {
            const sr_real *y = Y + d->k[e], v = d->v[e];
            for (i = 0; i < SR_NV; ++i) t[i] += y[SR_NPI * i] * v;
        }
        for (i = 0; i < SR_NV; ++i) D[i][c] = -t[i];
    }
}

static int residual_columns(const sr_model *model, const colset *cs, const sr_real x[SR_NX], const sr_real a[SR_NV],
                            sr_real D[SR_NV][NW])
{
    sr_real all[SR_NV * NP];
    int i, c, status;
    if (cs->pi) {
        sr_real Y[SR_NV * SR_NPI];
        status = sr_gen_regressor(model->p, x, a, Y);
        if (status == SR_OK) regressor_columns(cs, Y, D);
        return status;
    }
    status = sr_gen_general_param_residual_jacobian(model->p, x, a, all);
    for (i = 0; i < SR_NV && status == SR_OK; ++i) {
        for (c = 0; c < cs->ns; ++c) D[i][c] = 0;
        for (c = cs->ns; c < cs->n; ++c) D[i][c] = -all[NP * i + (cs->cols ? cs->cols[c - cs->ns] : c - cs->ns)];
    }
    return status;
}

/* A general stage's a = M^-1 f from the kernel's M (upper triangle) and f; L, inv its factor. */
static int stage_accel(const sr_real Mu[15], const sr_real f[SR_NV], sr_real L[SR_NV * SR_NV], sr_real inv[SR_NV],
                       sr_real a[SR_NV])
{
    int i, k, status = sr_internal_cholesky(Mu, L, inv);
    if (status != SR_OK) return status;
    for (i = 0; i < SR_NV; ++i) {   /* a = M^-1 f */
        sr_real t = f[i];
        for (k = 0; k < i; ++k) t -= L[SR_NV * i + k] * a[k];
        a[i] = t * inv[i];
    }
    for (i = SR_NV - 1; i >= 0; --i) {
        sr_real t = a[i];
        for (k = i + 1; k < SR_NV; ++k) t -= L[SR_NV * k + i] * a[k];
        a[i] = t * inv[i];
    }
    return SR_OK;
}

/* A general stage's D = M^-1 ((df - (dM) a) dy + D) on the columns cs, D holding -d(M nu' - f)/dp. */
static void stage_columns(const colset *cs, const sr_real df[SR_NV * SR_NE], const sr_real dM[5 * 15],
                          const sr_real L[SR_NV * SR_NV], const sr_real inv[SR_NV], const sr_real a[SR_NV],
                          const error_p dy, sr_real D[SR_NV][NW])
{
    sr_real g[SR_NV][SR_NE];
    const int nc = cs->n;
    int i, j, k, c;
    for (i = 0; i < SR_NV; ++i) {
        for (k = 0; k < SR_NE; ++k) g[i][k] = df[SR_NE * i + k];
        for (k = 0; k < 5; ++k)   /* the configuration directions d_xi_S, d_th_Y, d_th_P move M */
            for (j = 0; j < SR_NV; ++j) g[i][k] -= dM[15 * k + SR_UPPER[i][j]] * a[j];
        for (c = 0; c < nc; ++c) {   /* summed in a local, in the order of k (see sr_internal_cholesky_solve) */
            sr_real t = D[i][c];
            for (k = 0; k < SR_NE; ++k)
                if (k != SR_E_q && k != SR_E_q + 1) t += g[i][k] * dy[k][c];   /* nothing depends on q */
            D[i][c] = t;
        }
    }
    sr_internal_cholesky_solve(L, inv, NW, nc, &D[0][0]);
}

/* A general robot's stage: nu' = a and its whole derivative along the stage's dy on the columns
 * cs, D = Ja dy + d(nu')/dp = M^-1 ((df - (dM) a) dy - d(M nu' - f)/dp), from one kernel for M, f
 * and their state derivatives and one factorisation: Ja itself is never formed, and the solve runs
 * on the few columns only. */
static int general_stage_rows(const sr_model *model, const colset *cs, const sr_real y[SR_NX],
                              const sr_real u[SR_NU], const error_p dy, sr_real a[SR_NV], sr_real D[SR_NV][NW])
{
    sr_real Mu[15], f[SR_NV], df[SR_NV * SR_NE], dfdu[SR_NV * SR_NU], dM[5 * 15], L[SR_NV * SR_NV], inv[SR_NV];
    int status = sr_internal_general_accel_jacobian_terms(model, y, u, Mu, f, df, dfdu, dM);
    if (status == SR_OK) status = stage_accel(Mu, f, L, inv, a);
    if (status == SR_OK) status = residual_columns(model, cs, y, a, D);
    if (status != SR_OK) return status;
    stage_columns(cs, df, dM, L, inv, a, dy, D);
    return SR_OK;
}

/* nu' and d(nu')/dp on the columns cs at a state the caller checked (u not NULL), the general
 * kernels' constants given; J row-major SR_NV x NP, its first cs->n columns written. */
static int accel_param_jacobian(const sr_model *model, const sr_real *constants, const colset *cs,
                                const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real a[SR_NV],
                                sr_real J[SR_NV][NW])
{
    sr_real Mu[15], f[SR_NV], L[SR_NV * SR_NV], inv[SR_NV];
    const int nc = cs->n;
    int i, status;
    status = sr_gen_general_system(constants, x, u, Mu, f);
    if (status == SR_OK) status = sr_internal_cholesky(Mu, L, inv);
    if (status != SR_OK) return status;
    for (i = 0; i < SR_NV; ++i) a[i] = f[i];
    sr_internal_cholesky_solve(L, inv, 1, 1, a);   /* a = M^-1 f */
    status = residual_columns(model, cs, x, a, J);
    if (status != SR_OK) return status;
    sr_internal_cholesky_solve(L, inv, NW, nc, &J[0][0]);   /* J = -M^-1 dR */
    return SR_OK;
}

int sr_accel_param_jacobian(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                            sr_real J[SR_NV * SR_NPARAM])
{
    sr_real a[SR_NV], j[SR_NV][NW], cg[SR_GEN_GENERAL_NCONST];
    int i, status = arg_model(model, READS(WHOLE));
    if (status != SR_OK) return status;
    if (!x || !J) return SR_ERR_NULL;
    status = sr_internal_check_state(model, x);
    if (status == SR_OK && u && !all_finite(u, SR_NU)) status = SR_ERR_NONFINITE;
    if (status == SR_OK)
        status = accel_param_jacobian(model, general_constants(model, cg), &ALL_COLUMNS, x, u ? u : sr_zero_u, a, j);
    for (i = 0; i < SR_NV && status == SR_OK; ++i)
        if (!all_finite(j[i], NP)) status = SR_ERR_NONFINITE;
    if (status != SR_OK) return status;
    for (i = 0; i < SR_NV; ++i) memcpy(J + NP * i, j[i], NP * sizeof(sr_real));
    return SR_OK;
}

int sr_accel_param_jacobian_batch(const sr_model *model, long n, const sr_real *x, const sr_real *u, sr_real *J,
                                  long *failed_row)
{
    long i;
    int status = arg_model(model, READS(WHOLE));
    if (failed_row) *failed_row = -1;
    if (status == SR_OK) status = arg_rows(n, x && J);
    if (status != SR_OK) return status;
    for (i = 0; i < n; ++i) {
        status = sr_accel_param_jacobian(model, x + i * SR_NX, u ? u + i * SR_NU : NULL, J + i * SR_NV * NP);
        if (status != SR_OK) {
            if (failed_row) *failed_row = i;
            return status;
        }
    }
    return SR_OK;
}

/* ---- one step ------------------------------------------------------------------------------- */

/* dy = A(th) [I | 0] + B(th) dth on the first nc columns, the first ns of them the start state's
 * directions: the error of y = x . exp(th) (q_z does not move); A(th) = diag(Exp(th_S)^T, 1, 1, I_2,
 * I_5), Exp(th_S) = I + D. */
static void action_rows(int ns, int nc, const sr_real th[SR_NT], const sr_real D[9], const tangent_p dth, error_p dy)
{
    const size_t row = (size_t)nc * sizeof(sr_real);
    sr_real Jr[9];
    int i, c;
    so3_right_jacobian(th + SR_T_S, Jr);
    for (i = 0; i < 3; ++i)
        for (c = 0; c < nc; ++c)
            dy[SR_E_xi_S + i][c] = Jr[3 * i] * dth[SR_T_S][c] + Jr[3 * i + 1] * dth[SR_T_S + 1][c]
                                   + Jr[3 * i + 2] * dth[SR_T_S + 2][c];
    memcpy(dy[SR_E_th_Y], dth[SR_T_Y], row);
    memcpy(dy[SR_E_th_P], dth[SR_T_P], row);
    for (i = 0; i < 2; ++i) memcpy(dy[SR_E_q + i], dth[SR_T_Q + i], row);
    for (i = 0; i < SR_NV; ++i) memcpy(dy[SR_E_nu + i], dth[SR_T_V + i], row);
    if (!ns) return;
    for (i = 0; i < 3; ++i) {
        int j;
        for (j = 0; j < 3; ++j) dy[SR_E_xi_S + i][j] += D[3 * j + i];
        dy[SR_E_xi_S + i][i] += 1;
    }
    for (i = SR_E_th_Y; i < NS; ++i) dy[state_row(i)][i] += 1;
}

/* The start state's own error on the carried columns: the identity on the first ns, 0 on the
 * others (the parameters move nothing at the start). */
static void start_rows(int ns, int nc, error_p dy)
{
    int i, c;
    for (i = 0; i < SR_NE; ++i)
        for (c = 0; c < nc; ++c) dy[i][c] = 0;
    for (c = 0; c < ns; ++c) dy[state_row(c)][c] = 1;
}

/* df on the columns cs from the stage's d(nu')/d(d, p) Jp, at y with the field f (its accelerations
 * included): the kinematic rows' derivatives along dy (dy NULL: 0) and q'/r in the column of r; the
 * accelerations' rows Jp, to which a stage of the paper's robot adds Ja dy. */
static void field_columns(const sr_model *model, const colset *cs, const sr_real y[SR_NX], const error_p dy,
                          const sr_real f[SR_NT], const sr_real Jp[SR_NV][NW], tangent_p df)
{
    const sr_real *R = y + SR_X_R_S, *w = y + SR_X_w_S, r = model->p[SR_P_r];
    const int nc = cs->n;
    const size_t row = (size_t)nc * sizeof(sr_real);
    sr_real p[2][3], wxp[2][3];
    int i, j, c;
    for (i = 0; i < SR_T_V; ++i) memset(df[i], 0, row);
    for (i = 0; i < SR_NV; ++i) memcpy(df[SR_T_V + i], Jp[i], row);
    if (cs->r_col >= 0)   /* q' is linear in r */
        for (i = 0; i < 2; ++i) df[SR_T_Q + i][cs->r_col] = f[SR_T_Q + i] / r;
    if (!dy) return;
    for (i = 0; i < 3; ++i) memcpy(df[SR_T_S + i], dy[SR_E_nu + i], row);   /* th_S' = w_S */
    memcpy(df[SR_T_Y], dy[SR_E_nu + 3], row);
    memcpy(df[SR_T_P], dy[SR_E_nu + 4], row);
    for (j = 0; j < 3; ++j) {   /* d(q') = p . dw + (w x p) . dxi, as in sr_step_jacobian_lie_euler */
        p[0][j] = r * R[3 + j];
        p[1][j] = -r * R[j];
    }
    for (i = 0; i < 2; ++i) {
        wxp[i][0] = w[1] * p[i][2] - w[2] * p[i][1];
        wxp[i][1] = w[2] * p[i][0] - w[0] * p[i][2];
        wxp[i][2] = w[0] * p[i][1] - w[1] * p[i][0];
        for (c = 0; c < nc; ++c) {   /* summed in a local, in the order of j (see sr_internal_cholesky_solve) */
            sr_real t = df[SR_T_Q + i][c];
            for (j = 0; j < 3; ++j) t += p[i][j] * dy[SR_E_nu + j][c] + wxp[i][j] * dy[SR_E_xi_S + j][c];
            df[SR_T_Q + i][c] = t;
        }
    }
}

/* The vector field f at y and df = J_f(y) dy + df/dp(y) on the columns cs (dy NULL: y is the
 * step's start, dy = 0). */
static int field_rows(const sr_model *model, const sr_real *constants, const colset *cs, const sr_real y[SR_NX],
                      const sr_real u[SR_NU], const error_p dy, sr_real f[SR_NT], tangent_p df)
{
    const int nc = cs->n;
    sr_real a[SR_NV], Jp[SR_NV][NW], Ja[SR_NV * SR_NE], Jb[SR_NV * SR_NU];
    int i, j, c, status;
    const int general_stage = dy && model->general;
    sr_internal_kinematics(model, y, f);
    if (general_stage) status = general_stage_rows(model, cs, y, u, dy, f + SR_T_V, Jp);
    else status = accel_param_jacobian(model, constants, cs, y, u, f + SR_T_V, Jp);
    if (status == SR_OK && dy && !general_stage) status = sr_internal_accel_jacobian(model, y, u, a, Ja, Jb);
    /* A stage state that overflowed fails the pivot test (NaN): report what happened. */
    if (status != SR_OK) return status == SR_ERR_SINGULAR && !all_finite(y, SR_NX) ? SR_ERR_NONFINITE : status;
    field_columns(model, cs, y, dy, f, (const sr_real(*)[NW])Jp, df);
    for (i = 0; i < SR_NV && dy && !general_stage; ++i)   /* the accelerations: Ja dy (q's columns of Ja are zero) */
        for (j = 0; j < SR_NE; ++j) {
            const sr_real m = Ja[SR_NE * i + j];
            if (j == SR_E_q || j == SR_E_q + 1) continue;
            for (c = 0; c < nc; ++c) df[SR_T_V + i][c] += m * dy[j][c];
        }
    return SR_OK;
}

/* RKMK4's stage s > 1 after its field: k_S = dexp^-1(th, f_S), dk_S = P df_S + Q dth_S on the nc
 * columns (K_s, dK its field and df on entry), and dsum += b_s dK. */
static void stage_combine(int nc, const sr_real th[SR_NT], const tangent_p dth, sr_real b_s, sr_real K_s[SR_NT],
                          tangent_p dK, tangent_p dsum)
{
    sr_real P[9], Q[9], kS[3], dS[3][NW];
    int i, j, c;
    dexpinv_and_derivatives(th, K_s, kS, P, Q);
    for (i = 0; i < 3; ++i)
        for (c = 0; c < nc; ++c) {   /* summed in a local (see sr_internal_cholesky_solve) */
            sr_real t = 0;
            for (j = 0; j < 3; ++j) t += P[3 * i + j] * dK[SR_T_S + j][c] + Q[3 * i + j] * dth[SR_T_S + j][c];
            dS[i][c] = t;
        }
    for (i = 0; i < 3; ++i) {
        K_s[SR_T_S + i] = kS[i];
        memcpy(dK[SR_T_S + i], dS[i], (size_t)nc * sizeof(sr_real));
    }
    for (i = 0; i < SR_NT; ++i)
        for (c = 0; c < nc; ++c) dsum[i][c] += b_s * dK[i][c];
}

/* RKMK4's end from the four stages' K and dsum = sum_k b_k dK_k: dy, and x_end (unless NULL). */
static void step_end(const colset *cs, const sr_real x[SR_NX], sr_real h, const sr_real K[4][SR_NT], const tangent_p dsum,
                     error_p dy, sr_real *x_end)
{
    const sr_real b[4] = {h / 6, h / 3, h / 3, h / 6};
    sr_real th[SR_NT], D[9];
    int i, s;
    for (i = 0; i < SR_NT; ++i) {   /* as the stepper's combine */
        th[i] = 0;
        for (s = 0; s < 4; ++s) th[i] += b[s] * K[s][i];
    }
    if (cs->ns || x_end) so3_exp_minus_identity(th + SR_T_S, D);
    if (x_end) act_increment(x, D, th, NULL, x_end);   /* the step itself, as the stepper's advance */
    action_rows(cs->ns, cs->n, th, D, dsum, dy);
}

/* RKMK4 with the state held: K1 = f(x), K_s = dexp^-1(th_s, f(x . exp(th_s))), th_s = a_s h K_(s-1),
 * x_new = x . exp(sum_k b_k K_k); dy the error of x_new along p.  Only the last stage's dK is kept
 * and the combination sum_k b_k dK_k is summed as the stages go (in the combine's order): a
 * quarter of the stack, which keeps the working set in L1. */
static int rkmk4_param(const sr_model *model, const colset *cs, const sr_real x[SR_NX], const sr_real u[SR_NU],
                       sr_real h, error_p dy, sr_real *x_end)
{
    static const sr_real a_diag[3] = {SR_C(0.5), SR_C(0.5), SR_C(1.0)};
    const sr_real b[4] = {h / 6, h / 3, h / 3, h / 6};
    const int nc = cs->n;
    sr_real K[4][SR_NT], th[SR_NT], D[9], y[SR_NX], cg[SR_GEN_GENERAL_NCONST];
    const sr_real *constants = general_constants(model, cg);
    tangent_p dK, dth, dsum;
    error_p dstage;
    int s, i, c, status;
    if (cs->ns) start_rows(cs->ns, nc, dstage);
    status = field_rows(model, constants, cs, x, u, cs->ns ? (const sr_real(*)[NW])dstage : NULL, K[0], dK);
    for (i = 0; i < SR_NT; ++i)
        for (c = 0; c < nc; ++c) dsum[i][c] = b[0] * dK[i][c];
    for (s = 1; s < 4 && status == SR_OK; ++s) {
        const sr_real hs = a_diag[s - 1] * h;
        for (i = 0; i < SR_NT; ++i) th[i] = hs * K[s - 1][i];
        for (i = 0; i < SR_NT; ++i)
            for (c = 0; c < nc; ++c) dth[i][c] = hs * dK[i][c];
        so3_exp_minus_identity(th + SR_T_S, D);
        act_increment(x, D, th, NULL, y);   /* the stepper's stage state */
        action_rows(cs->ns, nc, th, D, (const sr_real(*)[NW])dth, dstage);
        status = field_rows(model, constants, cs, y, u, (const sr_real(*)[NW])dstage, K[s], dK);
        if (status == SR_OK) stage_combine(nc, th, (const sr_real(*)[NW])dth, b[s], K[s], dK, dsum);
    }
    if (status != SR_OK) return status;
    step_end(cs, x, h, (const sr_real(*)[SR_NT])K, (const sr_real(*)[NW])dsum, dy, x_end);
    return SR_OK;
}

/* Lie-Euler: x_new = x . exp(h f(x)). */
static int lie_euler_param(const sr_model *model, const colset *cs, const sr_real x[SR_NX], const sr_real u[SR_NU],
                           sr_real h, error_p dy, sr_real *x_end)
{
    sr_real f[SR_NT], th[SR_NT], D[9], cg[SR_GEN_GENERAL_NCONST];
    tangent_p df;
    int i, c, status;
    if (cs->ns) start_rows(cs->ns, cs->n, dy);
    status = field_rows(model, general_constants(model, cg), cs, x, u, cs->ns ? (const sr_real(*)[NW])dy : NULL, f, df);
    if (status != SR_OK) return status;
    for (i = 0; i < SR_NT; ++i) {
        th[i] = h * f[i];
        for (c = 0; c < cs->n; ++c) df[i][c] *= h;
    }
    if (cs->ns || x_end) so3_exp_minus_identity(th + SR_T_S, D);
    if (x_end) act_increment(x, D, th, NULL, x_end);
    action_rows(cs->ns, cs->n, th, D, (const sr_real(*)[NW])df, dy);
    return SR_OK;
}

/* The step's sensitivity on the columns cs at a state not yet checked (u may be NULL); dy's first
 * cs->n columns written, and x_end (unless NULL) the step's end state, from the same stages. */
static int step_param(const sr_model *model, const colset *cs, int method, const sr_real x[SR_NX],
                      const sr_real u[SR_NU], sr_real dt, error_p dy, sr_real *x_end)
{
    int status = sr_internal_check_state(model, x);
    if (status == SR_OK && u && !all_finite(u, SR_NU)) status = SR_ERR_NONFINITE;
    if (status != SR_OK) return status;
    if (!u) u = sr_zero_u;
    return method == SR_LIE_EULER ? lie_euler_param(model, cs, x, u, dt, dy, x_end)
                                  : rkmk4_param(model, cs, x, u, dt, dy, x_end);
}

int sr_step_param_jacobian(const sr_model *model, int method, const sr_real x[SR_NX], const sr_real u[SR_NU],
                           sr_real dt, sr_real Jp[SR_NE * SR_NPARAM])
{
    error_p dy;
    int i, status = arg_model(model, READS(WHOLE));
    if (status != SR_OK) return status;
    if (!x || !Jp) return SR_ERR_NULL;
    if ((method != SR_LIE_EULER && method != SR_RKMK4) || arg_dt(dt) != SR_OK) return SR_ERR_ARG;
    status = step_param(model, &ALL_COLUMNS, method, x, u, dt, dy, NULL);
    for (i = 0; i < SR_NE && status == SR_OK; ++i)
        if (!all_finite(dy[i], NP)) status = SR_ERR_NONFINITE;
    if (status != SR_OK) return status;
    for (i = 0; i < SR_NE; ++i) memcpy(Jp + NP * i, dy[i], NP * sizeof(sr_real));
    return SR_OK;
}

int sr_step_param_jacobian_batch(const sr_model *model, int method, long n, const sr_real *x, const sr_real *u,
                                 sr_real dt, sr_real *Jp, long *failed_row)
{
    long i;
    int status = arg_model(model, READS(WHOLE));
    if (failed_row) *failed_row = -1;
    if (status == SR_OK) status = arg_rows(n, x && Jp);
    if (status == SR_OK && ((method != SR_LIE_EULER && method != SR_RKMK4) || arg_dt(dt) != SR_OK)) status = SR_ERR_ARG;
    if (status != SR_OK) return status;
    for (i = 0; i < n; ++i) {
        status = sr_step_param_jacobian(model, method, x + i * SR_NX, u ? u + i * SR_NU : NULL, dt,
                                        Jp + i * SR_NE * NP);
        if (status != SR_OK) {
            if (failed_row) *failed_row = i;
            return status;
        }
    }
    return SR_OK;
}

/* Row k of a step's F (SR_NE entries) from row k of dy's NS state columns: the carried directions
 * in place, the identity on q's (nothing depends on q: see NS). */
static void state_columns(const sr_real dy_k[NW], int k, sr_real F_k[SR_NE])
{
    int c;
    for (c = 0; c < NS; ++c) F_k[state_row(c)] = dy_k[c];
    F_k[SR_E_q] = (sr_real)(k == SR_E_q);
    F_k[SR_E_q + 1] = (sr_real)(k == SR_E_q + 1);
}

/* ---- RKMK4 on a block of states in lockstep ---------------------------------------------------- */

/* SR_PARAM_LANES: the states a block takes through RKMK4's stages together (rkmk4_param_lanes), 0
 * for none.  8 where the compiler has vectors of doubles to run the lanes kernels on (x86-64,
 * AArch64), at about 120 KB of stack with its callees; 0 elsewhere (a Cortex-M gains nothing from it). */
#ifndef SR_PARAM_LANES
#if defined(__x86_64__) || defined(__aarch64__)
#define SR_PARAM_LANES 8
#else
#define SR_PARAM_LANES 0
#endif
#endif

#if SR_PARAM_LANES > 0
#define LANES SR_PARAM_LANES

/* RKMK4's sensitivity on the columns cs (every parameter column moving pi alone; no state columns,
 * or the NS of a step's F before them) of a general robot at m <= LANES states x (rows SR_NX apart;
 * u rows u_stride apart, 0 for one row), checked by the caller: the same arithmetic as rkmk4_param
 * state by state, but each stage's two generated kernels (M, f and their state derivatives; the
 * regressor) run on all the block's stage states at once in their lanes forms (sr_gen_*_lanes,
 * vectorised across the states, each lane the scalar kernel's bits).  Jp (m x SR_NE x the parameter
 * columns), F (m x SR_NE x SR_NE, with state columns only, as sr_step_jacobian_param_cols_batch
 * writes it) and x_next (m x SR_NX, unless NULL) written; SR_OK, else nonzero where any state fails
 * (a singular M, a flag the lanes cleared, a non-finite result): then the caller redoes the block
 * state by state, which reports the failing row. */
static int rkmk4_param_lanes(const sr_model *model, const colset *cs, int m, const sr_real *x, const sr_real *u,
                             long u_stride, sr_real h, sr_real *F, sr_real *Jp, sr_real *x_next)
{
    static const sr_real a_diag[3] = {SR_C(0.5), SR_C(0.5), SR_C(1.0)};
    const sr_real b[4] = {h / 6, h / 3, h / 3, h / 6};
    const int nc = cs->n;
    sr_real K[LANES][4][SR_NT], th[LANES][SR_NT], D[LANES][9], y[LANES][SR_NX], ok[LANES];
    sr_real Mu[LANES][15], f[LANES][SR_NV], df[LANES][SR_NV * SR_NE], dfdu[LANES][SR_NV * SR_NU], dM[LANES][5 * 15];
    sr_real L[LANES][SR_NV * SR_NV], inv[LANES][SR_NV], Y[LANES][SR_NV * SR_NPI], Jr[SR_NV][NW], end[SR_NX];
    tangent_p dK[LANES], dsum[LANES], dth;
    error_p dstage;
    int l, s, i, c, status = SR_OK;
    if (cs->ns) {   /* K1 = f(x) with the state columns: x's stage as every later one (general_stage_rows) */
        sr_gen_general_accel_jacobian_terms_lanes(model->cg, m, x, SR_NX, u, u_stride, Mu[0], 15, f[0], SR_NV, df[0],
                                                  SR_NV * SR_NE, dfdu[0], SR_NV * SR_NU, dM[0], 5 * 15, ok);
        for (l = 0; l < m && status == SR_OK; ++l) {
            sr_internal_kinematics(model, x + SR_NX * l, K[l][0]);
            status = ok[l] == 1 ? stage_accel(Mu[l], f[l], L[l], inv[l], K[l][0] + SR_T_V) : SR_ERR_NONFINITE;
        }
    }
    for (l = 0; l < m && status == SR_OK && !cs->ns; ++l) {   /* K1 = f(x): M and f alone, as accel_param_jacobian */
        sr_internal_kinematics(model, x + SR_NX * l, K[l][0]);
        status = sr_gen_general_system(model->cg, x + SR_NX * l, u + u_stride * l, Mu[l], f[l]);
        if (status == SR_OK) status = sr_internal_cholesky(Mu[l], L[l], inv[l]);
        for (i = 0; i < SR_NV; ++i) K[l][0][SR_T_V + i] = f[l][i];
        if (status == SR_OK) sr_internal_cholesky_solve(L[l], inv[l], 1, 1, K[l][0] + SR_T_V);
    }
    if (status != SR_OK) return status;
    for (s = 0; s < 4; ++s) {
        const sr_real *ys = s ? &y[0][0] : x;
        const sr_real hs = s ? a_diag[s - 1] * h : 0;
        if (s) {   /* the stage states, then M, f and their derivatives there */
            for (l = 0; l < m; ++l) {
                for (i = 0; i < SR_NT; ++i) th[l][i] = hs * K[l][s - 1][i];
                so3_exp_minus_identity(th[l] + SR_T_S, D[l]);
                act_increment(x + SR_NX * l, D[l], th[l], NULL, y[l]);
            }
            sr_gen_general_accel_jacobian_terms_lanes(model->cg, m, ys, SR_NX, u, u_stride, Mu[0], 15, f[0], SR_NV, df[0],
                                                      SR_NV * SR_NE, dfdu[0], SR_NV * SR_NU, dM[0], 5 * 15, ok);
            for (l = 0; l < m && status == SR_OK; ++l) {
                sr_internal_kinematics(model, y[l], K[l][s]);
                status = ok[l] == 1 ? stage_accel(Mu[l], f[l], L[l], inv[l], K[l][s] + SR_T_V) : SR_ERR_NONFINITE;
            }
            if (status != SR_OK) return status;
        }
        sr_gen_regressor_lanes(model->p, m, ys, SR_NX, K[0][s] + SR_T_V, 4 * SR_NT, Y[0], SR_NV * SR_NPI, ok);
        for (l = 0; l < m; ++l) {
            if (ok[l] != 1) return SR_ERR_NONFINITE;
            regressor_columns(cs, Y[l], Jr);
            if (!s && cs->ns) {   /* the start's own error carried: start_rows, then the stage's columns */
                start_rows(cs->ns, nc, dstage);
                stage_columns(cs, df[l], dM[l], L[l], inv[l], K[l][0] + SR_T_V, (const sr_real(*)[NW])dstage, Jr);
                field_columns(model, cs, x + SR_NX * l, (const sr_real(*)[NW])dstage, K[l][0], (const sr_real(*)[NW])Jr,
                              dK[l]);
            } else if (!s) {
                sr_internal_cholesky_solve(L[l], inv[l], NW, nc, &Jr[0][0]);
                field_columns(model, cs, x + SR_NX * l, NULL, K[l][0], (const sr_real(*)[NW])Jr, dK[l]);
            }
            if (!s) {
                for (i = 0; i < SR_NT; ++i)
                    for (c = 0; c < nc; ++c) dsum[l][i][c] = b[0] * dK[l][i][c];
                continue;
            }
            for (i = 0; i < SR_NT; ++i)
                for (c = 0; c < nc; ++c) dth[i][c] = hs * dK[l][i][c];
            action_rows(cs->ns, nc, th[l], D[l], (const sr_real(*)[NW])dth, dstage);
            stage_columns(cs, df[l], dM[l], L[l], inv[l], K[l][s] + SR_T_V, (const sr_real(*)[NW])dstage, Jr);
            field_columns(model, cs, y[l], (const sr_real(*)[NW])dstage, K[l][s], (const sr_real(*)[NW])Jr, dK[l]);
            stage_combine(nc, th[l], (const sr_real(*)[NW])dth, b[s], K[l][s], dK[l], dsum[l]);
        }
    }
    for (l = 0; l < m; ++l) {
        const int np = nc - cs->ns;
        sr_real *out = Jp + (long)l * SR_NE * np;
        step_end(cs, x + SR_NX * l, h, (const sr_real(*)[SR_NT])K[l], (const sr_real(*)[NW])dsum[l], dstage, end);
        for (i = 0; i < SR_NE; ++i) {
            if (!all_finite(dstage[i], nc)) return SR_ERR_NONFINITE;
            if (cs->ns) state_columns(dstage[i], i, F + ((long)l * SR_NE + i) * SR_NE);
            for (c = 0; c < np; ++c) out[i * np + c] = dstage[i][cs->ns + c];
        }
        if (x_next) {
            if (!all_finite(end, SR_NX)) return SR_ERR_NONFINITE;
            memcpy(x_next + SR_NX * l, end, sizeof end);
        }
    }
    return SR_OK;
}

/* Whether the block of LANES states from row i (fewer at the end of n) passes step_param's checks:
 * each state valid, its torques (u not NULL) finite. */
static int lanes_checked(const sr_model *model, const sr_real *x, const sr_real *u, long i, long n)
{
    long k;
    for (k = i; k < n && k < i + LANES; ++k)
        if (sr_internal_check_state(model, x + k * SR_NX) != SR_OK || (u && !all_finite(u + k * SR_NU, SR_NU))) return 0;
    return 1;
}
#endif

/* sr_step_param_jacobian_cols_batch; with_next: each row's end state in x_next (n x SR_NX) too. */
static int cols_batch(const sr_model *model, int method, long n, const sr_real *x, const sr_real *u, sr_real dt,
                      int ncols, const int *cols, int with_next, sr_real *x_next, sr_real *Jp, long *failed_row)
{
    colset cs;
    pi_column pi[NP];
    error_p dy;
    sr_real end[SR_NX];
    long i;
    int k, c, status = arg_model(model, READS(WHOLE));
    if (failed_row) *failed_row = -1;
    if (status == SR_OK) status = arg_columns(ncols, cols);
    if (status == SR_OK) status = arg_rows(n, x && Jp && (x_next || !with_next));
    if (status == SR_OK && ((method != SR_LIE_EULER && method != SR_RKMK4) || arg_dt(dt) != SR_OK)) status = SR_ERR_ARG;
    if (status != SR_OK) return status;
    cs = columns_of(model, 0, ncols, cols, pi);
    for (i = 0; i < n; ++i) {
        sr_real *out = Jp + i * SR_NE * ncols;
#if SR_PARAM_LANES > 0
        if (i % LANES == 0 && method == SR_RKMK4 && model->general && cs.pi && lanes_checked(model, x, u, i, n)) {
            const int m = n - i < LANES ? (int)(n - i) : LANES;
            if (rkmk4_param_lanes(model, &cs, m, x + i * SR_NX, u ? u + i * SR_NU : sr_zero_u, u ? SR_NU : 0, dt, NULL,
                                  out, with_next ? x_next + i * SR_NX : NULL) == SR_OK) {
                i += m - 1;
                continue;
            }
        }
#endif
        status = step_param(model, &cs, method, x + i * SR_NX, u ? u + i * SR_NU : NULL, dt, dy, with_next ? end : NULL);
        for (k = 0; k < SR_NE && status == SR_OK; ++k) {
            if (!all_finite(dy[k], ncols)) status = SR_ERR_NONFINITE;
            for (c = 0; c < ncols; ++c) out[k * ncols + c] = dy[k][c];
        }
        if (status == SR_OK && with_next) {
            if (!all_finite(end, SR_NX)) status = SR_ERR_NONFINITE;
            memcpy(x_next + i * SR_NX, end, sizeof end);
        }
        if (status != SR_OK) {
            if (failed_row) *failed_row = i;
            return status;
        }
    }
    return SR_OK;
}

int sr_step_param_jacobian_cols_batch(const sr_model *model, int method, long n, const sr_real *x, const sr_real *u,
                                      sr_real dt, int ncols, const int *cols, sr_real *Jp, long *failed_row)
{
    return cols_batch(model, method, n, x, u, dt, ncols, cols, 0, NULL, Jp, failed_row);
}

int sr_step_and_param_jacobian_cols_batch(const sr_model *model, int method, long n, const sr_real *x,
                                          const sr_real *u, sr_real dt, int ncols, const int *cols, sr_real *x_next,
                                          sr_real *Jp, long *failed_row)
{
    return cols_batch(model, method, n, x, u, dt, ncols, cols, 1, x_next, Jp, failed_row);
}

int sr_step_jacobian_param_cols_batch(const sr_model *model, int method, long n, const sr_real *x, const sr_real *u,
                                      sr_real dt, int ncols, const int *cols, sr_real *F, sr_real *Jp,
                                      long *failed_row)
{
    colset cs;
    pi_column pi[NP];
    error_p dy;
    long i;
    int k, c, status = arg_model(model, READS(WHOLE));
    if (failed_row) *failed_row = -1;
    if (status == SR_OK) status = arg_columns(ncols, cols);
    if (status == SR_OK) status = arg_rows(n, x && F && Jp);
    if (status == SR_OK && ((method != SR_LIE_EULER && method != SR_RKMK4) || arg_dt(dt) != SR_OK)) status = SR_ERR_ARG;
    if (status != SR_OK) return status;
    cs = columns_of(model, NS, ncols, cols, pi);
    for (i = 0; i < n; ++i) {
        sr_real *f = F + i * SR_NE * SR_NE, *out = Jp + i * SR_NE * ncols;
#if SR_PARAM_LANES > 0
        if (i % LANES == 0 && method == SR_RKMK4 && model->general && cs.pi && lanes_checked(model, x, u, i, n)) {
            const int m = n - i < LANES ? (int)(n - i) : LANES;
            if (rkmk4_param_lanes(model, &cs, m, x + i * SR_NX, u ? u + i * SR_NU : sr_zero_u, u ? SR_NU : 0, dt, f, out,
                                  NULL) == SR_OK) {
                i += m - 1;
                continue;
            }
        }
#endif
        status = step_param(model, &cs, method, x + i * SR_NX, u ? u + i * SR_NU : NULL, dt, dy, NULL);
        for (k = 0; k < SR_NE && status == SR_OK; ++k) {
            if (!all_finite(dy[k], NS + ncols)) status = SR_ERR_NONFINITE;
            state_columns(dy[k], k, f + SR_NE * k);
            for (c = 0; c < ncols; ++c) out[k * ncols + c] = dy[k][NS + c];
        }
        if (status != SR_OK) {
            if (failed_row) *failed_row = i;
            return status;
        }
    }
    return SR_OK;
}

int sr_accel_param_jacobian_cols_batch(const sr_model *model, long n, const sr_real *x, const sr_real *u, int ncols,
                                       const int *cols, sr_real *J, long *failed_row)
{
    colset cs;
    pi_column pi[NP];
    sr_real a[SR_NV], j[SR_NV][NW], cg[SR_GEN_GENERAL_NCONST];
    const sr_real *constants;
    long i;
    int k, c, status = arg_model(model, READS(WHOLE));
    if (failed_row) *failed_row = -1;
    if (status == SR_OK) status = arg_columns(ncols, cols);
    if (status == SR_OK) status = arg_rows(n, x && J);
    if (status != SR_OK) return status;
    cs = columns_of(model, 0, ncols, cols, pi);
    constants = general_constants(model, cg);
    for (i = 0; i < n; ++i) {
        const sr_real *ui = u ? u + i * SR_NU : NULL;
        sr_real *out = J + i * SR_NV * ncols;
        status = sr_internal_check_state(model, x + i * SR_NX);
        if (status == SR_OK && ui && !all_finite(ui, SR_NU)) status = SR_ERR_NONFINITE;
        if (status == SR_OK) status = accel_param_jacobian(model, constants, &cs, x + i * SR_NX, ui ? ui : sr_zero_u, a, j);
        for (k = 0; k < SR_NV && status == SR_OK; ++k) {
            if (!all_finite(j[k], ncols)) status = SR_ERR_NONFINITE;
            for (c = 0; c < ncols; ++c) out[k * ncols + c] = j[k][c];
        }
        if (status != SR_OK) {
            if (failed_row) *failed_row = i;
            return status;
        }
    }
    return SR_OK;
}

/* ---- the regressor -------------------------------------------------------------------------- */

int sr_regressor(const sr_model *model, const sr_real x[SR_NX], const sr_real nudot[SR_NV],
                 sr_real Y[SR_NV * SR_NPI])
{
    sr_real y[SR_NV * SR_NPI];
    int status = arg_model(model, READS(WHOLE));
    if (status != SR_OK) return status;
    if (!x || !nudot || !Y) return SR_ERR_NULL;
    status = sr_internal_check_state(model, x);
    if (status == SR_OK && !all_finite(nudot, SR_NV)) status = SR_ERR_NONFINITE;
    if (status == SR_OK) status = sr_gen_regressor(model->p, x, nudot, y);
    if (status != SR_OK) return status;
    memcpy(Y, y, sizeof y);
    return SR_OK;
}

int sr_regressor_batch(const sr_model *model, long n, const sr_real *x, const sr_real *nudot, sr_real *Y,
                       long *failed_row)
{
    long i;
    int status = arg_model(model, READS(WHOLE));
    if (failed_row) *failed_row = -1;
    if (status == SR_OK) status = arg_rows(n, x && nudot && Y);
    if (status != SR_OK) return status;
    for (i = 0; i < n; ++i) {
        status = sr_regressor(model, x + i * SR_NX, nudot + i * SR_NV, Y + i * SR_NV * SR_NPI);
        if (status != SR_OK) {
            if (failed_row) *failed_row = i;
            return status;
        }
    }
    return SR_OK;
}
