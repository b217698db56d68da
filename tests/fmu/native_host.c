/* A plain C FMI 2.0 co-simulation host for the native FMU's tests (no FMPy, no Python):
 *   native_host MODEL.so GUID CYCLES VR [STEPS DT [RK4 [NREAD]]]
 * dlopens the binary once, then CYCLES times instantiates, initialises, does 10 steps of
 * 10 ms, reads the Real VR, terminates and frees; prints the cycles and whether VR was
 * the same every time (STEPS steps of DT [s] instead; RK4 = 1 sets the Boolean rk4 true;
 * NREAD: the Reals of value references 0 .. NREAD-1, the outputs, read after every step).
 * Built with -fsanitize=address,undefined by tests/fmu/test_native.py, and without by
 * benchmarks/fmu_native.py (the real-time factor it prints: simulated time / wall). */

#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "fmi2Functions.h"

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status,
                   fmi2String category, fmi2String message, ...) {
    va_list ap;
    (void)env;
    va_start(ap, message);
    fprintf(stderr, "[%s|%d|%s] ", name, (int)status, category);
    vfprintf(stderr, message, ap);
    fputc('\n', stderr);
    va_end(ap);
}

#define LOAD(T, name)                                                  \
    T name = (T)dlsym(lib, #name);                                     \
    if (!name) {                                                       \
        fprintf(stderr, "missing symbol %s\n", #name);                 \
        return 2;                                                      \
    }

int main(int argc, char** argv) {
    if (argc < 5) {
        fprintf(stderr, "usage: %s MODEL.so GUID CYCLES VR [STEPS DT]\n", argv[0]);
        return 2;
    }
    int cycles = atoi(argv[3]);
    fmi2ValueReference vr = (fmi2ValueReference)atoi(argv[4]);
    int steps = argc > 5 ? atoi(argv[5]) : 10;
    double dt = argc > 6 ? atof(argv[6]) : 0.01;
    fmi2Boolean rk4 = argc > 7 && atoi(argv[7]) ? fmi2True : fmi2False;
    fmi2ValueReference rk4_vr = 0;
    int nread = argc > 8 ? atoi(argv[8]) : 0;
    fmi2ValueReference* reads = calloc((size_t)nread + 1, sizeof(fmi2ValueReference));
    double* values = calloc((size_t)nread + 1, sizeof(double));
    for (int i = 0; i < nread; i++)
        reads[i] = (fmi2ValueReference)i;
    void* lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        fprintf(stderr, "dlopen: %s\n", dlerror());
        return 2;
    }
    LOAD(fmi2InstantiateTYPE*, fmi2Instantiate)
    LOAD(fmi2SetupExperimentTYPE*, fmi2SetupExperiment)
    LOAD(fmi2EnterInitializationModeTYPE*, fmi2EnterInitializationMode)
    LOAD(fmi2ExitInitializationModeTYPE*, fmi2ExitInitializationMode)
    LOAD(fmi2DoStepTYPE*, fmi2DoStep)
    LOAD(fmi2GetRealTYPE*, fmi2GetReal)
    LOAD(fmi2SetBooleanTYPE*, fmi2SetBoolean)
    LOAD(fmi2TerminateTYPE*, fmi2Terminate)
    LOAD(fmi2FreeInstanceTYPE*, fmi2FreeInstance)
    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    double first = 0.0;
    int same = 1;
    int runs = cycles > 0 ? cycles : 1;
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (int c = 0; c < runs; c++) {
        fmi2Component s = fmi2Instantiate("host", fmi2CoSimulation, argv[2], "", &cb,
                                          fmi2False, fmi2False);
        if (!s) {
            fprintf(stderr, "instantiate failed in cycle %d\n", c);
            return 1;
        }
        if (fmi2SetupExperiment(s, fmi2False, 0.0, 0.0, fmi2False, 0.0) != fmi2OK ||
            fmi2EnterInitializationMode(s) != fmi2OK ||
            fmi2SetBoolean(s, &rk4_vr, 1, &rk4) != fmi2OK ||
            fmi2ExitInitializationMode(s) != fmi2OK)
            return 1;
        for (int i = 0; i < steps; i++) {
            if (fmi2DoStep(s, i * dt, dt, fmi2True) != fmi2OK) {
                fprintf(stderr, "step %d failed in cycle %d\n", i, c);
                return 1;
            }
            if (nread && fmi2GetReal(s, reads, (size_t)nread, values) != fmi2OK)
                return 1;
        }
        double v = 0.0;
        if (fmi2GetReal(s, &vr, 1, &v) != fmi2OK)
            return 1;
        if (c == 0)
            first = v;
        else if (v != first)
            same = 0;
        fmi2Terminate(s);
        fmi2FreeInstance(s);
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    double wall = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    printf("%d cycles of %d steps of %g s: value %.17g, %s; wall %.6f s, real-time factor "
           "%.1f\n", runs, steps, dt, first, same ? "same radius every time" : "DIFFERENT",
           wall, runs * steps * dt / wall);
    free(reads);
    free(values);
    dlclose(lib);
    return same ? 0 : 1;
}
