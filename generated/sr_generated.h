/* GENERATED FILE, DO NOT EDIT: written by `make generate` (python -m derive) from the derive/ package [sha256 of its sources 51effb25c19c215e], SymPy 1.14.0. */
/*
 * Symbolic kernels of the spherical-robot model (Fiori 2024), derived in derive/.
 * Internal to the library: use the checked API of c/include/spherical_robot.h.
 * Every function returns SR_GEN_OK, SR_GEN_NONFINITE (a result is not finite) or, for accel,
 * SR_GEN_SINGULAR; outputs are caller-provided and written only on SR_GEN_OK (sr_gen_constants:
 * always, the caller checks them).
 */
#ifndef SR_GENERATED_H
#define SR_GENERATED_H

/* sr_real, SR_C, SR_GEN_PIVOT_TOL and the SR_GEN_ status codes: hand-written, in c/include/. */
#include "sr_real.h"

#define SR_GEN_NPARAM 32
#define SR_GEN_NPAPER 12
#define SR_GEN_NPI 27
#define SR_GEN_NCONST 38
#define SR_GEN_NCONST_NAMED 12
#define SR_GEN_GENERAL_NCONST 104
#define SR_GEN_GENERAL_NCONST_NAMED 31
#define SR_GEN_NX 35
#define SR_GEN_NU 2
#define SR_GEN_NV 5
#define SR_GEN_NE 12
#define SR_GEN_NSC 3
#define SR_GEN_NMOUNT 12
#define SR_GEN_NBIAS 6
#define SR_GEN_NIMU 6
#define SR_GEN_NEB 18

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
/* Layout of p[SR_GEN_NPARAM], the parameters of the general robot, derive/parameters.py (SI). */
#define SR_P_r 0
#define SR_P_m_S 1
#define SR_P_j_S 2
#define SR_P_k_S 3
#define SR_P_m_Y 4
#define SR_P_c_Y_x 5
#define SR_P_c_Y_y 6
#define SR_P_c_Y_z 7
#define SR_P_J_Y_xx 8
#define SR_P_J_Y_yy 9
#define SR_P_J_Y_zz 10
#define SR_P_J_Y_xy 11
#define SR_P_J_Y_xz 12
#define SR_P_J_Y_yz 13
#define SR_P_k_Y 14
#define SR_P_m_P 15
#define SR_P_c_P_x 16
#define SR_P_c_P_y 17
#define SR_P_c_P_z 18
#define SR_P_J_P_xx 19
#define SR_P_J_P_yy 20
#define SR_P_J_P_zz 21
#define SR_P_J_P_xy 22
#define SR_P_J_P_xz 23
#define SR_P_J_P_yz 24
#define SR_P_k_P 25
#define SR_P_j_mY 26
#define SR_P_n_Y 27
#define SR_P_j_mP 28
#define SR_P_n_P 29
#define SR_P_g 30
#define SR_P_slope 31
/* Layout of pp[SR_GEN_NPAPER], the paper's parameters (Section 5.2, SI), for sr_gen_paper_params. */
#define SR_PAPER_r 0
#define SR_PAPER_m_S 1
#define SR_PAPER_k_S 2
#define SR_PAPER_b 3
#define SR_PAPER_h 4
#define SR_PAPER_m_b 5
#define SR_PAPER_m_h 6
#define SR_PAPER_k_Y 7
#define SR_PAPER_l 8
#define SR_PAPER_m_P 9
#define SR_PAPER_k_P 10
#define SR_PAPER_g 11
/* Layout of pi[SR_GEN_NPI], the parameters the equations of motion are linear in (the regressor's columns, derive/param_derivatives.py): per body m, m c, the tensor about O, the damping; the rotors. */
#define SR_PI_m_S 0
#define SR_PI_j_S 1
#define SR_PI_k_S 2
#define SR_PI_m_Y 3
#define SR_PI_mc_Y_x 4
#define SR_PI_mc_Y_y 5
#define SR_PI_mc_Y_z 6
#define SR_PI_JO_Y_xx 7
#define SR_PI_JO_Y_yy 8
#define SR_PI_JO_Y_zz 9
#define SR_PI_JO_Y_xy 10
#define SR_PI_JO_Y_xz 11
#define SR_PI_JO_Y_yz 12
#define SR_PI_k_Y 13
#define SR_PI_m_P 14
#define SR_PI_mc_P_x 15
#define SR_PI_mc_P_y 16
#define SR_PI_mc_P_z 17
#define SR_PI_JO_P_xx 18
#define SR_PI_JO_P_yy 19
#define SR_PI_JO_P_zz 20
#define SR_PI_JO_P_xy 21
#define SR_PI_JO_P_xz 22
#define SR_PI_JO_P_yz 23
#define SR_PI_k_P 24
#define SR_PI_j_mY 25
#define SR_PI_j_mP 26
/* The bodies a sensor is mounted on (derive/sensors.py). */
#define SR_BODY_shell 0
#define SR_BODY_yoke 1
#define SR_BODY_pendulum 2
/* Layout of sc[SR_GEN_NSC], the sensor kernels' constants (sr_gen_sensor_constants). */
#define SR_SC_r 0
#define SR_SC_g_x 1
#define SR_SC_g_z 2
/* Layout of the sensor mount mount[SR_GEN_NMOUNT]: lever arm in the body's frame, mounting rotation R_m (sensor axes in the body's frame, row-major). */
#define SR_MOUNT_lever 0
#define SR_MOUNT_R_m 3
/* Layout of the IMU's biases bias[SR_GEN_NBIAS], sensor frame. */
#define SR_BIAS_b_g 0
#define SR_BIAS_b_a 3
/* Layout of an IMU reading y[SR_GEN_NIMU], sensor frame. */
#define SR_IMU_gyro 0
#define SR_IMU_accel 3
/* Layout of the estimator's error state [d | b_g | b_a] (SR_GEN_NEB), the columns of the sensor Jacobians. */
#define SR_EB_xi_S 0
#define SR_EB_th_Y 3
#define SR_EB_th_P 4
#define SR_EB_q 5
#define SR_EB_nu 7
#define SR_EB_b_g 12
#define SR_EB_b_a 15

/* Arithmetic operations (+ - * /) per call, counted in the emitted code after CSE. */
#define SR_GEN_CONSTANTS_FLOPS 44
#define SR_GEN_INERTIA_FLOPS 107
#define SR_GEN_RHS_FLOPS 168
#define SR_GEN_ENERGY_FLOPS 136
#define SR_GEN_EQUILIBRIUM_RESIDUAL_FLOPS 23
#define SR_GEN_ACCEL_FLOPS 261
#define SR_GEN_ACCEL_JACOBIAN_YOKE_TERMS_FLOPS 632
#define SR_GEN_PAPER_PARAMS_FLOPS 52
#define SR_GEN_GENERAL_CONSTANTS_FLOPS 324
#define SR_GEN_GENERAL_INERTIA_FLOPS 219
#define SR_GEN_GENERAL_RHS_FLOPS 398
#define SR_GEN_GENERAL_SYSTEM_FLOPS 615
#define SR_GEN_GENERAL_ENERGY_FLOPS 336
#define SR_GEN_GENERAL_EQUILIBRIUM_RESIDUAL_FLOPS 126
#define SR_GEN_GENERAL_ACCEL_JACOBIAN_TERMS_FLOPS 4398
#define SR_GEN_GENERAL_PARAM_RESIDUAL_JACOBIAN_FLOPS 2812
#define SR_GEN_REGRESSOR_FLOPS 1488
#define SR_GEN_SENSOR_CONSTANTS_FLOPS 4
#define SR_GEN_IMU_SHELL_FLOPS 95
#define SR_GEN_IMU_SHELL_JACOBIAN_FLOPS 440
#define SR_GEN_HEADING_SHELL_FLOPS 11
#define SR_GEN_HEADING_SHELL_JACOBIAN_FLOPS 63
#define SR_GEN_IMU_YOKE_FLOPS 124
#define SR_GEN_IMU_YOKE_JACOBIAN_FLOPS 726
#define SR_GEN_HEADING_YOKE_FLOPS 17
#define SR_GEN_HEADING_YOKE_JACOBIAN_FLOPS 91
#define SR_GEN_IMU_PENDULUM_FLOPS 161
#define SR_GEN_IMU_PENDULUM_JACOBIAN_FLOPS 1184
#define SR_GEN_HEADING_PENDULUM_FLOPS 23
#define SR_GEN_HEADING_PENDULUM_JACOBIAN_FLOPS 127
#define SR_GEN_ENCODERS_JACOBIAN_FLOPS 0
#define SR_GEN_POSITION_JACOBIAN_FLOPS 0
#define SR_GEN_CONTACT_FORCE_FLOPS 100
#define SR_GEN_GENERAL_CONTACT_FORCE_FLOPS 179

/* What each kernel reads of a model (sr_model's p, c or cg): SR_GEN_READS_<kernel>(R) expands to
 * R(array, first, end) for each run [first, end) of the entries of `array` that its code loads, and
 * to nothing for a kernel that reads none.  The read sets of the model's checksums (c/src/sr_argcheck.h). */
#define SR_GEN_READS_constants(R) R(p, 0, 5) R(p, 8, 10) R(p, 14, 16) R(p, 18, 20) R(p, 25, 26) R(p, 30, 31)
#define SR_GEN_READS_inertia(R) R(c, 8, 9) R(c, 12, 20)
#define SR_GEN_READS_rhs(R) R(c, 6, 12) R(c, 15, 16) R(c, 20, 22)
#define SR_GEN_READS_energy(R) R(c, 8, 9) R(c, 12, 13) R(c, 15, 18) R(c, 21, 30)
#define SR_GEN_READS_equilibrium_residual(R) R(c, 21, 22)
#define SR_GEN_READS_accel(R) R(c, 6, 17) R(c, 18, 22) R(c, 30, 33)
#define SR_GEN_READS_accel_jacobian_yoke_terms(R) R(c, 6, 17) R(c, 18, 22) R(c, 31, 32) R(c, 33, 37)
#define SR_GEN_READS_paper_params(R)
#define SR_GEN_READS_general_constants(R) R(p, 0, 32)
#define SR_GEN_READS_general_inertia(R) R(cg, 16, 17) R(cg, 18, 19) R(cg, 22, 23) R(cg, 24, 25) R(cg, 31, 56)
#define SR_GEN_READS_general_rhs(R) R(cg, 0, 2) R(cg, 4, 13) R(cg, 16, 19) R(cg, 22, 31) R(cg, 56, 62)
#define SR_GEN_READS_general_system(R) R(cg, 0, 2) R(cg, 4, 13) R(cg, 16, 19) R(cg, 22, 62)
#define SR_GEN_READS_general_energy(R) R(cg, 16, 17) R(cg, 18, 19) R(cg, 22, 25) R(cg, 31, 32) R(cg, 33, 35) R(cg, 39, 48) R(cg, 49, 51) R(cg, 52, 53) R(cg, 62, 82)
#define SR_GEN_READS_general_equilibrium_residual(R) R(cg, 67, 70) R(cg, 71, 72) R(cg, 75, 81) R(cg, 82, 83)
#define SR_GEN_READS_general_accel_jacobian_terms(R) R(cg, 4, 7) R(cg, 16, 17) R(cg, 18, 19) R(cg, 22, 25) R(cg, 31, 56) R(cg, 67, 70) R(cg, 71, 72) R(cg, 75, 81) R(cg, 82, 104)
#define SR_GEN_READS_general_param_residual_jacobian(R) R(p, 0, 2) R(p, 4, 8) R(p, 15, 19) R(p, 26, 32)
#define SR_GEN_READS_regressor(R) R(p, 0, 1) R(p, 27, 28) R(p, 29, 32)
#define SR_GEN_READS_sensor_constants(R) R(p, 0, 1) R(p, 30, 32)
#define SR_GEN_READS_imu_shell(R)
#define SR_GEN_READS_imu_shell_jacobian(R)
#define SR_GEN_READS_heading_shell(R)
#define SR_GEN_READS_heading_shell_jacobian(R)
#define SR_GEN_READS_imu_yoke(R)
#define SR_GEN_READS_imu_yoke_jacobian(R)
#define SR_GEN_READS_heading_yoke(R)
#define SR_GEN_READS_heading_yoke_jacobian(R)
#define SR_GEN_READS_imu_pendulum(R)
#define SR_GEN_READS_imu_pendulum_jacobian(R)
#define SR_GEN_READS_heading_pendulum(R)
#define SR_GEN_READS_heading_pendulum_jacobian(R)
#define SR_GEN_READS_encoders_jacobian(R)
#define SR_GEN_READS_position_jacobian(R)
#define SR_GEN_READS_contact_force(R) R(c, 0, 1) R(c, 2, 3) R(c, 4, 5) R(c, 37, 38)
#define SR_GEN_READS_general_contact_force(R) R(cg, 0, 2) R(cg, 7, 13) R(cg, 29, 31)

/* The float build's symbols carry _f, so a float/double mismatch fails at link time. */
#ifdef SR_USE_FLOAT
#define sr_gen_constants sr_gen_constants_f
#define sr_gen_inertia sr_gen_inertia_f
#define sr_gen_rhs sr_gen_rhs_f
#define sr_gen_energy sr_gen_energy_f
#define sr_gen_equilibrium_residual sr_gen_equilibrium_residual_f
#define sr_gen_accel sr_gen_accel_f
#define sr_gen_accel_jacobian_yoke_terms sr_gen_accel_jacobian_yoke_terms_f
#define sr_gen_paper_params sr_gen_paper_params_f
#define sr_gen_general_constants sr_gen_general_constants_f
#define sr_gen_general_inertia sr_gen_general_inertia_f
#define sr_gen_general_rhs sr_gen_general_rhs_f
#define sr_gen_general_system sr_gen_general_system_f
#define sr_gen_general_energy sr_gen_general_energy_f
#define sr_gen_general_equilibrium_residual sr_gen_general_equilibrium_residual_f
#define sr_gen_general_accel_jacobian_terms sr_gen_general_accel_jacobian_terms_f
#define sr_gen_general_param_residual_jacobian sr_gen_general_param_residual_jacobian_f
#define sr_gen_regressor sr_gen_regressor_f
#define sr_gen_sensor_constants sr_gen_sensor_constants_f
#define sr_gen_imu_shell sr_gen_imu_shell_f
#define sr_gen_imu_shell_jacobian sr_gen_imu_shell_jacobian_f
#define sr_gen_heading_shell sr_gen_heading_shell_f
#define sr_gen_heading_shell_jacobian sr_gen_heading_shell_jacobian_f
#define sr_gen_imu_yoke sr_gen_imu_yoke_f
#define sr_gen_imu_yoke_jacobian sr_gen_imu_yoke_jacobian_f
#define sr_gen_heading_yoke sr_gen_heading_yoke_f
#define sr_gen_heading_yoke_jacobian sr_gen_heading_yoke_jacobian_f
#define sr_gen_imu_pendulum sr_gen_imu_pendulum_f
#define sr_gen_imu_pendulum_jacobian sr_gen_imu_pendulum_jacobian_f
#define sr_gen_heading_pendulum sr_gen_heading_pendulum_f
#define sr_gen_heading_pendulum_jacobian sr_gen_heading_pendulum_jacobian_f
#define sr_gen_encoders_jacobian sr_gen_encoders_jacobian_f
#define sr_gen_position_jacobian sr_gen_position_jacobian_f
#define sr_gen_contact_force sr_gen_contact_force_f
#define sr_gen_general_contact_force sr_gen_general_contact_force_f
#define sr_gen_accel_lanes sr_gen_accel_lanes_f
#define sr_gen_general_accel_jacobian_terms_lanes sr_gen_general_accel_jacobian_terms_lanes_f
#define sr_gen_regressor_lanes sr_gen_regressor_lanes_f
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
 *   c[33] k_21 = j_P + j_yy
 *   c[34] k_22 = 2*j_xx
 *   c[35] k_23 = 2*m_R*r**2
 *   c[36] k_24 = 2*j_P
 *   c[37] k_25 = l*m_P/2 */
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
/* The yoke frame's M' (upper triangle, row by row), f', ∂f'/∂(δξ', δθ_P, δν') (5 x 9, row-major), ∂f'/∂u (5 x 2) and ∂M'/∂(δξ', δθ_P) (4 upper triangles), at γ' = R_Y^T γ, ν' = diag(R_Y^T, 1, 1) ν, for the paper robot's accel Jacobian (c/src/sr_jacobians.c: g = M'⁻¹ f', ∂g = M'⁻¹(∂f' − (∂M') g), and the chain rule to the error coordinates). */
int sr_gen_accel_jacobian_yoke_terms(const sr_real c[SR_GEN_NCONST], const sr_real x[SR_GEN_NX], const sr_real u[SR_GEN_NU], sr_real M[15], sr_real f[5], sr_real df[45], sr_real dfdu[10], sr_real dM[60]);
/* The paper's robot (Section 2.3) as a general one: p[SR_P_*] from the paper's twelve parameters (derive.parameters.from_paper). */
int sr_gen_paper_params(const sr_real pp[SR_GEN_NPAPER], sr_real p[SR_GEN_NPARAM]);
/* Constants of the general kernels from the parameters, cg[0..] = (r, m_R, m_P, j_S, k_S, k_Y, k_P, h_Y_x, h_Y_y, h_Y_z, h_P_x, h_P_y, h_P_z, Jh_Y_xx, Jh_Y_yy, Jh_Y_zz, Jh_Y_xy, Jh_Y_xz, Jh_Y_yz, Jh_P_xx, Jh_P_yy, Jh_P_zz, Jh_P_xy, Jh_P_xz, Jh_P_yz, j_mY, n_Y, j_mP, n_P, g_x, g_z), then the parameter-only subexpressions of the kernels:
 *   cg[31] kg_0 = Jh_P_xx - Jh_P_zz
 *   cg[32] kg_1 = 2*h_P_y*r + 2*h_Y_y*r
 *   cg[33] kg_2 = m_R*r**2
 *   cg[34] kg_3 = 2*Jh_P_xz
 *   cg[35] kg_4 = 2*h_Y_z*r
 *   cg[36] kg_5 = 2*h_P_z*r
 *   cg[37] kg_6 = 2*h_P_x*r
 *   cg[38] kg_7 = Jh_P_yy + Jh_P_zz + Jh_Y_yy + Jh_Y_zz + j_S + j_mY
 *   cg[39] kg_8 = Jh_P_xz + Jh_Y_xz
 *   cg[40] kg_9 = h_P_y*r + h_Y_y*r
 *   cg[41] kg_10 = h_Y_x*r
 *   cg[42] kg_11 = h_Y_z*r
 *   cg[43] kg_12 = h_P_x*r
 *   cg[44] kg_13 = h_P_z*r
 *   cg[45] kg_14 = Jh_P_yy + Jh_P_zz + Jh_Y_yy + Jh_Y_zz + j_mY*n_Y
 *   cg[46] kg_15 = -Jh_P_yy + Jh_P_zz - Jh_Y_yy + Jh_Y_zz + j_mP
 *   cg[47] kg_16 = 2*Jh_Y_yz
 *   cg[48] kg_17 = 2*h_Y_x*r
 *   cg[49] kg_18 = 2*Jh_P_xy
 *   cg[50] kg_19 = 2*Jh_P_yz
 *   cg[51] kg_20 = Jh_P_xx + Jh_P_zz + Jh_Y_xx + Jh_Y_zz + j_S + j_mP + m_R*r**2
 *   cg[52] kg_21 = Jh_P_xx + Jh_P_zz + j_mP*n_P
 *   cg[53] kg_22 = Jh_P_xx + Jh_P_yy + Jh_Y_xx + Jh_Y_yy + j_S + m_R*r**2
 *   cg[54] kg_23 = Jh_P_yy + Jh_P_zz + Jh_Y_yy + Jh_Y_zz + j_mY*n_Y**2
 *   cg[55] kg_24 = Jh_P_xx + Jh_P_zz + j_mP*n_P**2
 *   cg[56] kg_25 = Jh_Y_xx + Jh_Y_zz
 *   cg[57] kg_26 = Jh_Y_xx + Jh_Y_yy
 *   cg[58] kg_27 = Jh_Y_yy + Jh_Y_zz
 *   cg[59] kg_28 = Jh_P_yy + Jh_P_zz
 *   cg[60] kg_29 = Jh_P_xx + Jh_P_yy
 *   cg[61] kg_30 = Jh_P_xx + Jh_P_zz
 *   cg[62] kg_31 = Jh_P_xx/2 + Jh_P_zz/2 + j_mP*n_P**2/2
 *   cg[63] kg_32 = Jh_P_yy/2 + Jh_P_zz/2 + Jh_Y_yy/2 + Jh_Y_zz/2 + j_S/2 + j_mY/2
 *   cg[64] kg_33 = Jh_P_xx/2 + Jh_P_zz/2 + Jh_Y_xx/2 + Jh_Y_zz/2 + j_S/2 + j_mP/2 + m_R*r**2/2
 *   cg[65] kg_34 = Jh_P_xx/2 + Jh_P_yy/2 + Jh_Y_xx/2 + Jh_Y_yy/2 + j_S/2 + m_R*r**2/2
 *   cg[66] kg_35 = Jh_P_yy/2 + Jh_P_zz/2 + Jh_Y_yy/2 + Jh_Y_zz/2 + j_mY*n_Y**2/2
 *   cg[67] kg_36 = g_x*h_P_y + g_x*h_Y_y
 *   cg[68] kg_37 = g_z*h_P_y + g_z*h_Y_y
 *   cg[69] kg_38 = g_x*h_Y_x
 *   cg[70] kg_39 = g_x*m_R
 *   cg[71] kg_40 = g_z*h_Y_x
 *   cg[72] kg_41 = g_z*m_P
 *   cg[73] kg_42 = Jh_P_xx/2 - Jh_P_zz/2
 *   cg[74] kg_43 = -Jh_P_yy/2 + Jh_P_zz/2 - Jh_Y_yy/2 + Jh_Y_zz/2 + j_mP/2
 *   cg[75] kg_44 = g_x*h_P_x
 *   cg[76] kg_45 = g_z*h_P_x
 *   cg[77] kg_46 = g_x*h_P_z
 *   cg[78] kg_47 = g_z*h_P_z
 *   cg[79] kg_48 = g_x*h_Y_z
 *   cg[80] kg_49 = g_z*h_Y_z
 *   cg[81] kg_50 = m_R*r**2/2
 *   cg[82] kg_51 = g_x*m_R*r
 *   cg[83] kg_52 = 2*Jh_P_zz + j_mP*n_P
 *   cg[84] kg_53 = -2*Jh_P_yy + 2*Jh_P_zz - 2*Jh_Y_yy + 2*Jh_Y_zz + 2*j_mP
 *   cg[85] kg_54 = 4*Jh_P_xz
 *   cg[86] kg_55 = 2*Jh_P_xx - 2*Jh_P_zz
 *   cg[87] kg_56 = 4*Jh_Y_yz
 *   cg[88] kg_57 = 4*Jh_P_xy
 *   cg[89] kg_58 = 4*Jh_P_yz
 *   cg[90] kg_59 = -Jh_P_xx + Jh_P_zz - Jh_Y_xx + Jh_Y_zz + j_mY
 *   cg[91] kg_60 = 2*Jh_P_zz + 2*Jh_Y_zz + j_mP + j_mY*n_Y
 *   cg[92] kg_61 = 2*Jh_P_xz + 2*Jh_Y_xz
 *   cg[93] kg_62 = 2*Jh_P_xx + j_mP*n_P
 *   cg[94] kg_63 = 2*Jh_Y_xy
 *   cg[95] kg_64 = Jh_P_xx - Jh_P_yy + Jh_Y_xx - Jh_Y_yy + j_mP - j_mY
 *   cg[96] kg_65 = 2*Jh_P_yy + 2*Jh_Y_yy - j_mP + j_mY*n_Y
 *   cg[97] kg_66 = -4*Jh_P_yy + 4*Jh_P_zz - 4*Jh_Y_yy + 4*Jh_Y_zz + 4*j_mP
 *   cg[98] kg_67 = 4*Jh_P_xx - 4*Jh_P_zz
 *   cg[99] kg_68 = 8*Jh_P_xz
 *   cg[100] kg_69 = 8*Jh_Y_yz
 *   cg[101] kg_70 = 8*Jh_P_xy
 *   cg[102] kg_71 = 8*Jh_P_yz
 *   cg[103] kg_72 = 2*m_R*r**2 */
int sr_gen_general_constants(const sr_real p[SR_GEN_NPARAM], sr_real cg[SR_GEN_GENERAL_NCONST]);
/* Generalized inertia M of the general robot, row-major 5x5. */
int sr_gen_general_inertia(const sr_real cg[SR_GEN_GENERAL_NCONST], const sr_real x[SR_GEN_NX], sr_real M[25]);
/* Right-hand side f of M ν̇ = f for the general robot (body by body, derive.newton_euler.general_program, proven equal to the derivation). */
int sr_gen_general_rhs(const sr_real cg[SR_GEN_GENERAL_NCONST], const sr_real x[SR_GEN_NX], const sr_real u[SR_GEN_NU], sr_real f[5]);
/* M (upper triangle, row by row) and f of the general robot, for the solve of sr_accel. */
int sr_gen_general_system(const sr_real cg[SR_GEN_GENERAL_NCONST], const sr_real x[SR_GEN_NX], const sr_real u[SR_GEN_NU], sr_real M[15], sr_real f[5]);
/* Total energy of the general robot: ½νᵀMν + m_R g_x q_x + m_P g_z q_z + the shape potential [J] (derive.lagrangian.total_energy). */
int sr_gen_general_energy(const sr_real cg[SR_GEN_GENERAL_NCONST], const sr_real x[SR_GEN_NX], sr_real E[1]);
/* f at ν = 0, u = 0 for the general robot. */
int sr_gen_general_equilibrium_residual(const sr_real cg[SR_GEN_GENERAL_NCONST], const sr_real x[SR_GEN_NX], sr_real res[5]);
/* M (upper triangle, row by row), f, ∂f/∂d (5 x SR_GEN_NE, row-major, error coordinates of SR_E_*), ∂f/∂u (5 x 2) and ∂M/∂d along δξ_S, δθ_Y, δθ_P (5 upper triangles) for the accel Jacobian ∂ν̇ = M⁻¹(∂f − (∂M) ν̇). */
int sr_gen_general_accel_jacobian_terms(const sr_real cg[SR_GEN_GENERAL_NCONST], const sr_real x[SR_GEN_NX], const sr_real u[SR_GEN_NU], sr_real M[15], sr_real f[5], sr_real df[60], sr_real dfdu[10], sr_real dM[75]);
/* ∂(M ν̇ − f)/∂p of the general robot with ν̇ held (5 x SR_GEN_NPARAM, row-major, columns SR_P_*), for ∂ν̇/∂p = −M⁻¹ ∂(M ν̇ − f)/∂p (derive.param_derivatives). */
int sr_gen_general_param_residual_jacobian(const sr_real p[SR_GEN_NPARAM], const sr_real x[SR_GEN_NX], const sr_real nud[SR_GEN_NV], sr_real dR[160]);
/* The regressor Y (5 x SR_GEN_NPI, row-major, columns SR_PI_*): M ν̇ − f(u = 0) = Y π, π the inertial parameters and dampings (derive.param_derivatives.INERTIAL_PARAMETERS). */
int sr_gen_regressor(const sr_real p[SR_GEN_NPARAM], const sr_real x[SR_GEN_NX], const sr_real nud[SR_GEN_NV], sr_real Y[135]);
/* The sensor kernels' constants sc = (r, g sin(slope), g cos(slope)) (SR_SC_*) from the parameters (derive.sensors.constant_expressions). */
int sr_gen_sensor_constants(const sr_real p[SR_GEN_NPARAM], sr_real sc[SR_GEN_NSC]);
/* IMU on the shell: y = (gyroscope R_m^T w_B + b_g, accelerometer R_m^T R_B^T (p'' - g) + b_a) in the sensor frame (SR_IMU_*), at the mount's lever arm, given nu_dot (derive.sensors.imu). */
int sr_gen_imu_shell(const sr_real sc[SR_GEN_NSC], const sr_real x[SR_GEN_NX], const sr_real nud[SR_GEN_NV], const sr_real mount[SR_GEN_NMOUNT], const sr_real bias[SR_GEN_NBIAS], sr_real y[6]);
/* IMU on the shell: y, dy/d(d, b) with nu_dot held (SR_GEN_NIMU x SR_GEN_NEB, row-major, columns SR_EB_*) and dy/d(nu_dot) (SR_GEN_NIMU x SR_GEN_NV), so that dy/dd = H + Hn Ja (derive.sensors.imu_jacobians). */
int sr_gen_imu_shell_jacobian(const sr_real sc[SR_GEN_NSC], const sr_real x[SR_GEN_NX], const sr_real nud[SR_GEN_NV], const sr_real mount[SR_GEN_NMOUNT], const sr_real bias[SR_GEN_NBIAS], sr_real y[6], sr_real H[108], sr_real Hn[30]);
/* Heading sensor on the shell: h = (h_x, h_y), the sensor's x axis R_B R_m e_x on the floor's axes; the heading is atan2(h_y, h_x) (derive.sensors.heading_vector). */
int sr_gen_heading_shell(const sr_real x[SR_GEN_NX], const sr_real mount[SR_GEN_NMOUNT], sr_real h[2]);
/* Heading sensor on the shell: h as sr_gen_heading_shell and the heading's d(atan2(h_y, h_x))/d(d, b) (1 x SR_GEN_NEB; not finite where h = 0) (derive.sensors.heading_jacobian). */
int sr_gen_heading_shell_jacobian(const sr_real x[SR_GEN_NX], const sr_real mount[SR_GEN_NMOUNT], sr_real h[2], sr_real H[18]);
/* IMU on the yoke: y = (gyroscope R_m^T w_B + b_g, accelerometer R_m^T R_B^T (p'' - g) + b_a) in the sensor frame (SR_IMU_*), at the mount's lever arm, given nu_dot (derive.sensors.imu). */
int sr_gen_imu_yoke(const sr_real sc[SR_GEN_NSC], const sr_real x[SR_GEN_NX], const sr_real nud[SR_GEN_NV], const sr_real mount[SR_GEN_NMOUNT], const sr_real bias[SR_GEN_NBIAS], sr_real y[6]);
/* IMU on the yoke: y, dy/d(d, b) with nu_dot held (SR_GEN_NIMU x SR_GEN_NEB, row-major, columns SR_EB_*) and dy/d(nu_dot) (SR_GEN_NIMU x SR_GEN_NV), so that dy/dd = H + Hn Ja (derive.sensors.imu_jacobians). */
int sr_gen_imu_yoke_jacobian(const sr_real sc[SR_GEN_NSC], const sr_real x[SR_GEN_NX], const sr_real nud[SR_GEN_NV], const sr_real mount[SR_GEN_NMOUNT], const sr_real bias[SR_GEN_NBIAS], sr_real y[6], sr_real H[108], sr_real Hn[30]);
/* Heading sensor on the yoke: h = (h_x, h_y), the sensor's x axis R_B R_m e_x on the floor's axes; the heading is atan2(h_y, h_x) (derive.sensors.heading_vector). */
int sr_gen_heading_yoke(const sr_real x[SR_GEN_NX], const sr_real mount[SR_GEN_NMOUNT], sr_real h[2]);
/* Heading sensor on the yoke: h as sr_gen_heading_yoke and the heading's d(atan2(h_y, h_x))/d(d, b) (1 x SR_GEN_NEB; not finite where h = 0) (derive.sensors.heading_jacobian). */
int sr_gen_heading_yoke_jacobian(const sr_real x[SR_GEN_NX], const sr_real mount[SR_GEN_NMOUNT], sr_real h[2], sr_real H[18]);
/* IMU on the pendulum: y = (gyroscope R_m^T w_B + b_g, accelerometer R_m^T R_B^T (p'' - g) + b_a) in the sensor frame (SR_IMU_*), at the mount's lever arm, given nu_dot (derive.sensors.imu). */
int sr_gen_imu_pendulum(const sr_real sc[SR_GEN_NSC], const sr_real x[SR_GEN_NX], const sr_real nud[SR_GEN_NV], const sr_real mount[SR_GEN_NMOUNT], const sr_real bias[SR_GEN_NBIAS], sr_real y[6]);
/* IMU on the pendulum: y, dy/d(d, b) with nu_dot held (SR_GEN_NIMU x SR_GEN_NEB, row-major, columns SR_EB_*) and dy/d(nu_dot) (SR_GEN_NIMU x SR_GEN_NV), so that dy/dd = H + Hn Ja (derive.sensors.imu_jacobians). */
int sr_gen_imu_pendulum_jacobian(const sr_real sc[SR_GEN_NSC], const sr_real x[SR_GEN_NX], const sr_real nud[SR_GEN_NV], const sr_real mount[SR_GEN_NMOUNT], const sr_real bias[SR_GEN_NBIAS], sr_real y[6], sr_real H[108], sr_real Hn[30]);
/* Heading sensor on the pendulum: h = (h_x, h_y), the sensor's x axis R_B R_m e_x on the floor's axes; the heading is atan2(h_y, h_x) (derive.sensors.heading_vector). */
int sr_gen_heading_pendulum(const sr_real x[SR_GEN_NX], const sr_real mount[SR_GEN_NMOUNT], sr_real h[2]);
/* Heading sensor on the pendulum: h as sr_gen_heading_pendulum and the heading's d(atan2(h_y, h_x))/d(d, b) (1 x SR_GEN_NEB; not finite where h = 0) (derive.sensors.heading_jacobian). */
int sr_gen_heading_pendulum_jacobian(const sr_real x[SR_GEN_NX], const sr_real mount[SR_GEN_NMOUNT], sr_real h[2], sr_real H[18]);
/* Joint encoders (theta_Y, theta_P): d/d(d, b), 2 x SR_GEN_NEB row-major (derive.sensors.encoders_jacobian). */
int sr_gen_encoders_jacobian(sr_real H[36]);
/* Position fix (q_x, q_y): d/d(d, b), 2 x SR_GEN_NEB row-major (derive.sensors.position_jacobian). */
int sr_gen_position_jacobian(sr_real H[36]);
/* Contact force F = (F_x, F_y, F_z) of the floor on the shell, plane frame (z the floor's normal) [N], from the total momentum balance F = sum m_B p''_B - m_R g at the accelerations nud (derive.contact). */
int sr_gen_contact_force(const sr_real c[SR_GEN_NCONST], const sr_real x[SR_GEN_NX], const sr_real nud[SR_GEN_NV], sr_real F[3]);
/* General robot: contact force F = (F_x, F_y, F_z) of the floor on the shell, plane frame (z the floor's normal) [N], from the total momentum balance F = sum m_B p''_B - m_R g at the accelerations nud (derive.contact). */
int sr_gen_general_contact_force(const sr_real cg[SR_GEN_GENERAL_NCONST], const sr_real x[SR_GEN_NX], const sr_real nud[SR_GEN_NV], sr_real F[3]);
/* sr_gen_accel on n states, for the batch calls: one loop without branches that the compiler vectorises across states (the same expressions, so each lane's result is the scalar kernel's, bit for bit); every output is written, and ok[i] is cleared where the scalar kernel would fail (or its outputs' sum overflows: decide such a state by the scalar kernel). GCC vectorises it at -O3 (or -O2 -fvect-cost-model=dynamic), for AVX2 too (SR_LANES_CLONES). */
void sr_gen_accel_lanes(const sr_real c[SR_GEN_NCONST], long n, const sr_real *restrict x, long x_stride, const sr_real *restrict u, long u_stride, sr_real *restrict a, long a_stride, sr_real *restrict ok);
/* sr_gen_general_accel_jacobian_terms on n states, for the batch calls: one loop without branches that the compiler vectorises across states (the same expressions, so each lane's result is the scalar kernel's, bit for bit); every output is written, and ok[i] is cleared where the scalar kernel would fail (or its outputs' sum overflows: decide such a state by the scalar kernel). GCC vectorises it at -O3 (or -O2 -fvect-cost-model=dynamic), for AVX2 too (SR_LANES_CLONES), with more run-time alias tests of its output arrays than GCC 12 makes by default (--param vect-max-version-for-alias-checks=100, in the builds). */
void sr_gen_general_accel_jacobian_terms_lanes(const sr_real cg[SR_GEN_GENERAL_NCONST], long n, const sr_real *restrict x, long x_stride, const sr_real *restrict u, long u_stride, sr_real *restrict M, long M_stride, sr_real *restrict f, long f_stride, sr_real *restrict df, long df_stride, sr_real *restrict dfdu, long dfdu_stride, sr_real *restrict dM, long dM_stride, sr_real *restrict ok);
/* sr_gen_regressor on n states, for the batch calls: one loop without branches that the compiler vectorises across states (the same expressions, so each lane's result is the scalar kernel's, bit for bit); every output is written, and ok[i] is cleared where the scalar kernel would fail (or its outputs' sum overflows: decide such a state by the scalar kernel). GCC vectorises it at -O3 (or -O2 -fvect-cost-model=dynamic), for AVX2 too (SR_LANES_CLONES). */
void sr_gen_regressor_lanes(const sr_real p[SR_GEN_NPARAM], long n, const sr_real *restrict x, long x_stride, const sr_real *restrict nud, long nud_stride, sr_real *restrict Y, long Y_stride, sr_real *restrict ok);

#endif /* SR_GENERATED_H */
