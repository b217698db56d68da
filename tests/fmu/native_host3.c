/* A plain C FMI 3.0 co-simulation host for the native FMU's tests (no FMPy, no Python):
 *   native_host3 MODEL.so TOKEN CYCLES VR VR_TIME
 * dlopens the binary once, then CYCLES times instantiates, initialises, does 10 steps of
 * 10 ms, takes, serialises and frees an FMU state, reads the Float64 VR, misuses it twice
 * (a step that does not start where the last ended: refused in the FMI 2.0 core and logged
 * through the wrapper's relay; a Float64 that cannot be set: refused by the wrapper),
 * terminates and frees; prints the cycles, whether VR was the same every time and the
 * messages logged. Built with
 * -fsanitize=address,undefined by tests/fmu/test_fmi3.py. */

#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>

#include "fmi3Functions.h"

static int logged = 0;

/* counts the messages (each cycle's deliberate misuse logs two), prints the first ones */
static void logger(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category,
                   fmi3String message) {
    (void)env;
    if (logged++ < 2)
        fprintf(stderr, "[%d|%s] %s\n", (int)status, category, message);
}

#define LOAD(name)                                                     \
    name##TYPE* name = (name##TYPE*)dlsym(lib, #name);                 \
    if (!name) {                                                       \
        fprintf(stderr, "missing symbol %s\n", #name);                 \
        return 2;                                                      \
    }

int main(int argc, char** argv) {
    if (argc < 6) {
        fprintf(stderr, "usage: %s MODEL.so TOKEN CYCLES VR VR_TIME\n", argv[0]);
        return 2;
    }
    int cycles = atoi(argv[3]);
    fmi3ValueReference vr = (fmi3ValueReference)atoi(argv[4]);
    void* lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        fprintf(stderr, "dlopen: %s\n", dlerror());
        return 2;
    }
    LOAD(fmi3InstantiateCoSimulation)
    LOAD(fmi3EnterInitializationMode)
    LOAD(fmi3ExitInitializationMode)
    LOAD(fmi3DoStep)
    LOAD(fmi3GetFloat64)
    LOAD(fmi3SetFloat64)
    LOAD(fmi3GetFMUState)
    LOAD(fmi3SerializedFMUStateSize)
    LOAD(fmi3SerializeFMUState)
    LOAD(fmi3FreeFMUState)
    LOAD(fmi3Terminate)
    LOAD(fmi3FreeInstance)
    double first = 0.0;
    int same = 1;
    for (int c = 0; c < cycles; c++) {
        fmi3Instance s = fmi3InstantiateCoSimulation("h", argv[2], "", fmi3False, fmi3False,
                                                     fmi3False, fmi3False, NULL, 0, NULL,
                                                     logger, NULL);
        if (!s) {
            fprintf(stderr, "instantiate failed at cycle %d\n", c);
            return 1;
        }
        if (fmi3EnterInitializationMode(s, fmi3False, 0.0, 0.0, fmi3False, 0.0) != fmi3OK ||
            fmi3ExitInitializationMode(s) != fmi3OK)
            return 1;
        for (int i = 0; i < 10; i++) {
            fmi3Boolean event, terminate, early;
            fmi3Float64 last;
            if (fmi3DoStep(s, i * 0.01, 0.01, fmi3True, &event, &terminate, &early, &last)
                != fmi3OK)
                return 1;
        }
        fmi3FMUState state = NULL;
        size_t size = 0;
        if (fmi3GetFMUState(s, &state) != fmi3OK ||
            fmi3SerializedFMUStateSize(s, state, &size) != fmi3OK)
            return 1;
        fmi3Byte* bytes = malloc(size);
        if (!bytes || fmi3SerializeFMUState(s, state, bytes, size) != fmi3OK)
            return 1;
        free(bytes);
        fmi3FreeFMUState(s, &state);
        double v = 0.0;
        if (fmi3GetFloat64(s, &vr, 1, &v, 1) != fmi3OK)
            return 1;
        if (c == 0)
            first = v;
        same = same && v == first;
        fmi3Boolean event, terminate, early;
        fmi3Float64 last;
        fmi3ValueReference bad = (fmi3ValueReference)atoi(argv[5]);
        if (fmi3DoStep(s, 99.0, 0.01, fmi3True, &event, &terminate, &early, &last) != fmi3Error
            || fmi3SetFloat64(s, &bad, 1, &v, 1) != fmi3Error)
            return 1;
        fmi3Terminate(s);
        fmi3FreeInstance(s);
    }
    dlclose(lib);
    printf("%d cycles, %s radius %.17g, %d messages\n", cycles, same ? "same" : "different",
           first, logged);
    return 0;
}
