/*
 * fmi2.c -- the robot as an FMI 2.0 co-simulation FMU (over sr_fmu.h).
 *
 * The instance is one block from the environment's allocateMemory; nothing else is allocated
 * and nothing is shared between instances.  Errors are logged (always, whatever loggingOn says:
 * an error without its reason helps nobody) and leave the instance in its error state, from
 * which only fmi2Reset, fmi2Terminate and fmi2FreeInstance lead out.
 */
#include <string.h>

#include "fmi2Functions.h"
#include "sr_fmu.h"

typedef enum { INSTANTIATED, INITIALISING, STEPPING, TERMINATED, FAILED } phase;

typedef struct instance {
    sr_fmu fmu;
    fmi2CallbackFunctions callbacks;
    fmi2Boolean logging;
    phase phase;
    double start_time;
    char name[64];
} instance;

static fmi2Status report(instance *c, fmi2Status status)
{
    if (status == fmi2Error) {
        c->phase = FAILED;
        /* Formatted here: not every environment formats the logger's variadic arguments, and the
         * messages hold no '%' or '#'. */
        c->callbacks.logger(c->callbacks.componentEnvironment, c->name, fmi2Error, "logStatusError",
                            c->fmu.message);
    }
    return status;
}

static fmi2Status misuse(instance *c, const char *function)
{
    static const char *const phases[] = {"instantiated", "initialisation mode", "step mode", "terminated",
                                         "error"};
    strcpy(c->fmu.message, function);
    strncat(c->fmu.message, ": not allowed in ", SR_FMU_MESSAGE - strlen(c->fmu.message) - 1);
    strncat(c->fmu.message, phases[c->phase], SR_FMU_MESSAGE - strlen(c->fmu.message) - 1);
    return report(c, fmi2Error);
}

static int initialising(const instance *c)
{
    return c->phase == INSTANTIATED || c->phase == INITIALISING;
}

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component component, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[])
{
    instance *c = (instance *)component;
    (void)nCategories;
    (void)categories;
    if (c == NULL)
        return fmi2Error;
    c->logging = loggingOn;
    return fmi2OK;
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn)
{
    instance *c;
    const char *name = instanceName != NULL ? instanceName : "";
    (void)fmuResourceLocation;
    (void)visible;
    if (functions == NULL || functions->logger == NULL)
        return NULL;
    if (functions->allocateMemory == NULL || functions->freeMemory == NULL) {
        functions->logger(functions->componentEnvironment, name, fmi2Error, "logStatusError",
                          "fmi2Instantiate: allocateMemory and freeMemory are required");
        return NULL;
    }
    if (fmuType != fmi2CoSimulation) {
        functions->logger(functions->componentEnvironment, name, fmi2Error, "logStatusError",
                          "fmi2Instantiate: this FMU is for co-simulation only");
        return NULL;
    }
    if (fmuGUID == NULL || strcmp(fmuGUID, SR_FMU_TOKEN) != 0) {
        functions->logger(functions->componentEnvironment, name, fmi2Error, "logStatusError",
                          "fmi2Instantiate: the GUID is not this binary's " SR_FMU_TOKEN);
        return NULL;
    }
    c = (instance *)functions->allocateMemory(1, sizeof *c);
    if (c == NULL) {
        functions->logger(functions->componentEnvironment, name, fmi2Error, "logStatusError",
                          "fmi2Instantiate: out of memory");
        return NULL;
    }
    sr_fmu_reset(&c->fmu);
    c->callbacks = *functions;
    c->logging = loggingOn;
    c->phase = INSTANTIATED;
    c->start_time = 0;
    strncpy(c->name, name, sizeof c->name - 1);
    c->name[sizeof c->name - 1] = '\0';
    return c;
}

void fmi2FreeInstance(fmi2Component component)
{
    instance *c = (instance *)component;
    if (c != NULL)
        c->callbacks.freeMemory(c);
}

fmi2Status fmi2SetupExperiment(fmi2Component component, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime)
{
    instance *c = (instance *)component;
    (void)toleranceDefined;
    (void)tolerance;
    (void)stopTimeDefined;
    (void)stopTime;
    if (c == NULL)
        return fmi2Error;
    if (c->phase != INSTANTIATED)
        return misuse(c, "fmi2SetupExperiment");
    c->start_time = startTime;
    c->fmu.time = startTime;
    c->fmu.ready = 0;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component component)
{
    instance *c = (instance *)component;
    if (c == NULL)
        return fmi2Error;
    if (c->phase != INSTANTIATED)
        return misuse(c, "fmi2EnterInitializationMode");
    c->phase = INITIALISING;
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component component)
{
    instance *c = (instance *)component;
    if (c == NULL)
        return fmi2Error;
    if (c->phase != INITIALISING)
        return misuse(c, "fmi2ExitInitializationMode");
    if (!c->fmu.ready && sr_fmu_prepare(&c->fmu, c->start_time) != SR_FMU_OK)
        return report(c, fmi2Error);
    c->phase = STEPPING;
    return fmi2OK;
}

fmi2Status fmi2Terminate(fmi2Component component)
{
    instance *c = (instance *)component;
    if (c == NULL)
        return fmi2Error;
    c->phase = TERMINATED;
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component component)
{
    instance *c = (instance *)component;
    if (c == NULL)
        return fmi2Error;
    sr_fmu_reset(&c->fmu);
    c->phase = INSTANTIATED;
    c->start_time = 0;
    return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component component, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[])
{
    instance *c = (instance *)component;
    size_t i;
    if (c == NULL)
        return fmi2Error;
    if (nvr > 0 && (vr == NULL || value == NULL))
        return misuse(c, "fmi2GetReal (NULL array)");
    for (i = 0; i < nvr; ++i)
        if (sr_fmu_get_real(&c->fmu, vr[i], &value[i]) != SR_FMU_OK)
            return report(c, fmi2Error);
    return fmi2OK;
}

fmi2Status fmi2GetInteger(fmi2Component component, const fmi2ValueReference vr[], size_t nvr,
                          fmi2Integer value[])
{
    instance *c = (instance *)component;
    size_t i;
    long v;
    if (c == NULL)
        return fmi2Error;
    if (nvr > 0 && (vr == NULL || value == NULL))
        return misuse(c, "fmi2GetInteger (NULL array)");
    for (i = 0; i < nvr; ++i) {
        if (sr_fmu_get_integer(&c->fmu, vr[i], &v) != SR_FMU_OK)
            return report(c, fmi2Error);
        value[i] = (fmi2Integer)v;
    }
    return fmi2OK;
}

fmi2Status fmi2GetBoolean(fmi2Component component, const fmi2ValueReference vr[], size_t nvr,
                          fmi2Boolean value[])
{
    instance *c = (instance *)component;
    (void)vr;
    (void)value;
    if (c == NULL)
        return fmi2Error;
    return nvr == 0 ? fmi2OK : misuse(c, "fmi2GetBoolean (this FMU has no Boolean variable)");
}

fmi2Status fmi2GetString(fmi2Component component, const fmi2ValueReference vr[], size_t nvr,
                         fmi2String value[])
{
    instance *c = (instance *)component;
    (void)vr;
    (void)value;
    if (c == NULL)
        return fmi2Error;
    return nvr == 0 ? fmi2OK : misuse(c, "fmi2GetString (this FMU has no String variable)");
}

fmi2Status fmi2SetReal(fmi2Component component, const fmi2ValueReference vr[], size_t nvr,
                       const fmi2Real value[])
{
    instance *c = (instance *)component;
    size_t i;
    if (c == NULL)
        return fmi2Error;
    if (c->phase == FAILED || c->phase == TERMINATED)
        return misuse(c, "fmi2SetReal");
    if (nvr > 0 && (vr == NULL || value == NULL))
        return misuse(c, "fmi2SetReal (NULL array)");
    for (i = 0; i < nvr; ++i)
        if (sr_fmu_set_real(&c->fmu, vr[i], value[i], initialising(c)) != SR_FMU_OK)
            return report(c, fmi2Error);
    return fmi2OK;
}

fmi2Status fmi2SetInteger(fmi2Component component, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Integer value[])
{
    instance *c = (instance *)component;
    size_t i;
    if (c == NULL)
        return fmi2Error;
    if (c->phase == FAILED || c->phase == TERMINATED)
        return misuse(c, "fmi2SetInteger");
    if (nvr > 0 && (vr == NULL || value == NULL))
        return misuse(c, "fmi2SetInteger (NULL array)");
    for (i = 0; i < nvr; ++i)
        if (sr_fmu_set_integer(&c->fmu, vr[i], value[i], initialising(c)) != SR_FMU_OK)
            return report(c, fmi2Error);
    return fmi2OK;
}

fmi2Status fmi2SetBoolean(fmi2Component component, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Boolean value[])
{
    instance *c = (instance *)component;
    (void)vr;
    (void)value;
    if (c == NULL)
        return fmi2Error;
    return nvr == 0 ? fmi2OK : misuse(c, "fmi2SetBoolean (this FMU has no Boolean variable)");
}

fmi2Status fmi2SetString(fmi2Component component, const fmi2ValueReference vr[], size_t nvr,
                         const fmi2String value[])
{
    instance *c = (instance *)component;
    (void)vr;
    (void)value;
    if (c == NULL)
        return fmi2Error;
    return nvr == 0 ? fmi2OK : misuse(c, "fmi2SetString (this FMU has no String variable)");
}

/* The FMU does not offer its state (canGetAndSetFMUstate="false") nor derivatives. */
fmi2Status fmi2GetFMUstate(fmi2Component component, fmi2FMUstate *state)
{
    (void)state;
    return component == NULL ? fmi2Error : misuse((instance *)component, "fmi2GetFMUstate (not supported)");
}

fmi2Status fmi2SetFMUstate(fmi2Component component, fmi2FMUstate state)
{
    (void)state;
    return component == NULL ? fmi2Error : misuse((instance *)component, "fmi2SetFMUstate (not supported)");
}

fmi2Status fmi2FreeFMUstate(fmi2Component component, fmi2FMUstate *state)
{
    (void)state;
    return component == NULL ? fmi2Error : misuse((instance *)component, "fmi2FreeFMUstate (not supported)");
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component component, fmi2FMUstate state, size_t *size)
{
    (void)state;
    (void)size;
    return component == NULL ? fmi2Error
                             : misuse((instance *)component, "fmi2SerializedFMUstateSize (not supported)");
}

fmi2Status fmi2SerializeFMUstate(fmi2Component component, fmi2FMUstate state, fmi2Byte bytes[], size_t size)
{
    (void)state;
    (void)bytes;
    (void)size;
    return component == NULL ? fmi2Error
                             : misuse((instance *)component, "fmi2SerializeFMUstate (not supported)");
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component component, const fmi2Byte bytes[], size_t size,
                                   fmi2FMUstate *state)
{
    (void)bytes;
    (void)size;
    (void)state;
    return component == NULL ? fmi2Error
                             : misuse((instance *)component, "fmi2DeSerializeFMUstate (not supported)");
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component component, const fmi2ValueReference unknown[],
                                        size_t nUnknown, const fmi2ValueReference known[], size_t nKnown,
                                        const fmi2Real dvKnown[], fmi2Real dvUnknown[])
{
    (void)unknown;
    (void)nUnknown;
    (void)known;
    (void)nKnown;
    (void)dvKnown;
    (void)dvUnknown;
    return component == NULL ? fmi2Error
                             : misuse((instance *)component, "fmi2GetDirectionalDerivative (not supported)");
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component component, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[])
{
    (void)vr;
    (void)nvr;
    (void)order;
    (void)value;
    return component == NULL ? fmi2Error
                             : misuse((instance *)component, "fmi2SetRealInputDerivatives (not supported)");
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component component, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[])
{
    (void)vr;
    (void)nvr;
    (void)order;
    (void)value;
    return component == NULL ? fmi2Error
                             : misuse((instance *)component, "fmi2GetRealOutputDerivatives (not supported)");
}

fmi2Status fmi2DoStep(fmi2Component component, fmi2Real currentCommunicationPoint,
                      fmi2Real communicationStepSize, fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    instance *c = (instance *)component;
    (void)noSetFMUStatePriorToCurrentPoint;
    if (c == NULL)
        return fmi2Error;
    if (c->phase != STEPPING)
        return misuse(c, "fmi2DoStep");
    if (sr_fmu_do_step(&c->fmu, currentCommunicationPoint, communicationStepSize) != SR_FMU_OK)
        return report(c, fmi2Error);
    return fmi2OK;
}

fmi2Status fmi2CancelStep(fmi2Component component)
{
    return component == NULL ? fmi2Error
                             : misuse((instance *)component, "fmi2CancelStep (doStep never returns fmi2Pending)");
}

fmi2Status fmi2GetStatus(fmi2Component component, const fmi2StatusKind s, fmi2Status *value)
{
    (void)s;
    (void)value;
    return component == NULL ? fmi2Error
                             : misuse((instance *)component, "fmi2GetStatus (doStep never returns fmi2Pending)");
}

fmi2Status fmi2GetRealStatus(fmi2Component component, const fmi2StatusKind s, fmi2Real *value)
{
    instance *c = (instance *)component;
    if (c == NULL || value == NULL)
        return fmi2Error;
    if (s != fmi2LastSuccessfulTime)
        return misuse(c, "fmi2GetRealStatus (only fmi2LastSuccessfulTime)");
    *value = c->fmu.time;
    return fmi2OK;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component component, const fmi2StatusKind s, fmi2Integer *value)
{
    (void)s;
    (void)value;
    return component == NULL ? fmi2Error : misuse((instance *)component, "fmi2GetIntegerStatus (no such status)");
}

fmi2Status fmi2GetBooleanStatus(fmi2Component component, const fmi2StatusKind s, fmi2Boolean *value)
{
    instance *c = (instance *)component;
    if (c == NULL || value == NULL)
        return fmi2Error;
    if (s != fmi2Terminated)
        return misuse(c, "fmi2GetBooleanStatus (only fmi2Terminated)");
    *value = fmi2False;
    return fmi2OK;
}

fmi2Status fmi2GetStringStatus(fmi2Component component, const fmi2StatusKind s, fmi2String *value)
{
    (void)s;
    (void)value;
    return component == NULL ? fmi2Error : misuse((instance *)component, "fmi2GetStringStatus (no such status)");
}
