/* fmi_host.c: a minimal FMI 2.0 co-simulation importer with no Python in its process, as
 * most FMI tools are (tests/test_fmu.py). Usage:
 *   fmi_host BINARY GUID RESOURCE_URI STEPS H VR_IN... -- U... -- VR_OUT... [-- VR_STRING]
 * sets the inputs VR_IN to U before each of STEPS doSteps of H seconds, then prints the
 * outputs VR_OUT, one per line. With VR_STRING (a String variable) it also makes the calls
 * FMI 2.0 does not allow, fmi2SetReal on VR_STRING before initialisation and fmi2DoStep
 * before it and after fmi2Terminate, and prints "misuse S1 S2 S3", their statuses, on
 * standard error. With FMI_HOST_RELOAD set in its environment it unloads the FMU after the run and
 * loads and runs it once more. It then returns from main, as a tool does: exit() runs the atexit
 * handlers and the libraries' destructors, pythonfmu's among them (fmi2_guard.c makes those
 * safe), and the process's status is the run's. */
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef void *Component;
typedef struct {
    void (*logger)(void *, const char *, int, const char *, const char *, ...);
    void *(*allocate)(size_t, size_t);
    void (*release)(void *);
    void (*step_finished)(void *, int);
    void *environment;
} Callbacks;

static void logger(void *env, const char *name, int status, const char *category, const char *message, ...) {
    (void)env;
    (void)name;
    va_list args;
    va_start(args, message);
    fprintf(stderr, "[%d %s] ", status, category);
    vfprintf(stderr, message, args);
    fputc('\n', stderr);
    va_end(args);
}

typedef Component (*Instantiate)(const char *, int, const char *, const char *, const Callbacks *, int, int);
typedef int (*Setup)(Component, int, double, double, int, double);
typedef int (*Mode)(Component);
typedef int (*SetReal)(Component, const unsigned *, size_t, const double *);
typedef int (*GetReal)(Component, const unsigned *, size_t, double *);
typedef int (*DoStep)(Component, double, double, int);
typedef void (*Free)(Component);
#define CALL(type, name) type name = (type)dlsym(lib, #name)

/* one run of the FMU in lib, as the usage says: the process's status */
static int run(void *lib, int argc, char **argv) {
    CALL(Instantiate, fmi2Instantiate);
    CALL(Setup, fmi2SetupExperiment);
    CALL(Mode, fmi2EnterInitializationMode);
    CALL(Mode, fmi2ExitInitializationMode);
    CALL(SetReal, fmi2SetReal);
    CALL(GetReal, fmi2GetReal);
    CALL(DoStep, fmi2DoStep);
    CALL(Mode, fmi2Terminate);
    CALL(Free, fmi2FreeInstance);
    unsigned vr_in[64], vr_out[64], vr_string = 0;
    double u[64], y[64];
    size_t n_in = 0, n_u = 0, n_out = 0, n_string = 0;
    int part = 0;
    for (int i = 6; i < argc; i++) {
        if (strcmp(argv[i], "--") == 0) part++;
        else if (part == 0 && n_in < 64) vr_in[n_in++] = (unsigned)atoi(argv[i]);
        else if (part == 1 && n_u < 64) u[n_u++] = atof(argv[i]);
        else if (part == 2 && n_out < 64) vr_out[n_out++] = (unsigned)atoi(argv[i]);
        else if (part == 3 && n_string < 1) vr_string = (unsigned)atoi(argv[i]), n_string = 1;
    }
    Callbacks callbacks = {logger, calloc, free, NULL, NULL};
    Component c = fmi2Instantiate("host", 1, argv[2], argv[3], &callbacks, 0, 0);
    if (!c || n_u != n_in) return 4;
    double one = 1.0;
    int misuse[3] = {0, 0, 0};
    if (n_string) {
        misuse[0] = fmi2SetReal(c, &vr_string, 1, &one);
        misuse[1] = fmi2DoStep(c, 0.0, atof(argv[5]), 1);
    }
    int status = fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0) | fmi2EnterInitializationMode(c) |
                 fmi2ExitInitializationMode(c);
    int steps = atoi(argv[4]);
    double h = atof(argv[5]);
    for (int k = 0; k < steps && status == 0; k++) {
        status |= fmi2SetReal(c, vr_in, n_in, u);
        status |= fmi2DoStep(c, k * h, h, 1);
    }
    status |= fmi2GetReal(c, vr_out, n_out, y);
    for (size_t i = 0; i < n_out; i++) printf("%.17g\n", y[i]);
    status |= fmi2Terminate(c);
    if (n_string) {
        misuse[2] = fmi2DoStep(c, steps * h, h, 1);
        fprintf(stderr, "misuse %d %d %d\n", misuse[0], misuse[1], misuse[2]);
    }
    fmi2FreeInstance(c);
    return status ? 5 : 0;
}

int main(int argc, char **argv) {
    if (argc < 6) return 2;
    /* FMI_HOST_RELOAD set: the FMU unloaded after its run and loaded and run again, as a tool that runs two
     * simulations in one process does */
    for (int load = 0; load < (getenv("FMI_HOST_RELOAD") ? 2 : 1); load++) {
        void *lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
        if (!lib) {
            fprintf(stderr, "dlopen: %s\n", dlerror());
            return 3;
        }
        int status = run(lib, argc, argv);
        dlclose(lib);
        if (status) return status;
    }
    return 0;
}
