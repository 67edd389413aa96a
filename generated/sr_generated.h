/* GENERATED FILE, DO NOT EDIT: written by `make generate` (python -m derive) from the derive/ package [sha256 of its sources c3fc8b42fe5ac388], SymPy 1.14.0. */
/*
 * Symbolic kernels of the spherical-robot model (Fiori 2024), derived in derive/.
 * Internal to the library: use the checked API of c/spherical_robot.h.
 * Every function returns SR_GEN_OK, SR_GEN_NONFINITE (a result is not finite) or, for accel,
 * SR_GEN_SINGULAR; outputs are caller-provided and written only on SR_GEN_OK (sr_gen_constants:
 * always, the caller checks them).
 */
#ifndef SR_GENERATED_H
#define SR_GENERATED_H

/* sr_real, SR_C, SR_GEN_PIVOT_TOL and the SR_GEN_ status codes: hand-written, in c/. */
#include "sr_real.h"

#define SR_GEN_NPARAM 12
#define SR_GEN_NCONST 40
#define SR_GEN_NCONST_NAMED 12
#define SR_GEN_NX 35
#define SR_GEN_NU 2
#define SR_GEN_NV 5
#define SR_GEN_NE 12

/* Layout of x[SR_GEN_NX]: offset of each block (matrices row-major; nu = (w_S, w_Y, w_P) starts at SR_X_w_S). */
#define SR_X_R_S 0
#define SR_X_R_Y 9
#define SR_X_R_P 18
#define SR_X_q 27
#define SR_X_w_S 30
#define SR_X_w_Y 33
#define SR_X_w_P 34
/* Layout of u[SR_GEN_NU]. */
#define SR_U_u_Y 0
#define SR_U_u_P 1
/* Layout of the error state d[SR_GEN_NE] (tangent coordinates of x, right-trivialised: x (+) d). */
#define SR_E_xi_S 0
#define SR_E_th_Y 3
#define SR_E_th_P 4
#define SR_E_q 5
#define SR_E_nu 7
/* Layout of p[SR_GEN_NPARAM], the parameters of derive/parameters.py (SI). */
#define SR_P_r 0
#define SR_P_m_S 1
#define SR_P_k_S 2
#define SR_P_b 3
#define SR_P_h 4
#define SR_P_m_b 5
#define SR_P_m_h 6
#define SR_P_k_Y 7
#define SR_P_l 8
#define SR_P_m_P 9
#define SR_P_k_P 10
#define SR_P_g 11

/* Arithmetic operations (+ - * /) per call, counted in the emitted code after CSE. */
#define SR_GEN_CONSTANTS_FLOPS 69
#define SR_GEN_INERTIA_FLOPS 107
#define SR_GEN_RHS_FLOPS 168
#define SR_GEN_ENERGY_FLOPS 136
#define SR_GEN_EQUILIBRIUM_RESIDUAL_FLOPS 23
#define SR_GEN_ACCEL_FLOPS 261
#define SR_GEN_ACCEL_JACOBIAN_TERMS_FLOPS 1779

/* The float build's symbols carry _f, so a float/double mismatch fails at link time. */
#ifdef SR_USE_FLOAT
#define sr_gen_constants sr_gen_constants_f
#define sr_gen_inertia sr_gen_inertia_f
#define sr_gen_rhs sr_gen_rhs_f
#define sr_gen_energy sr_gen_energy_f
#define sr_gen_equilibrium_residual sr_gen_equilibrium_residual_f
#define sr_gen_accel sr_gen_accel_f
#define sr_gen_accel_jacobian_terms sr_gen_accel_jacobian_terms_f
#endif

/* Derived constants of Section 2.3 from the twelve parameters, c[0..11] = (r, l, g, m_P, m_R, j_S, j_xx, j_yy, j_P, k_S, k_Y, k_P), then the parameter-only subexpressions of the kernels, computed once per model:
 *   c[12] k_0 = m_R*r**2
 *   c[13] k_1 = l*m_P*r
 *   c[14] k_2 = j_P + j_S + j_xx
 *   c[15] k_3 = l*m_P*r/2
 *   c[16] k_4 = j_P + j_xx
 *   c[17] k_5 = j_P - j_xx
 *   c[18] k_6 = j_P + j_S + j_yy + m_R*r**2
 *   c[19] k_7 = j_S + j_xx + j_yy + m_R*r**2
 *   c[20] k_8 = j_xx + j_yy
 *   c[21] k_9 = g*l*m_P/2
 *   c[22] k_10 = j_P/2 + j_S/2 + j_xx/2
 *   c[23] k_11 = j_P/2 + j_S/2 + j_yy/2 + m_R*r**2/2
 *   c[24] k_12 = j_S/2 + j_xx/2 + j_yy/2 + m_R*r**2/2
 *   c[25] k_13 = j_P/2 + j_xx/2
 *   c[26] k_14 = j_P/2
 *   c[27] k_15 = g*m_P
 *   c[28] k_16 = j_P/2 - j_xx/2
 *   c[29] k_17 = m_R*r**2/2
 *   c[30] k_18 = 1/j_P
 *   c[31] k_19 = j_xx - j_yy
 *   c[32] k_20 = l*m_P*r/(2*j_P)
 *   c[33] k_21 = 2*j_P - 2*j_xx
 *   c[34] k_22 = 2*j_P
 *   c[35] k_23 = j_P - j_yy
 *   c[36] k_24 = 2*j_xx
 *   c[37] k_25 = 4*j_P - 4*j_xx
 *   c[38] k_26 = 4*j_P
 *   c[39] k_27 = 2*m_R*r**2 */
int sr_gen_constants(const sr_real p[SR_GEN_NPARAM], sr_real c[SR_GEN_NCONST]);
/* Generalized inertia M(γ, R_Y, R_P), row-major 5x5, kinetic energy ½νᵀMν. */
int sr_gen_inertia(const sr_real c[SR_GEN_NCONST], const sr_real x[SR_GEN_NX], sr_real M[25]);
/* Right-hand side f of M ν̇ = f: gyroscopic, non-holonomic, gravity, motor and friction terms. */
int sr_gen_rhs(const sr_real c[SR_GEN_NCONST], const sr_real x[SR_GEN_NX], const sr_real u[SR_GEN_NU], sr_real f[5]);
/* Total energy: ½νᵀMν + m_P g e_zᵀ(q + R_S R_Y R_P c̄_P) [J]. */
int sr_gen_energy(const sr_real c[SR_GEN_NCONST], const sr_real x[SR_GEN_NX], sr_real E[1]);
/* f at ν = 0, u = 0 (eq. 106); zero iff R_S R_Y R_P e_z = ±e_z (eq. 108). */
int sr_gen_equilibrium_residual(const sr_real c[SR_GEN_NCONST], const sr_real x[SR_GEN_NX], sr_real res[5]);
/* ν̇ = (ω̇_S, ω̇_Y, ω̇_P) solving M ν̇ = f, joints first; SR_GEN_SINGULAR if M is not positive definite. */
int sr_gen_accel(const sr_real c[SR_GEN_NCONST], const sr_real x[SR_GEN_NX], const sr_real u[SR_GEN_NU], sr_real a[SR_GEN_NV]);
/* M (upper triangle, row by row), f, ∂f/∂d (5 x SR_GEN_NE, row-major, error coordinates of SR_E_*), ∂f/∂u (5 x 2) and ∂M/∂d along δξ_S, δθ_Y, δθ_P (5 upper triangles) for the accel Jacobian ∂ν̇ = M⁻¹(∂f − (∂M) ν̇). */
int sr_gen_accel_jacobian_terms(const sr_real c[SR_GEN_NCONST], const sr_real x[SR_GEN_NX], const sr_real u[SR_GEN_NU], sr_real M[15], sr_real f[5], sr_real df[60], sr_real dfdu[10], sr_real dM[75]);

#endif /* SR_GENERATED_H */
