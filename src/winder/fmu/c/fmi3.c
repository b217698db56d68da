/* winder's native FMI 3.0 wrapper: the FMI 2.0 core of fmi2.c (the machine's generated
 * functions and winder's C integrators: co-simulation with DOPRI5 or RK4 inside each
 * communication step, model exchange with the switching functions as event indicators)
 * behind fmi3Functions.h. Each fmi3 instance owns one fmi2 component; every function
 * translates its arguments and calls the fmi2 one, so both interfaces run the same code
 * and give the same numbers. Value references: layout.h (FMI 3.0 adds the time, the event
 * indicators and the Booleans after the FMI 2.0 Reals). Clocks, configuration mode and
 * scheduled execution are not offered (modelDescription.xml declares none). */

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "fmi3Functions.h"
#include "winder_model.h"
#include "layout.h"

typedef struct {
    fmi2Component c2;
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback log;
    int me;
} Inst;

static fmi3Status st3(fmi2Status s) {
    switch (s) {
    case fmi2OK: return fmi3OK;
    case fmi2Warning: return fmi3Warning;
    case fmi2Discard: return fmi3Discard;
    case fmi2Error: return fmi3Error;
    default: return fmi3Fatal;
    }
}

/* the fmi2 core's logger: its message formatted, then handed to the FMI 3.0 callback */
static void relay(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status,
                  fmi2String category, fmi2String message, ...) {
    const Inst* in = env;
    char buf[1024];
    va_list ap;
    (void)name;
    if (!in || !in->log)
        return;
    va_start(ap, message);
    vsnprintf(buf, sizeof buf, message, ap);
    va_end(ap);
    in->log(in->env, st3(status), category, buf);
}

static fmi3Status refuse(Inst* in, const char* what) {
    if (in && in->log)
        in->log(in->env, fmi3Error, "logStatusError", what);
    return fmi3Error;
}

static Inst* instantiate(fmi3String name, fmi3String token, fmi3Boolean logging,
                         fmi3InstanceEnvironment env, fmi3LogMessageCallback log, int me) {
    Inst* in = calloc(1, sizeof(Inst));
    if (!in)
        return NULL;
    in->env = env;
    in->log = log;
    in->me = me;
    fmi2CallbackFunctions cb = {relay, NULL, NULL, NULL, in};
    in->c2 = fmi2Instantiate(name, me ? fmi2ModelExchange : fmi2CoSimulation, token, "", &cb,
                             fmi2False, logging ? fmi2True : fmi2False);
    if (!in->c2) {
        free(in);
        return NULL;
    }
    return in;
}

/* ---- instance ------------------------------------------------------------------------ */

const char* fmi3GetVersion(void) { return fmi3Version; }

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t n,
                               const fmi3String categories[]) {
    (void)n;
    (void)categories;
    return st3(fmi2SetDebugLogging(((Inst*)instance)->c2, loggingOn, 0, NULL));
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String token,
                                          fmi3String resourcePath, fmi3Boolean visible,
                                          fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment env,
                                          fmi3LogMessageCallback logMessage) {
    (void)resourcePath;
    (void)visible;
    return instantiate(instanceName, token, loggingOn, env, logMessage, 1);
}

fmi3Instance fmi3InstantiateCoSimulation(
    fmi3String instanceName, fmi3String token, fmi3String resourcePath, fmi3Boolean visible,
    fmi3Boolean loggingOn, fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
    const fmi3ValueReference requiredIntermediateVariables[],
    size_t nRequiredIntermediateVariables, fmi3InstanceEnvironment env,
    fmi3LogMessageCallback logMessage, fmi3IntermediateUpdateCallback intermediateUpdate) {
    (void)resourcePath;
    (void)visible;
    (void)earlyReturnAllowed;
    (void)requiredIntermediateVariables;
    (void)intermediateUpdate;
    if (eventModeUsed || nRequiredIntermediateVariables) {
        if (logMessage)
            logMessage(env, fmi3Error, "logStatusError", "this FMU offers neither event mode "
                       "in co-simulation nor intermediate variables (it has no clocks)");
        return NULL;
    }
    return instantiate(instanceName, token, loggingOn, env, logMessage, 0);
}

fmi3Instance fmi3InstantiateScheduledExecution(
    fmi3String instanceName, fmi3String token, fmi3String resourcePath, fmi3Boolean visible,
    fmi3Boolean loggingOn, fmi3InstanceEnvironment env, fmi3LogMessageCallback logMessage,
    fmi3ClockUpdateCallback clockUpdate, fmi3LockPreemptionCallback lockPreemption,
    fmi3UnlockPreemptionCallback unlockPreemption) {
    (void)instanceName;
    (void)token;
    (void)resourcePath;
    (void)visible;
    (void)loggingOn;
    (void)clockUpdate;
    (void)lockPreemption;
    (void)unlockPreemption;
    if (logMessage)
        logMessage(env, fmi3Error, "logStatusError",
                   "scheduled execution is not offered: use co-simulation or model exchange");
    return NULL;
}

void fmi3FreeInstance(fmi3Instance instance) {
    Inst* in = instance;
    if (!in)
        return;
    fmi2FreeInstance(in->c2);
    free(in);
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined,
                                       fmi3Float64 tolerance, fmi3Float64 startTime,
                                       fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    Inst* in = instance;
    fmi2Status s = fmi2SetupExperiment(in->c2, toleranceDefined, tolerance, startTime,
                                       stopTimeDefined, stopTime);
    return s == fmi2OK ? st3(fmi2EnterInitializationMode(in->c2)) : st3(s);
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    return st3(fmi2ExitInitializationMode(((Inst*)instance)->c2));
}

fmi3Status fmi3EnterEventMode(fmi3Instance instance) {
    return st3(fmi2EnterEventMode(((Inst*)instance)->c2));
}

fmi3Status fmi3Terminate(fmi3Instance instance) {
    return st3(fmi2Terminate(((Inst*)instance)->c2));
}

fmi3Status fmi3Reset(fmi3Instance instance) { return st3(fmi2Reset(((Inst*)instance)->c2)); }

/* ---- variables ----------------------------------------------------------------------- */

/* the Reals of FMI 2.0 in one fmi2GetReal call per contiguous run (its derivatives are
 * evaluated once per call), then the time and the event indicators */
fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                          fmi3Float64 values[], size_t nValues) {
    Inst* in = instance;
    double z[W_NZ + 1];
    int have_z = 0;
    if (nValues != nvr)
        return refuse(in, "fmi3GetFloat64: one value per value reference");
    for (size_t i = 0; i < nvr;) {
        fmi2Status s = fmi2OK;
        size_t run = 0;
        while (i + run < nvr && vr[i + run] < VR_END)
            run++;
        if (run) {
            s = fmi2GetReal(in->c2, &vr[i], run, &values[i]);
            i += run;
        } else if (vr[i] == VR_TIME) {
            s = fmi2GetRealStatus(in->c2, fmi2LastSuccessfulTime, &values[i++]);
        } else if (vr[i] < VR_Z + W_NZ) {
            if (!have_z) {
                s = fmi2GetEventIndicators(in->c2, z, W_NZ);
                have_z = 1;
            }
            values[i] = z[vr[i] - VR_Z];
            i++;
        } else {
            return refuse(in, "fmi3GetFloat64: not a Float64 value reference");
        }
        if (s != fmi2OK)
            return st3(s);
    }
    return fmi3OK;
}

fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                          const fmi3Float64 values[], size_t nValues) {
    Inst* in = instance;
    if (nValues != nvr)
        return refuse(in, "fmi3SetFloat64: one value per value reference");
    for (size_t i = 0; i < nvr; i++)
        if (vr[i] >= VR_END)
            return refuse(in, "fmi3SetFloat64: the time and the event indicators cannot "
                              "be set");
    return st3(fmi2SetReal(in->c2, vr, nvr, values));
}

/* the FMI 2.0 Boolean of an FMI 3.0 value reference (rk4 0, speed_profile 1), or -1 */
static int bool2(fmi3ValueReference vr) {
    return vr >= VR_BOOL && vr < VR_BOOL + 1 + W_OWN ? (int)(vr - VR_BOOL) : -1;
}

fmi3Status fmi3GetBoolean(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                          fmi3Boolean values[], size_t nValues) {
    Inst* in = instance;
    if (nValues != nvr)
        return refuse(in, "fmi3GetBoolean: one value per value reference");
    for (size_t i = 0; i < nvr; i++) {
        int b = bool2(vr[i]);
        fmi2ValueReference r = (fmi2ValueReference)b;
        fmi2Boolean v = fmi2False;
        if (b < 0)
            return refuse(in, "fmi3GetBoolean: not a Boolean value reference");
        fmi2Status s = fmi2GetBoolean(in->c2, &r, 1, &v);
        if (s != fmi2OK)
            return st3(s);
        values[i] = v != fmi2False;
    }
    return fmi3OK;
}

fmi3Status fmi3SetBoolean(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                          const fmi3Boolean values[], size_t nValues) {
    Inst* in = instance;
    if (nValues != nvr)
        return refuse(in, "fmi3SetBoolean: one value per value reference");
    for (size_t i = 0; i < nvr; i++) {
        int b = bool2(vr[i]);
        fmi2ValueReference r = (fmi2ValueReference)b;
        fmi2Boolean v = values[i] ? fmi2True : fmi2False;
        if (b < 0)
            return refuse(in, "fmi3SetBoolean: not a Boolean value reference");
        fmi2Status s = fmi2SetBoolean(in->c2, &r, 1, &v);
        if (s != fmi2OK)
            return st3(s);
    }
    return fmi3OK;
}

/* the types this FMU has no variables of: any value reference is refused */
#define NO_VARIABLES(Type, CType)                                                           \
    fmi3Status fmi3Get##Type(fmi3Instance instance, const fmi3ValueReference vr[],          \
                             size_t nvr, CType values[], size_t nValues) {                  \
        (void)vr;                                                                           \
        (void)values;                                                                       \
        (void)nValues;                                                                      \
        return nvr ? refuse(instance, "this FMU has no " #Type " variables") : fmi3OK;      \
    }                                                                                       \
    fmi3Status fmi3Set##Type(fmi3Instance instance, const fmi3ValueReference vr[],          \
                             size_t nvr, const CType values[], size_t nValues) {            \
        (void)vr;                                                                           \
        (void)values;                                                                       \
        (void)nValues;                                                                      \
        return nvr ? refuse(instance, "this FMU has no " #Type " variables") : fmi3OK;      \
    }

NO_VARIABLES(Float32, fmi3Float32)
NO_VARIABLES(Int8, fmi3Int8)
NO_VARIABLES(UInt8, fmi3UInt8)
NO_VARIABLES(Int16, fmi3Int16)
NO_VARIABLES(UInt16, fmi3UInt16)
NO_VARIABLES(Int32, fmi3Int32)
NO_VARIABLES(UInt32, fmi3UInt32)
NO_VARIABLES(Int64, fmi3Int64)
NO_VARIABLES(UInt64, fmi3UInt64)
NO_VARIABLES(String, fmi3String)

fmi3Status fmi3GetBinary(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                         size_t valueSizes[], fmi3Binary values[], size_t nValues) {
    (void)vr;
    (void)valueSizes;
    (void)values;
    (void)nValues;
    return nvr ? refuse(instance, "this FMU has no Binary variables") : fmi3OK;
}

fmi3Status fmi3SetBinary(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                         const size_t valueSizes[], const fmi3Binary values[],
                         size_t nValues) {
    (void)vr;
    (void)valueSizes;
    (void)values;
    (void)nValues;
    return nvr ? refuse(instance, "this FMU has no Binary variables") : fmi3OK;
}

fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                        fmi3Clock values[]) {
    (void)vr;
    (void)values;
    return nvr ? refuse(instance, "this FMU has no clocks") : fmi3OK;
}

fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                        const fmi3Clock values[]) {
    (void)vr;
    (void)values;
    return nvr ? refuse(instance, "this FMU has no clocks") : fmi3OK;
}

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance instance, fmi3ValueReference vr,
                                               size_t* n) {
    (void)vr;
    (void)n;
    return refuse(instance, "variable dependencies: read them from modelDescription.xml "
                            "(ModelStructure)");
}

fmi3Status fmi3GetVariableDependencies(fmi3Instance instance, fmi3ValueReference dependent,
                                       size_t elementIndicesOfDependent[],
                                       fmi3ValueReference independents[],
                                       size_t elementIndicesOfIndependents[],
                                       fmi3DependencyKind dependencyKinds[],
                                       size_t nDependencies) {
    (void)dependent;
    (void)elementIndicesOfDependent;
    (void)independents;
    (void)elementIndicesOfIndependents;
    (void)dependencyKinds;
    (void)nDependencies;
    return refuse(instance, "variable dependencies: read them from modelDescription.xml "
                            "(ModelStructure)");
}

/* ---- FMU state (the fmi2 core's, serialised with its GUID) ---------------------------- */

fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState* state) {
    return st3(fmi2GetFMUstate(((Inst*)instance)->c2, state));
}

fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState state) {
    return st3(fmi2SetFMUstate(((Inst*)instance)->c2, state));
}

fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState* state) {
    return st3(fmi2FreeFMUstate(((Inst*)instance)->c2, state));
}

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState state,
                                      size_t* size) {
    return st3(fmi2SerializedFMUstateSize(((Inst*)instance)->c2, state, size));
}

fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState state,
                                 fmi3Byte serializedState[], size_t size) {
    return st3(fmi2SerializeFMUstate(((Inst*)instance)->c2, state, (fmi2Byte*)serializedState,
                                     size));
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte serializedState[],
                                   size_t size, fmi3FMUState* state) {
    return st3(fmi2DeSerializeFMUstate(((Inst*)instance)->c2,
                                       (const fmi2Byte*)serializedState, size, state));
}

/* ---- partial derivatives ------------------------------------------------------------- */

fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance,
                                        const fmi3ValueReference unknowns[], size_t nUnknowns,
                                        const fmi3ValueReference knowns[], size_t nKnowns,
                                        const fmi3Float64 seed[], size_t nSeed,
                                        fmi3Float64 sensitivity[], size_t nSensitivity) {
    Inst* in = instance;
    if (nSeed != nKnowns || nSensitivity != nUnknowns)
        return refuse(in, "fmi3GetDirectionalDerivative: one seed per known and one "
                          "sensitivity per unknown");
    return st3(fmi2GetDirectionalDerivative(in->c2, unknowns, nUnknowns, knowns, nKnowns, seed,
                                            sensitivity));
}

fmi3Status fmi3GetAdjointDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[],
                                    size_t nUnknowns, const fmi3ValueReference knowns[],
                                    size_t nKnowns, const fmi3Float64 seed[], size_t nSeed,
                                    fmi3Float64 sensitivity[], size_t nSensitivity) {
    (void)unknowns;
    (void)nUnknowns;
    (void)knowns;
    (void)nKnowns;
    (void)seed;
    (void)nSeed;
    (void)sensitivity;
    (void)nSensitivity;
    return refuse(instance, "adjoint derivatives are not offered (providesAdjointDerivatives "
                            "is false): use fmi3GetDirectionalDerivative");
}

/* ---- configuration mode, clocks: not offered ------------------------------------------ */

fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance) {
    return refuse(instance, "this FMU has no structural parameters (no configuration mode)");
}

fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance) {
    return refuse(instance, "this FMU has no structural parameters (no configuration mode)");
}

fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference vr[],
                                  size_t nvr, fmi3Float64 intervals[],
                                  fmi3IntervalQualifier qualifiers[]) {
    (void)vr;
    (void)nvr;
    (void)intervals;
    (void)qualifiers;
    return refuse(instance, "this FMU has no clocks");
}

fmi3Status fmi3GetIntervalFraction(fmi3Instance instance, const fmi3ValueReference vr[],
                                   size_t nvr, fmi3UInt64 counters[],
                                   fmi3UInt64 resolutions[],
                                   fmi3IntervalQualifier qualifiers[]) {
    (void)vr;
    (void)nvr;
    (void)counters;
    (void)resolutions;
    (void)qualifiers;
    return refuse(instance, "this FMU has no clocks");
}

fmi3Status fmi3GetShiftDecimal(fmi3Instance instance, const fmi3ValueReference vr[],
                               size_t nvr, fmi3Float64 shifts[]) {
    (void)vr;
    (void)nvr;
    (void)shifts;
    return refuse(instance, "this FMU has no clocks");
}

fmi3Status fmi3GetShiftFraction(fmi3Instance instance, const fmi3ValueReference vr[],
                                size_t nvr, fmi3UInt64 counters[], fmi3UInt64 resolutions[]) {
    (void)vr;
    (void)nvr;
    (void)counters;
    (void)resolutions;
    return refuse(instance, "this FMU has no clocks");
}

fmi3Status fmi3SetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference vr[],
                                  size_t nvr, const fmi3Float64 intervals[]) {
    (void)vr;
    (void)nvr;
    (void)intervals;
    return refuse(instance, "this FMU has no clocks");
}

fmi3Status fmi3SetIntervalFraction(fmi3Instance instance, const fmi3ValueReference vr[],
                                   size_t nvr, const fmi3UInt64 counters[],
                                   const fmi3UInt64 resolutions[]) {
    (void)vr;
    (void)nvr;
    (void)counters;
    (void)resolutions;
    return refuse(instance, "this FMU has no clocks");
}

fmi3Status fmi3SetShiftDecimal(fmi3Instance instance, const fmi3ValueReference vr[],
                               size_t nvr, const fmi3Float64 shifts[]) {
    (void)vr;
    (void)nvr;
    (void)shifts;
    return refuse(instance, "this FMU has no clocks");
}

fmi3Status fmi3SetShiftFraction(fmi3Instance instance, const fmi3ValueReference vr[],
                                size_t nvr, const fmi3UInt64 counters[],
                                const fmi3UInt64 resolutions[]) {
    (void)vr;
    (void)nvr;
    (void)counters;
    (void)resolutions;
    return refuse(instance, "this FMU has no clocks");
}

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clock,
                                      fmi3Float64 activationTime) {
    (void)clock;
    (void)activationTime;
    return refuse(instance, "scheduled execution is not offered");
}

/* ---- event mode and model exchange ---------------------------------------------------- */

fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance) {
    (void)instance;
    return fmi3OK;
}

fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean* needUpdate,
                                    fmi3Boolean* terminateSimulation,
                                    fmi3Boolean* nominalsChanged, fmi3Boolean* valuesChanged,
                                    fmi3Boolean* nextEventTimeDefined,
                                    fmi3Float64* nextEventTime) {
    Inst* in = instance;
    fmi2EventInfo ev;
    fmi2Status s = fmi2NewDiscreteStates(in->c2, &ev);
    *needUpdate = ev.newDiscreteStatesNeeded != fmi2False;
    *terminateSimulation = ev.terminateSimulation != fmi2False;
    *nominalsChanged = ev.nominalsOfContinuousStatesChanged != fmi2False;
    *valuesChanged = ev.valuesOfContinuousStatesChanged != fmi2False;
    *nextEventTimeDefined = ev.nextEventTimeDefined != fmi2False;
    *nextEventTime = ev.nextEventTime;
    return st3(s);
}

fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance) {
    return st3(fmi2EnterContinuousTimeMode(((Inst*)instance)->c2));
}

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance, fmi3Boolean noSetPrior,
                                       fmi3Boolean* enterEventMode,
                                       fmi3Boolean* terminateSimulation) {
    fmi2Boolean e = fmi2False, t = fmi2False;
    fmi2Status s = fmi2CompletedIntegratorStep(((Inst*)instance)->c2, noSetPrior, &e, &t);
    *enterEventMode = e != fmi2False;
    *terminateSimulation = t != fmi2False;
    return st3(s);
}

fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time) {
    return st3(fmi2SetTime(((Inst*)instance)->c2, time));
}

fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 x[], size_t n) {
    return st3(fmi2SetContinuousStates(((Inst*)instance)->c2, x, n));
}

fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 dx[],
                                             size_t n) {
    return st3(fmi2GetDerivatives(((Inst*)instance)->c2, dx, n));
}

fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 z[], size_t n) {
    return st3(fmi2GetEventIndicators(((Inst*)instance)->c2, z, n));
}

fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 x[], size_t n) {
    return st3(fmi2GetContinuousStates(((Inst*)instance)->c2, x, n));
}

fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 x[],
                                             size_t n) {
    return st3(fmi2GetNominalsOfContinuousStates(((Inst*)instance)->c2, x, n));
}

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t* n) {
    (void)instance;
    *n = W_NZ;
    return fmi3OK;
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t* n) {
    (void)instance;
    *n = W_N;
    return fmi3OK;
}

/* ---- co-simulation ------------------------------------------------------------------- */

fmi3Status fmi3EnterStepMode(fmi3Instance instance) {
    (void)instance;
    return fmi3OK;
}

fmi3Status fmi3GetOutputDerivatives(fmi3Instance instance, const fmi3ValueReference vr[],
                                    size_t nvr, const fmi3Int32 orders[], fmi3Float64 values[],
                                    size_t nValues) {
    (void)vr;
    (void)orders;
    (void)values;
    (void)nValues;
    return nvr ? refuse(instance, "output derivatives are not offered "
                                  "(maxOutputDerivativeOrder 0)") : fmi3OK;
}

/* fmi2DoStep; the run-out of an unwinding roll (fmi2Discard) ends the simulation there */
fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 t, fmi3Float64 dt,
                      fmi3Boolean noSetPrior, fmi3Boolean* eventHandlingNeeded,
                      fmi3Boolean* terminateSimulation, fmi3Boolean* earlyReturn,
                      fmi3Float64* lastSuccessfulTime) {
    Inst* in = instance;
    fmi2Status s = fmi2DoStep(in->c2, t, dt, noSetPrior);
    fmi2Boolean ended = fmi2False;
    *eventHandlingNeeded = false;
    *earlyReturn = false;
    fmi2GetRealStatus(in->c2, fmi2LastSuccessfulTime, lastSuccessfulTime);
    fmi2GetBooleanStatus(in->c2, fmi2Terminated, &ended);
    *terminateSimulation = ended != fmi2False;
    return st3(s);
}
