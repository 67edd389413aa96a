/*
 * fmi3.c -- the robot as an FMI 3.0 co-simulation FMU (over sr_fmu.h).
 *
 * FMI 3 gives the FMU no allocator: the instance is one calloc'd block, freed by
 * fmi3FreeInstance; nothing else is allocated and nothing is shared between instances.  Errors
 * are logged (whatever loggingOn says) and leave the instance in its error state, from which
 * only fmi3Reset, fmi3Terminate and fmi3FreeInstance lead out.  No event mode, no clocks, no
 * early return: every interface of FMI 3 that the FMU does not offer answers fmi3Error.
 */
#include <stdlib.h>
#include <string.h>

#include "fmi3Functions.h"
#include "sr_fmu.h"

typedef enum { INSTANTIATED, INITIALISING, STEPPING, TERMINATED, FAILED } phase;

typedef struct instance {
    sr_fmu fmu;
    fmi3InstanceEnvironment environment;
    fmi3LogMessageCallback log;
    fmi3Boolean logging;
    phase phase;
} instance;

static fmi3Status report(instance *c, fmi3Status status)
{
    if (status == fmi3Error) {
        c->phase = FAILED;
        if (c->log != NULL)
            c->log(c->environment, fmi3Error, "logStatusError", c->fmu.message);
    }
    return status;
}

static fmi3Status misuse(fmi3Instance component, const char *function, const char *why)
{
    static const char *const phases[] = {"instantiated", "initialisation mode", "step mode", "terminated",
                                         "error"};
    instance *c = (instance *)component;
    if (c == NULL)
        return fmi3Error;
    strncpy(c->fmu.message, function, SR_FMU_MESSAGE - 1);
    c->fmu.message[SR_FMU_MESSAGE - 1] = '\0';
    strncat(c->fmu.message, ": ", SR_FMU_MESSAGE - strlen(c->fmu.message) - 1);
    strncat(c->fmu.message, why != NULL ? why : "not allowed in ", SR_FMU_MESSAGE - strlen(c->fmu.message) - 1);
    if (why == NULL)
        strncat(c->fmu.message, phases[c->phase], SR_FMU_MESSAGE - strlen(c->fmu.message) - 1);
    return report(c, fmi3Error);
}

#define NOT_OFFERED(component, function) misuse(component, function, "not offered by this FMU")

static int initialising(const instance *c)
{
    return c->phase == INSTANTIATED || c->phase == INITIALISING;
}

const char *fmi3GetVersion(void) { return fmi3Version; }

fmi3Status fmi3SetDebugLogging(fmi3Instance component, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[])
{
    instance *c = (instance *)component;
    (void)nCategories;
    (void)categories;
    if (c == NULL)
        return fmi3Error;
    c->logging = loggingOn;
    return fmi3OK;
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                          fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment instanceEnvironment,
                                          fmi3LogMessageCallback logMessage)
{
    (void)instanceName;
    (void)instantiationToken;
    (void)resourcePath;
    (void)visible;
    (void)loggingOn;
    if (logMessage != NULL)
        logMessage(instanceEnvironment, fmi3Error, "logStatusError",
                   "fmi3InstantiateModelExchange: this FMU is for co-simulation only");
    return NULL;
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
                                         fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                         fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
                                         const fmi3ValueReference requiredIntermediateVariables[],
                                         size_t nRequiredIntermediateVariables,
                                         fmi3InstanceEnvironment instanceEnvironment,
                                         fmi3LogMessageCallback logMessage,
                                         fmi3IntermediateUpdateCallback intermediateUpdate)
{
    instance *c;
    (void)instanceName;
    (void)resourcePath;
    (void)visible;
    (void)eventModeUsed;
    (void)earlyReturnAllowed;
    (void)requiredIntermediateVariables;
    (void)intermediateUpdate;
    if (instantiationToken == NULL || strcmp(instantiationToken, SR_FMU_TOKEN) != 0) {
        if (logMessage != NULL)
            logMessage(instanceEnvironment, fmi3Error, "logStatusError",
                       "fmi3InstantiateCoSimulation: the instantiation token is not this binary's " SR_FMU_TOKEN);
        return NULL;
    }
    if (nRequiredIntermediateVariables > 0) {
        if (logMessage != NULL)
            logMessage(instanceEnvironment, fmi3Error, "logStatusError",
                       "fmi3InstantiateCoSimulation: this FMU has no intermediate update");
        return NULL;
    }
    c = (instance *)calloc(1, sizeof *c);
    if (c == NULL) {
        if (logMessage != NULL)
            logMessage(instanceEnvironment, fmi3Error, "logStatusError", "fmi3InstantiateCoSimulation: out of memory");
        return NULL;
    }
    sr_fmu_reset(&c->fmu);
    c->environment = instanceEnvironment;
    c->log = logMessage;
    c->logging = loggingOn;
    c->phase = INSTANTIATED;
    return c;
}

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String instanceName, fmi3String instantiationToken,
                                               fmi3String resourcePath, fmi3Boolean visible,
                                               fmi3Boolean loggingOn, fmi3InstanceEnvironment instanceEnvironment,
                                               fmi3LogMessageCallback logMessage, fmi3ClockUpdateCallback clockUpdate,
                                               fmi3LockPreemptionCallback lockPreemption,
                                               fmi3UnlockPreemptionCallback unlockPreemption)
{
    (void)instanceName;
    (void)instantiationToken;
    (void)resourcePath;
    (void)visible;
    (void)loggingOn;
    (void)clockUpdate;
    (void)lockPreemption;
    (void)unlockPreemption;
    if (logMessage != NULL)
        logMessage(instanceEnvironment, fmi3Error, "logStatusError",
                   "fmi3InstantiateScheduledExecution: this FMU is for co-simulation only");
    return NULL;
}

void fmi3FreeInstance(fmi3Instance component)
{
    free(component);
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance component, fmi3Boolean toleranceDefined, fmi3Float64 tolerance,
                                       fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime)
{
    instance *c = (instance *)component;
    (void)toleranceDefined;
    (void)tolerance;
    (void)stopTimeDefined;
    (void)stopTime;
    if (c == NULL)
        return fmi3Error;
    if (c->phase != INSTANTIATED)
        return misuse(c, "fmi3EnterInitializationMode", NULL);
    c->fmu.time = startTime;
    c->fmu.ready = 0;
    c->phase = INITIALISING;
    return fmi3OK;
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance component)
{
    instance *c = (instance *)component;
    if (c == NULL)
        return fmi3Error;
    if (c->phase != INITIALISING)
        return misuse(c, "fmi3ExitInitializationMode", NULL);
    if (!c->fmu.ready && sr_fmu_prepare(&c->fmu, c->fmu.time) != SR_FMU_OK)
        return report(c, fmi3Error);
    c->phase = STEPPING;
    return fmi3OK;
}

fmi3Status fmi3EnterEventMode(fmi3Instance component)
{
    return NOT_OFFERED(component, "fmi3EnterEventMode");
}

fmi3Status fmi3Terminate(fmi3Instance component)
{
    instance *c = (instance *)component;
    if (c == NULL)
        return fmi3Error;
    c->phase = TERMINATED;
    return fmi3OK;
}

fmi3Status fmi3Reset(fmi3Instance component)
{
    instance *c = (instance *)component;
    if (c == NULL)
        return fmi3Error;
    sr_fmu_reset(&c->fmu);
    c->phase = INSTANTIATED;
    return fmi3OK;
}

static fmi3Status arrays(instance *c, const char *function, size_t nvr, size_t nValues, int null)
{
    if (nvr != nValues)
        return misuse(c, function, "nValues differs from nValueReferences (the FMU has scalars only)");
    if (nvr > 0 && null)
        return misuse(c, function, "NULL array");
    return fmi3OK;
}

fmi3Status fmi3GetFloat64(fmi3Instance component, const fmi3ValueReference vr[], size_t nvr,
                          fmi3Float64 values[], size_t nValues)
{
    instance *c = (instance *)component;
    size_t i;
    if (c == NULL)
        return fmi3Error;
    if (arrays(c, "fmi3GetFloat64", nvr, nValues, vr == NULL || values == NULL) != fmi3OK)
        return fmi3Error;
    for (i = 0; i < nvr; ++i)
        if (sr_fmu_get_real(&c->fmu, vr[i], &values[i]) != SR_FMU_OK)
            return report(c, fmi3Error);
    return fmi3OK;
}

fmi3Status fmi3SetFloat64(fmi3Instance component, const fmi3ValueReference vr[], size_t nvr,
                          const fmi3Float64 values[], size_t nValues)
{
    instance *c = (instance *)component;
    size_t i;
    if (c == NULL)
        return fmi3Error;
    if (c->phase == FAILED || c->phase == TERMINATED)
        return misuse(c, "fmi3SetFloat64", NULL);
    if (arrays(c, "fmi3SetFloat64", nvr, nValues, vr == NULL || values == NULL) != fmi3OK)
        return fmi3Error;
    for (i = 0; i < nvr; ++i)
        if (sr_fmu_set_real(&c->fmu, vr[i], values[i], initialising(c)) != SR_FMU_OK)
            return report(c, fmi3Error);
    return fmi3OK;
}

/* The stepper is an enumeration, which FMI 3 reads and writes as Int64. */
fmi3Status fmi3GetInt64(fmi3Instance component, const fmi3ValueReference vr[], size_t nvr,
                        fmi3Int64 values[], size_t nValues)
{
    instance *c = (instance *)component;
    size_t i;
    long v;
    if (c == NULL)
        return fmi3Error;
    if (arrays(c, "fmi3GetInt64", nvr, nValues, vr == NULL || values == NULL) != fmi3OK)
        return fmi3Error;
    for (i = 0; i < nvr; ++i) {
        if (sr_fmu_get_integer(&c->fmu, vr[i], &v) != SR_FMU_OK)
            return report(c, fmi3Error);
        values[i] = (fmi3Int64)v;
    }
    return fmi3OK;
}

fmi3Status fmi3SetInt64(fmi3Instance component, const fmi3ValueReference vr[], size_t nvr,
                        const fmi3Int64 values[], size_t nValues)
{
    instance *c = (instance *)component;
    size_t i;
    if (c == NULL)
        return fmi3Error;
    if (c->phase == FAILED || c->phase == TERMINATED)
        return misuse(c, "fmi3SetInt64", NULL);
    if (arrays(c, "fmi3SetInt64", nvr, nValues, vr == NULL || values == NULL) != fmi3OK)
        return fmi3Error;
    for (i = 0; i < nvr; ++i) {
        long value = values[i] < -2147483647 ? -2147483647 : values[i] > 2147483647 ? 2147483647 : (long)values[i];
        if (sr_fmu_set_integer(&c->fmu, vr[i], value, initialising(c)) != SR_FMU_OK)
            return report(c, fmi3Error);
    }
    return fmi3OK;
}

/* The types of which the FMU has no variable: an empty call succeeds, any other is an error. */
#define NO_VARIABLES_GET(function, type)                                                              \
    fmi3Status function(fmi3Instance component, const fmi3ValueReference vr[], size_t nvr, type values[], \
                        size_t nValues)                                                               \
    {                                                                                                 \
        (void)vr;                                                                                     \
        (void)values;                                                                                 \
        (void)nValues;                                                                                \
        if (component == NULL)                                                                        \
            return fmi3Error;                                                                         \
        return nvr == 0 ? fmi3OK : misuse(component, #function, "the FMU has no variable of this type"); \
    }
#define NO_VARIABLES_SET(function, type) NO_VARIABLES_GET(function, const type)

NO_VARIABLES_GET(fmi3GetFloat32, fmi3Float32)
NO_VARIABLES_GET(fmi3GetInt8, fmi3Int8)
NO_VARIABLES_GET(fmi3GetUInt8, fmi3UInt8)
NO_VARIABLES_GET(fmi3GetInt16, fmi3Int16)
NO_VARIABLES_GET(fmi3GetUInt16, fmi3UInt16)
NO_VARIABLES_GET(fmi3GetInt32, fmi3Int32)
NO_VARIABLES_GET(fmi3GetUInt32, fmi3UInt32)
NO_VARIABLES_GET(fmi3GetUInt64, fmi3UInt64)
NO_VARIABLES_GET(fmi3GetBoolean, fmi3Boolean)
NO_VARIABLES_GET(fmi3GetString, fmi3String)
NO_VARIABLES_SET(fmi3SetFloat32, fmi3Float32)
NO_VARIABLES_SET(fmi3SetInt8, fmi3Int8)
NO_VARIABLES_SET(fmi3SetUInt8, fmi3UInt8)
NO_VARIABLES_SET(fmi3SetInt16, fmi3Int16)
NO_VARIABLES_SET(fmi3SetUInt16, fmi3UInt16)
NO_VARIABLES_SET(fmi3SetInt32, fmi3Int32)
NO_VARIABLES_SET(fmi3SetUInt32, fmi3UInt32)
NO_VARIABLES_SET(fmi3SetUInt64, fmi3UInt64)
NO_VARIABLES_SET(fmi3SetBoolean, fmi3Boolean)
NO_VARIABLES_SET(fmi3SetString, fmi3String)

fmi3Status fmi3GetBinary(fmi3Instance component, const fmi3ValueReference vr[], size_t nvr, size_t valueSizes[],
                         fmi3Binary values[], size_t nValues)
{
    (void)vr;
    (void)valueSizes;
    (void)values;
    (void)nValues;
    return nvr == 0 && component != NULL ? fmi3OK : NOT_OFFERED(component, "fmi3GetBinary");
}

fmi3Status fmi3SetBinary(fmi3Instance component, const fmi3ValueReference vr[], size_t nvr,
                         const size_t valueSizes[], const fmi3Binary values[], size_t nValues)
{
    (void)vr;
    (void)valueSizes;
    (void)values;
    (void)nValues;
    return nvr == 0 && component != NULL ? fmi3OK : NOT_OFFERED(component, "fmi3SetBinary");
}

fmi3Status fmi3GetClock(fmi3Instance component, const fmi3ValueReference vr[], size_t nvr, fmi3Clock values[])
{
    (void)vr;
    (void)values;
    return nvr == 0 && component != NULL ? fmi3OK : NOT_OFFERED(component, "fmi3GetClock");
}

fmi3Status fmi3SetClock(fmi3Instance component, const fmi3ValueReference vr[], size_t nvr,
                        const fmi3Clock values[])
{
    (void)vr;
    (void)values;
    return nvr == 0 && component != NULL ? fmi3OK : NOT_OFFERED(component, "fmi3SetClock");
}

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance component, fmi3ValueReference vr, size_t *n)
{
    (void)vr;
    (void)n;
    return NOT_OFFERED(component, "fmi3GetNumberOfVariableDependencies");
}

fmi3Status fmi3GetVariableDependencies(fmi3Instance component, fmi3ValueReference dependent,
                                       size_t elementIndicesOfDependent[], fmi3ValueReference independents[],
                                       size_t elementIndicesOfIndependents[], fmi3DependencyKind dependencyKinds[],
                                       size_t nDependencies)
{
    (void)dependent;
    (void)elementIndicesOfDependent;
    (void)independents;
    (void)elementIndicesOfIndependents;
    (void)dependencyKinds;
    (void)nDependencies;
    return NOT_OFFERED(component, "fmi3GetVariableDependencies");
}

fmi3Status fmi3GetFMUState(fmi3Instance component, fmi3FMUState *state)
{
    (void)state;
    return NOT_OFFERED(component, "fmi3GetFMUState");
}

fmi3Status fmi3SetFMUState(fmi3Instance component, fmi3FMUState state)
{
    (void)state;
    return NOT_OFFERED(component, "fmi3SetFMUState");
}

fmi3Status fmi3FreeFMUState(fmi3Instance component, fmi3FMUState *state)
{
    (void)state;
    return NOT_OFFERED(component, "fmi3FreeFMUState");
}

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance component, fmi3FMUState state, size_t *size)
{
    (void)state;
    (void)size;
    return NOT_OFFERED(component, "fmi3SerializedFMUStateSize");
}

fmi3Status fmi3SerializeFMUState(fmi3Instance component, fmi3FMUState state, fmi3Byte serialized[], size_t size)
{
    (void)state;
    (void)serialized;
    (void)size;
    return NOT_OFFERED(component, "fmi3SerializeFMUState");
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance component, const fmi3Byte serialized[], size_t size,
                                   fmi3FMUState *state)
{
    (void)serialized;
    (void)size;
    (void)state;
    return NOT_OFFERED(component, "fmi3DeserializeFMUState");
}

fmi3Status fmi3GetDirectionalDerivative(fmi3Instance component, const fmi3ValueReference unknowns[],
                                        size_t nUnknowns, const fmi3ValueReference knowns[], size_t nKnowns,
                                        const fmi3Float64 seed[], size_t nSeed, fmi3Float64 sensitivity[],
                                        size_t nSensitivity)
{
    (void)unknowns;
    (void)nUnknowns;
    (void)knowns;
    (void)nKnowns;
    (void)seed;
    (void)nSeed;
    (void)sensitivity;
    (void)nSensitivity;
    return NOT_OFFERED(component, "fmi3GetDirectionalDerivative");
}

fmi3Status fmi3GetAdjointDerivative(fmi3Instance component, const fmi3ValueReference unknowns[],
                                    size_t nUnknowns, const fmi3ValueReference knowns[], size_t nKnowns,
                                    const fmi3Float64 seed[], size_t nSeed, fmi3Float64 sensitivity[],
                                    size_t nSensitivity)
{
    (void)unknowns;
    (void)nUnknowns;
    (void)knowns;
    (void)nKnowns;
    (void)seed;
    (void)nSeed;
    (void)sensitivity;
    (void)nSensitivity;
    return NOT_OFFERED(component, "fmi3GetAdjointDerivative");
}

fmi3Status fmi3EnterConfigurationMode(fmi3Instance component)
{
    return NOT_OFFERED(component, "fmi3EnterConfigurationMode");
}

fmi3Status fmi3ExitConfigurationMode(fmi3Instance component)
{
    return NOT_OFFERED(component, "fmi3ExitConfigurationMode");
}

fmi3Status fmi3GetIntervalDecimal(fmi3Instance component, const fmi3ValueReference vr[], size_t nvr,
                                  fmi3Float64 intervals[], fmi3IntervalQualifier qualifiers[])
{
    (void)vr;
    (void)nvr;
    (void)intervals;
    (void)qualifiers;
    return NOT_OFFERED(component, "fmi3GetIntervalDecimal");
}

fmi3Status fmi3GetIntervalFraction(fmi3Instance component, const fmi3ValueReference vr[], size_t nvr,
                                   fmi3UInt64 counters[], fmi3UInt64 resolutions[],
                                   fmi3IntervalQualifier qualifiers[])
{
    (void)vr;
    (void)nvr;
    (void)counters;
    (void)resolutions;
    (void)qualifiers;
    return NOT_OFFERED(component, "fmi3GetIntervalFraction");
}

fmi3Status fmi3GetShiftDecimal(fmi3Instance component, const fmi3ValueReference vr[], size_t nvr,
                               fmi3Float64 shifts[])
{
    (void)vr;
    (void)nvr;
    (void)shifts;
    return NOT_OFFERED(component, "fmi3GetShiftDecimal");
}

fmi3Status fmi3GetShiftFraction(fmi3Instance component, const fmi3ValueReference vr[], size_t nvr,
                                fmi3UInt64 counters[], fmi3UInt64 resolutions[])
{
    (void)vr;
    (void)nvr;
    (void)counters;
    (void)resolutions;
    return NOT_OFFERED(component, "fmi3GetShiftFraction");
}

fmi3Status fmi3SetIntervalDecimal(fmi3Instance component, const fmi3ValueReference vr[], size_t nvr,
                                  const fmi3Float64 intervals[])
{
    (void)vr;
    (void)nvr;
    (void)intervals;
    return NOT_OFFERED(component, "fmi3SetIntervalDecimal");
}

fmi3Status fmi3SetIntervalFraction(fmi3Instance component, const fmi3ValueReference vr[], size_t nvr,
                                   const fmi3UInt64 counters[], const fmi3UInt64 resolutions[])
{
    (void)vr;
    (void)nvr;
    (void)counters;
    (void)resolutions;
    return NOT_OFFERED(component, "fmi3SetIntervalFraction");
}

fmi3Status fmi3SetShiftDecimal(fmi3Instance component, const fmi3ValueReference vr[], size_t nvr,
                               const fmi3Float64 shifts[])
{
    (void)vr;
    (void)nvr;
    (void)shifts;
    return NOT_OFFERED(component, "fmi3SetShiftDecimal");
}

fmi3Status fmi3SetShiftFraction(fmi3Instance component, const fmi3ValueReference vr[], size_t nvr,
                                const fmi3UInt64 counters[], const fmi3UInt64 resolutions[])
{
    (void)vr;
    (void)nvr;
    (void)counters;
    (void)resolutions;
    return NOT_OFFERED(component, "fmi3SetShiftFraction");
}

fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance component)
{
    return NOT_OFFERED(component, "fmi3EvaluateDiscreteStates");
}

fmi3Status fmi3UpdateDiscreteStates(fmi3Instance component, fmi3Boolean *discreteStatesNeedUpdate,
                                    fmi3Boolean *terminateSimulation, fmi3Boolean *nominalsChanged,
                                    fmi3Boolean *valuesChanged, fmi3Boolean *nextEventTimeDefined,
                                    fmi3Float64 *nextEventTime)
{
    (void)discreteStatesNeedUpdate;
    (void)terminateSimulation;
    (void)nominalsChanged;
    (void)valuesChanged;
    (void)nextEventTimeDefined;
    (void)nextEventTime;
    return NOT_OFFERED(component, "fmi3UpdateDiscreteStates");
}

fmi3Status fmi3EnterStepMode(fmi3Instance component)
{
    return NOT_OFFERED(component, "fmi3EnterStepMode");
}

fmi3Status fmi3GetOutputDerivatives(fmi3Instance component, const fmi3ValueReference vr[], size_t nvr,
                                    const fmi3Int32 orders[], fmi3Float64 values[], size_t nValues)
{
    (void)vr;
    (void)nvr;
    (void)orders;
    (void)values;
    (void)nValues;
    return NOT_OFFERED(component, "fmi3GetOutputDerivatives");
}

/* Model exchange and scheduled execution: the FMU offers neither (its instantiation functions
 * refuse), but the standard's loaders bind every function of the header. */
fmi3Status fmi3ActivateModelPartition(fmi3Instance component, fmi3ValueReference clockReference,
                                      fmi3Float64 activationTime)
{
    (void)clockReference;
    (void)activationTime;
    return NOT_OFFERED(component, "fmi3ActivateModelPartition");
}

fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance component)
{
    return NOT_OFFERED(component, "fmi3EnterContinuousTimeMode");
}

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance component, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi3Boolean *enterEventMode, fmi3Boolean *terminateSimulation)
{
    (void)noSetFMUStatePriorToCurrentPoint;
    (void)enterEventMode;
    (void)terminateSimulation;
    return NOT_OFFERED(component, "fmi3CompletedIntegratorStep");
}

fmi3Status fmi3SetTime(fmi3Instance component, fmi3Float64 time)
{
    (void)time;
    return NOT_OFFERED(component, "fmi3SetTime");
}

/* The model-exchange calls of one array of n reals. */
#define MODEL_EXCHANGE_ARRAY(function, qualifier)                                          \
    fmi3Status function(fmi3Instance component, qualifier fmi3Float64 values[], size_t n) \
    {                                                                                      \
        (void)values;                                                                      \
        (void)n;                                                                           \
        return NOT_OFFERED(component, #function);                                          \
    }
#define NO_QUALIFIER

MODEL_EXCHANGE_ARRAY(fmi3SetContinuousStates, const)
MODEL_EXCHANGE_ARRAY(fmi3GetContinuousStateDerivatives, NO_QUALIFIER)
MODEL_EXCHANGE_ARRAY(fmi3GetEventIndicators, NO_QUALIFIER)
MODEL_EXCHANGE_ARRAY(fmi3GetContinuousStates, NO_QUALIFIER)
MODEL_EXCHANGE_ARRAY(fmi3GetNominalsOfContinuousStates, NO_QUALIFIER)

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance component, size_t *n)
{
    (void)n;
    return NOT_OFFERED(component, "fmi3GetNumberOfEventIndicators");
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance component, size_t *n)
{
    (void)n;
    return NOT_OFFERED(component, "fmi3GetNumberOfContinuousStates");
}

fmi3Status fmi3DoStep(fmi3Instance component, fmi3Float64 currentCommunicationPoint,
                      fmi3Float64 communicationStepSize, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                      fmi3Boolean *eventHandlingNeeded, fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn,
                      fmi3Float64 *lastSuccessfulTime)
{
    instance *c = (instance *)component;
    (void)noSetFMUStatePriorToCurrentPoint;
    if (c == NULL)
        return fmi3Error;
    if (c->phase != STEPPING)
        return misuse(c, "fmi3DoStep", NULL);
    if (eventHandlingNeeded == NULL || terminateSimulation == NULL || earlyReturn == NULL || lastSuccessfulTime == NULL)
        return misuse(c, "fmi3DoStep", "NULL output argument");
    *eventHandlingNeeded = fmi3False;
    *terminateSimulation = fmi3False;
    *earlyReturn = fmi3False;
    if (sr_fmu_do_step(&c->fmu, currentCommunicationPoint, communicationStepSize) != SR_FMU_OK) {
        *lastSuccessfulTime = c->fmu.time;
        return report(c, fmi3Error);
    }
    *lastSuccessfulTime = c->fmu.time;
    return fmi3OK;
}
