/*
 * sr_fmu.h -- what the FMI 2.0 and FMI 3.0 co-simulation wrappers (fmi2.c, fmi3.c) share: one
 * robot instance (parameters, initial conditions, stepper, state, inputs) and its variables,
 * independent of the FMI version.
 *
 * The variables (value reference -> what it is) come from sr_fmu_variables.h, which
 * runtime/interop/fmu.py writes at build time from the same tables as modelDescription.xml,
 * so that the XML and this C agree by construction.  Each entry names its kind with one of the
 * SR_FMU_* kinds below and its index with the library's own layout macros (SR_P_*, SR_X_*,
 * SR_U_*), so a layout change reaches both without an edit here.
 */
#ifndef SR_FMU_H
#define SR_FMU_H

#include <stddef.h>

#include "spherical_robot.h"

/* The kinds of variable. */
#define SR_FMU_TIME 0      /* the independent variable */
#define SR_FMU_INPUT 1     /* u[index]: a motor torque [N m] */
#define SR_FMU_PARAM 2     /* params[index]: a robot parameter (SR_P_*) */
#define SR_FMU_INIT 3      /* init[index]: an initial condition (SR_FMU_INIT_*) */
#define SR_FMU_METHOD 4    /* the stepper: a method code of sr_step (an enumeration, SR_FMU_METHODS) */
#define SR_FMU_STEP 5      /* the internal step [s] */
#define SR_FMU_STATE 6     /* x[index] (SR_X_*) */
#define SR_FMU_HEADING 7   /* heading [rad] */
#define SR_FMU_ENERGY 8    /* total energy [J] */
#define SR_FMU_CONTACT 9   /* contact force [N], index 0, 1: tangential x, y; 2: normal */

typedef struct sr_fmu_variable {
    int kind;
    int index;
} sr_fmu_variable;

#include "sr_fmu_variables.h"

/* Outcomes of the functions below; the wrappers map them to fmi2Status / fmi3Status. */
#define SR_FMU_OK 0
#define SR_FMU_ERROR 1

/* Room for one message. */
#define SR_FMU_MESSAGE 256

typedef struct sr_fmu {
    sr_real params[SR_NPARAM];
    sr_real init[SR_FMU_NINIT];
    int method;
    sr_real step;
    sr_real u[SR_NU];
    /* Valid while ready: the model of params and the state at time. */
    int ready;
    sr_model model;
    sr_real x[SR_NX];
    double time;
    char message[SR_FMU_MESSAGE];  /* the last error, for the wrapper to log */
} sr_fmu;

/* The start values of modelDescription.xml, time 0, not ready. */
void sr_fmu_reset(sr_fmu *fmu);

/* The variable of value reference vr, or NULL (message written) for an unknown one. */
const sr_fmu_variable *sr_fmu_variable_of(sr_fmu *fmu, unsigned int vr);

/* Builds the model from the parameters (sr_model_init) and the initial state at start_time from
 * the initial conditions, after checking the stepper, the step and every initial condition.
 * On failure the message names the offending variable and what is wrong with it. */
int sr_fmu_prepare(sr_fmu *fmu, double start_time);

/* Reads a real variable; outputs need sr_fmu_prepare to have succeeded. */
int sr_fmu_get_real(sr_fmu *fmu, unsigned int vr, double *value);

/* Writes a real variable.  Parameters and initial conditions only while initialising
 * (initialising != 0); they make the instance not ready.  Inputs at any time. */
int sr_fmu_set_real(sr_fmu *fmu, unsigned int vr, double value, int initialising);

/* The stepper (the one integer variable), read and written the same way. */
int sr_fmu_get_integer(sr_fmu *fmu, unsigned int vr, long *value);
int sr_fmu_set_integer(sr_fmu *fmu, unsigned int vr, long value, int initialising);

/* Advances from time t by h > 0 in ceil(h / step) equal steps of the stepper (each <= step), the
 * torques held.  t must be the instance's time.  The state is unchanged on failure. */
int sr_fmu_do_step(sr_fmu *fmu, double t, double h);

#endif /* SR_FMU_H */
