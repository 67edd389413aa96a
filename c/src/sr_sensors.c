/* sr_sensors.c -- the checked sensor models around the generated sr_gen_imu_* / sr_gen_heading_*
 * kernels (derive/sensors.py).  Hand-written; see sr_sensors.h for the contract of every function. */
#include "sr_sensors.h"
#include "sr_argcheck.h"
#include "sr_checks.h"
#include "sr_jacobians.h"
#include "sr_kernels.h"
#include "sr_unchecked.h"

#include <string.h>

/* The kernels per body (each body's chain of joints unrolled in its own kernel), chosen at run time
 * by direct calls: taking their addresses instead would reference the GOT in a PIC build. */
static int imu_kernel(int body, const sr_real sc[SR_GEN_NSC], const sr_real x[SR_NX], const sr_real a[SR_NV],
                      const sr_real mount[SR_NMOUNT], const sr_real bias[SR_NBIAS], sr_real y[SR_NIMU])
{
    switch (body) {
    case SR_BODY_shell: return sr_gen_imu_shell(sc, x, a, mount, bias, y);
    case SR_BODY_yoke: return sr_gen_imu_yoke(sc, x, a, mount, bias, y);
    default: return sr_gen_imu_pendulum(sc, x, a, mount, bias, y);
    }
}

static int imu_jacobian_kernel(int body, const sr_real sc[SR_GEN_NSC], const sr_real x[SR_NX], const sr_real a[SR_NV],
                               const sr_real mount[SR_NMOUNT], const sr_real bias[SR_NBIAS], sr_real y[SR_NIMU],
                               sr_real H[SR_NIMU * SR_NEB], sr_real Hn[SR_NIMU * SR_NV])
{
    switch (body) {
    case SR_BODY_shell: return sr_gen_imu_shell_jacobian(sc, x, a, mount, bias, y, H, Hn);
    case SR_BODY_yoke: return sr_gen_imu_yoke_jacobian(sc, x, a, mount, bias, y, H, Hn);
    default: return sr_gen_imu_pendulum_jacobian(sc, x, a, mount, bias, y, H, Hn);
    }
}

static int heading_kernel(int body, const sr_real x[SR_NX], const sr_real mount[SR_NMOUNT], sr_real h[2])
{
    switch (body) {
    case SR_BODY_shell: return sr_gen_heading_shell(x, mount, h);
    case SR_BODY_yoke: return sr_gen_heading_yoke(x, mount, h);
    default: return sr_gen_heading_pendulum(x, mount, h);
    }
}

static int heading_jacobian_kernel(int body, const sr_real x[SR_NX], const sr_real mount[SR_NMOUNT], sr_real h[2],
                                   sr_real H[SR_NEB])
{
    switch (body) {
    case SR_BODY_shell: return sr_gen_heading_shell_jacobian(x, mount, h, H);
    case SR_BODY_yoke: return sr_gen_heading_yoke_jacobian(x, mount, h, H);
    default: return sr_gen_heading_pendulum_jacobian(x, mount, h, H);
    }
}

static const sr_real zero_bias[SR_NBIAS] = {0, 0, 0, 0, 0, 0};

/* The kernels' constants (r, g_x, g_z) from the parameters: of every model, and of a firmware built
 * without the general kernels (-DSR_PAPER_ONLY), whose model has no general constants. */
static void sensor_constants(const sr_model *model, sr_real sc[SR_GEN_NSC])
{
    sr_gen_sensor_constants(model->p, sc);
}

int sr_check_mount(int body, const sr_real mount[SR_NMOUNT])
{
    if (!mount) return SR_ERR_NULL;
    if (body < 0 || body >= SR_NBODY) return SR_ERR_ARG;
    if (!all_finite(mount, SR_NMOUNT)) return SR_ERR_NONFINITE;
    if (!sr_internal_is_rotation(mount + SR_MOUNT_R_m)) return SR_ERR_NOT_ROTATION;
    return SR_OK;
}

/* The checks of every sensor call, in the library's order (sr_argcheck.h): the model (its read
 * sets `reads`: the state check's, and those of the kernels the call runs), the
 * pointers (outputs: nonzero when the call's outputs are all given), the body and the mount (if
 * the sensor has one), then the state. */
static int check_inputs(const sr_model *model, unsigned reads, const sr_real x[SR_NX], int outputs, int with_mount,
                        int body, const sr_real mount[SR_NMOUNT])
{
    int status = arg_model(model, reads);
    if (status != SR_OK) return status;
    if (!x || !outputs || (with_mount && !mount)) return SR_ERR_NULL;
    if (with_mount && (status = sr_check_mount(body, mount)) != SR_OK) return status;
    return sr_internal_check_state(model, x);
}

/* The IMU's checks: those of check_inputs with the mount, then the data beside the state: the n
 * entries of v (nu_dot or u; if given) and bias (NULL: zero) finite. */
static int check_imu(const sr_model *model, unsigned reads, const sr_real x[SR_NX], int outputs, const sr_real *v,
                     int n, int body, const sr_real mount[SR_NMOUNT], const sr_real **bias)
{
    const int status = check_inputs(model, reads | READS(SENSORS), x, outputs, 1, body, mount);
    if (status != SR_OK) return status;
    if (v && !all_finite(v, n)) return SR_ERR_NONFINITE;
    if (!*bias) *bias = zero_bias;
    return all_finite(*bias, SR_NBIAS) ? SR_OK : SR_ERR_NONFINITE;
}

int sr_imu_measure(const sr_model *model, const sr_real x[SR_NX], const sr_real nu_dot[SR_NV], int body,
                   const sr_real mount[SR_NMOUNT], const sr_real bias[SR_NBIAS], sr_real y[SR_NIMU])
{
    sr_real sc[SR_GEN_NSC];
    const int status = check_imu(model, READS(STATE), x, nu_dot && y, nu_dot, SR_NV, body, mount, &bias);
    if (status != SR_OK) return status;
    sensor_constants(model, sc);
    return imu_kernel(body, sc, x, nu_dot, mount, bias, y);
}

int sr_imu_measure_u(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], int body,
                     const sr_real mount[SR_NMOUNT], const sr_real bias[SR_NBIAS], sr_real y[SR_NIMU])
{
    sr_real a[SR_NV], sc[SR_GEN_NSC];
    int status = check_imu(model, READS(STATE) | READS(ACCEL), x, y != NULL, u, SR_NU, body, mount, &bias);
    if (status == SR_OK) status = sr_internal_accel(model, x, u ? u : sr_zero_u, a);
    if (status != SR_OK) return status;
    sensor_constants(model, sc);
    return imu_kernel(body, sc, x, a, mount, bias, y);
}

int sr_imu_partials(const sr_model *model, const sr_real x[SR_NX], const sr_real nu_dot[SR_NV], int body,
                    const sr_real mount[SR_NMOUNT], const sr_real bias[SR_NBIAS], sr_real y[SR_NIMU],
                    sr_real H[SR_NIMU * SR_NEB], sr_real Hn[SR_NIMU * SR_NV])
{
    sr_real sc[SR_GEN_NSC];
    const int status = check_imu(model, READS(STATE), x, nu_dot && y && H && Hn, nu_dot, SR_NV, body, mount, &bias);
    if (status != SR_OK) return status;
    sensor_constants(model, sc);
    return imu_jacobian_kernel(body, sc, x, nu_dot, mount, bias, y, H, Hn);
}

int sr_imu_jacobian(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], int body,
                    const sr_real mount[SR_NMOUNT], const sr_real bias[SR_NBIAS], sr_real y[SR_NIMU],
                    sr_real H[SR_NIMU * SR_NEB])
{
    const int status = check_imu(model, READS(STATE) | READS(JACOBIAN), x, y && H, u, SR_NU, body, mount, &bias);
    if (status != SR_OK) return status;
    return sr_internal_imu_jacobian(model, x, u, body, mount, bias, y, H);
}

/* SR_LANES_CLONES: with -DSR_CLONES also compiled for AVX2 (the same bits: no FMA, no
 * contraction), the accelerometer's chain rule four columns a vector (the filter's IMU update). */
SR_LANES_CLONES int sr_internal_imu_jacobian_minv(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                                                  int body, const sr_real mount[SR_NMOUNT], const sr_real bias[SR_NBIAS],
                                                  sr_real y[SR_NIMU], sr_real H[SR_NIMU * SR_NEB], sr_real *Hn_out,
                                                  sr_real *Minv)
{
    sr_real a[SR_NV], sc[SR_GEN_NSC], Ja[SR_NV * SR_NE], Jb[SR_NV * SR_NU], yy[SR_NIMU], HH[SR_NIMU * SR_NEB], Hn[SR_NIMU * SR_NV];
    sr_real Mi[SR_NV * SR_NV];
    int status, i, j, k;
    status = sr_internal_accel_jacobian_minv(model, x, u ? u : sr_zero_u, a, Ja, Jb, Minv ? Mi : NULL);
    if (status != SR_OK) return status;
    if (!all_finite(a, SR_NV) || !all_finite(Ja, SR_NV * SR_NE)) return SR_ERR_NONFINITE;
    sensor_constants(model, sc);
    status = imu_jacobian_kernel(body, sc, x, a, mount, bias ? bias : zero_bias, yy, HH, Hn);
    if (status != SR_OK) return status;
    /* Only the accelerometer reads nu_dot (the gyroscope's rows of Hn are zero by derivation). */
    for (i = SR_IMU_accel; i < SR_IMU_accel + 3; ++i)
        for (k = 0; k < SR_NV; ++k) {
            const sr_real h = Hn[SR_NV * i + k];
            for (j = 0; j < SR_NE; ++j) HH[SR_NEB * i + j] += h * Ja[SR_NE * k + j];
        }
    if (!all_finite(HH, SR_NIMU * SR_NEB)) return SR_ERR_NONFINITE;
    memcpy(y, yy, sizeof yy);
    memcpy(H, HH, sizeof HH);
    if (Hn_out) memcpy(Hn_out, Hn, sizeof Hn);
    if (Minv) memcpy(Minv, Mi, sizeof Mi);
    return SR_OK;
}

int sr_internal_imu_jacobian(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], int body,
                             const sr_real mount[SR_NMOUNT], const sr_real bias[SR_NBIAS], sr_real y[SR_NIMU],
                             sr_real H[SR_NIMU * SR_NEB])
{
    return sr_internal_imu_jacobian_minv(model, x, u, body, mount, bias, y, H, NULL, NULL);
}

int sr_imu_partials_batch(const sr_model *model, long n, const sr_real *x, const sr_real *nu_dot, int body,
                          const sr_real mount[SR_NMOUNT], const sr_real bias[SR_NBIAS], sr_real *y, sr_real *H,
                          sr_real *Hn, long *failed_row)
{
    long i;
    int status = arg_model(model, READS(STATE) | READS(SENSORS));
    if (failed_row) *failed_row = -1;
    if (status == SR_OK) status = arg_rows(n, x && nu_dot && y && H && Hn);
    if (status != SR_OK) return status;
    for (i = 0; i < n; ++i) {
        status = sr_imu_partials(model, x + i * SR_NX, nu_dot + i * SR_NV, body, mount, bias, y + i * SR_NIMU,
                                 H + i * SR_NIMU * SR_NEB, Hn + i * SR_NIMU * SR_NV);
        if (status != SR_OK) {
            if (failed_row) *failed_row = i;
            return status;
        }
    }
    return SR_OK;
}

/* R_Y = rot_x(theta_Y): (cos, sin) in its (1,1), (2,1) entries; R_P = rot_y(theta_P): (0,0), (0,2). */
static void encoder_angles(const sr_real x[SR_NX], sr_real y[2])
{
    y[0] = SR_ATAN2(x[SR_X_R_Y + 7], x[SR_X_R_Y + 4]);
    y[1] = SR_ATAN2(x[SR_X_R_P + 2], x[SR_X_R_P + 0]);
}

int sr_encoders_measure(const sr_model *model, const sr_real x[SR_NX], sr_real y[2])
{
    const int status = check_inputs(model, READS(STATE), x, y != NULL, 0, 0, NULL);
    if (status != SR_OK) return status;
    encoder_angles(x, y);
    return SR_OK;
}

int sr_encoders_jacobian(const sr_model *model, const sr_real x[SR_NX], sr_real y[2], sr_real H[2 * SR_NEB])
{
    const int status = check_inputs(model, READS(STATE), x, y && H, 0, 0, NULL);
    if (status != SR_OK) return status;
    sr_internal_encoders_jacobian(x, y, H);
    return SR_OK;
}

void sr_internal_encoders_jacobian(const sr_real x[SR_NX], sr_real y[2], sr_real H[2 * SR_NEB])
{
    sr_gen_encoders_jacobian(H);
    encoder_angles(x, y);
}

int sr_position_measure(const sr_model *model, const sr_real x[SR_NX], sr_real y[2])
{
    const int status = check_inputs(model, READS(STATE), x, y != NULL, 0, 0, NULL);
    if (status != SR_OK) return status;
    y[0] = x[SR_X_q + 0];
    y[1] = x[SR_X_q + 1];
    return SR_OK;
}

int sr_position_jacobian(const sr_model *model, const sr_real x[SR_NX], sr_real y[2], sr_real H[2 * SR_NEB])
{
    const int status = check_inputs(model, READS(STATE), x, y && H, 0, 0, NULL);
    if (status != SR_OK) return status;
    sr_gen_position_jacobian(H);
    y[0] = x[SR_X_q + 0];
    y[1] = x[SR_X_q + 1];
    return SR_OK;
}

/* The floor's components of the sensor's x axis, refused where the heading is undefined. */
static int heading_vector(const sr_model *model, const sr_real x[SR_NX], int outputs, int body,
                          const sr_real mount[SR_NMOUNT], sr_real h[2])
{
    int status = check_inputs(model, READS(STATE), x, outputs, 1, body, mount);
    if (status == SR_OK) status = heading_kernel(body, x, mount, h);
    if (status != SR_OK) return status;
    if (h[0] * h[0] + h[1] * h[1] < SR_HEADING_MIN_HORIZONTAL * SR_HEADING_MIN_HORIZONTAL) return SR_ERR_SINGULAR;
    return SR_OK;
}

int sr_heading_measure(const sr_model *model, const sr_real x[SR_NX], int body, const sr_real mount[SR_NMOUNT],
                       sr_real *heading)
{
    sr_real h[2];
    const int status = heading_vector(model, x, heading != NULL, body, mount, h);
    if (status != SR_OK) return status;
    *heading = SR_ATAN2(h[1], h[0]);
    return SR_OK;
}

int sr_heading_jacobian(const sr_model *model, const sr_real x[SR_NX], int body, const sr_real mount[SR_NMOUNT],
                        sr_real *heading, sr_real H[SR_NEB])
{
    sr_real h[2], HH[SR_NEB];
    int status = heading_vector(model, x, heading && H, body, mount, h);
    if (status == SR_OK) status = heading_jacobian_kernel(body, x, mount, h, HH);
    if (status != SR_OK) return status;
    *heading = SR_ATAN2(h[1], h[0]);
    memcpy(H, HH, sizeof HH);
    return SR_OK;
}

/* The encoders' and the position fix's batches share the row loop (position: nonzero for the fix);
 * the call is chosen per row by a direct call, as the kernels above are. */
static int pair_batch(int position, const sr_model *model, long n, const sr_real *x, sr_real *y, sr_real *H,
                      long *failed_row)
{
    long i;
    int status = arg_model(model, READS(STATE));
    if (failed_row) *failed_row = -1;
    if (status == SR_OK) status = arg_rows(n, x && y && H);
    if (status != SR_OK) return status;
    for (i = 0; i < n; ++i) {
        status = position ? sr_position_jacobian(model, x + i * SR_NX, y + 2 * i, H + 2 * i * SR_NEB)
                          : sr_encoders_jacobian(model, x + i * SR_NX, y + 2 * i, H + 2 * i * SR_NEB);
        if (status != SR_OK) {
            if (failed_row) *failed_row = i;
            return status;
        }
    }
    return SR_OK;
}

int sr_encoders_jacobian_batch(const sr_model *model, long n, const sr_real *x, sr_real *y, sr_real *H,
                               long *failed_row)
{
    return pair_batch(0, model, n, x, y, H, failed_row);
}

int sr_position_jacobian_batch(const sr_model *model, long n, const sr_real *x, sr_real *y, sr_real *H,
                               long *failed_row)
{
    return pair_batch(1, model, n, x, y, H, failed_row);
}
