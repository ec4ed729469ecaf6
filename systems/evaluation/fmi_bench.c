/* fmi_bench.c: the per-step cost of an FMI 2.0 co-simulation FMU in a C host with no Python in
 * its process, as most FMI tools are (systems.evaluation.bench.bench_fmu). Usage:
 *   fmi_bench BINARY GUID RESOURCE_URI DATA H ROUNDS VR_IN VR_OUT VR_VALID
 * DATA holds rows of raw doubles, one value per input of VR_IN (value references separated by
 * commas); each round resets the FMU, initialises it with its start values and, per row, sets
 * the inputs, steps H seconds and gets the outputs VR_OUT and the Boolean VR_VALID ("-": an FMU without
 * one, as an exported diagram, gets no Boolean). Prints the
 * best round's nanoseconds per step, then ends with _exit: pythonfmu's library finalises its
 * interpreter from a destructor that can crash at process exit. */
#define _POSIX_C_SOURCE 199309L
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "fmi2FunctionTypes.h"

#define MAX_VRS 64

/* errors only, as the FMU wrote them (its format, not expanded: the bench's FMUs pass none) */
static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                   fmi2String message, ...) {
    (void)env, (void)name;
    if (status > fmi2Warning) fprintf(stderr, "[%s] %s\n", category, message);
}

static size_t references(char *list, fmi2ValueReference vr[]) {
    size_t n = 0;
    for (char *t = strtok(list, ","); t && n < MAX_VRS; t = strtok(NULL, ",")) vr[n++] = (fmi2ValueReference)atoi(t);
    return n;
}

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

int main(int argc, char **argv) {
    if (argc != 10) {
        fprintf(stderr, "usage: fmi_bench BINARY GUID RESOURCE_URI DATA H ROUNDS VR_IN VR_OUT VR_VALID\n");
        return 2;
    }
    void *lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        fprintf(stderr, "dlopen: %s\n", dlerror());
        return 3;
    }
#define FIND(type, name) type *name = (type *)dlsym(lib, #name)
    FIND(fmi2InstantiateTYPE, fmi2Instantiate);
    FIND(fmi2SetupExperimentTYPE, fmi2SetupExperiment);
    FIND(fmi2EnterInitializationModeTYPE, fmi2EnterInitializationMode);
    FIND(fmi2ExitInitializationModeTYPE, fmi2ExitInitializationMode);
    FIND(fmi2ResetTYPE, fmi2Reset);
    FIND(fmi2SetRealTYPE, fmi2SetReal);
    FIND(fmi2GetRealTYPE, fmi2GetReal);
    FIND(fmi2GetBooleanTYPE, fmi2GetBoolean);
    FIND(fmi2DoStepTYPE, fmi2DoStep);
#undef FIND
    fmi2ValueReference vr_in[MAX_VRS], vr_out[MAX_VRS], vr_valid = (fmi2ValueReference)atoi(argv[9]);
    const int has_valid = strcmp(argv[9], "-") != 0;
    size_t n_in = references(argv[7], vr_in), n_out = references(argv[8], vr_out);
    FILE *data = fopen(argv[4], "rb");
    if (!data) return 4;
    fseek(data, 0, SEEK_END);
    size_t steps = (size_t)ftell(data) / (n_in * sizeof(double));
    double *inputs = malloc(steps * n_in * sizeof(double) + 1);
    rewind(data);
    if (!inputs || fread(inputs, sizeof(double) * n_in, steps, data) != steps) return 4;
    fclose(data);
    double h = atof(argv[5]), best = 1e300, outputs[MAX_VRS];
    fmi2Boolean valid;
    const fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    fmi2Component c = fmi2Instantiate("bench", fmi2CoSimulation, argv[2], argv[3], &callbacks, fmi2False, fmi2False);
    if (!c) return 5;
    int status = 0;
    for (int round = 0; round < atoi(argv[6]) && status <= fmi2Warning; round++) {
        status = fmi2Reset(c) | fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) |
                 fmi2EnterInitializationMode(c) | fmi2ExitInitializationMode(c);
        double start = now();
        for (size_t k = 0; k < steps && status <= fmi2Warning; k++) {
            status |= fmi2SetReal(c, vr_in, n_in, inputs + k * n_in);
            status |= fmi2DoStep(c, k * h, h, fmi2True);
            status |= fmi2GetReal(c, vr_out, n_out, outputs);
            if (has_valid) status |= fmi2GetBoolean(c, &vr_valid, 1, &valid);
        }
        double elapsed = (now() - start) / (double)steps;
        if (elapsed < best) best = elapsed;
    }
    printf("%.6g\n", best * 1e9);
    fflush(stdout);
    fflush(stderr);
    _exit(status > fmi2Warning ? 6 : 0);
}
