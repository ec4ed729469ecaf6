/* fmi_runner.c: an FMI 2.0 co-simulation importer with no Python in its process, as most FMI tools
 * are, driven by a script (tests/test_native_fmu.py). Usage: fmi_runner SCRIPT
 *
 * One command a line; each FMI call prints "<command> <status>" on stdout, the logger's messages
 * go to stderr as "[<status> <category>] <message>". Commands:
 *   load BINARY                   dlopen the FMU's shared library (the rest of the line) and find its functions
 *   instantiate GUID URI LOGGING  fmi2Instantiate (co-simulation; LOGGING 0 or 1)
 *   setup | enter | exit | terminate | reset | free
 *   real VR VALUE | string VR TEXT | boolean VR 0|1      one fmi2Set* (TEXT without spaces)
 *   step T H                      fmi2DoStep(T, H)
 *   get_real VR...                fmi2GetReal; prints the values after the status (%.17g)
 *   replay IN OUT NI VR... NO VR... NB VR...
 *       for each row of IN (raw doubles: t, h, then NI inputs): fmi2SetReal of the inputs,
 *       fmi2DoStep(t, h), fmi2GetReal of the NO outputs and fmi2GetBoolean of the NB ones;
 *       appends to OUT a row of doubles: the doStep status, the outputs, the booleans. Prints
 *       "replay <rows> <worst status>".
 *   save | restore                fmi2GetFMUstate, fmi2SerializeFMUstate, fmi2DeSerializeFMUstate
 *                                 into one saved state | fmi2SetFMUstate of it
 *   cycles N GUID URI H           N times: instantiate, setup, enter, exit, doStep(0, H),
 *                                 terminate, free; prints the worst status
 *   unload                        free the saved state, dlclose
 * main returns 0 once the script has run (a failing FMI call is reported, not fatal), 2 on a
 * script or loading error. */
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2FunctionTypes.h"

#define MAX_VRS 128

typedef struct {
    void *library;
    fmi2InstantiateTYPE *instantiate;
    fmi2FreeInstanceTYPE *free_instance;
    fmi2SetupExperimentTYPE *setup;
    fmi2EnterInitializationModeTYPE *enter;
    fmi2ExitInitializationModeTYPE *exit_init;
    fmi2TerminateTYPE *terminate;
    fmi2ResetTYPE *reset;
    fmi2SetRealTYPE *set_real;
    fmi2SetStringTYPE *set_string;
    fmi2SetBooleanTYPE *set_boolean;
    fmi2GetRealTYPE *get_real;
    fmi2GetBooleanTYPE *get_boolean;
    fmi2DoStepTYPE *do_step;
    fmi2GetFMUstateTYPE *get_state;
    fmi2SetFMUstateTYPE *set_state;
    fmi2FreeFMUstateTYPE *free_state;
    fmi2SerializedFMUstateSizeTYPE *state_size;
    fmi2SerializeFMUstateTYPE *serialize;
    fmi2DeSerializeFMUstateTYPE *deserialize;
} Fmu;

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                   fmi2String message, ...) {
    (void)env, (void)name;
    va_list args;
    va_start(args, message);
    fprintf(stderr, "[%d %s] ", (int)status, category);
    vfprintf(stderr, message, args);
    fputc('\n', stderr);
    va_end(args);
}

static const fmi2CallbackFunctions CALLBACKS = {logger, calloc, free, NULL, NULL};

static int load(Fmu *fmu, const char *path) {
    fmu->library = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!fmu->library) {
        fprintf(stderr, "dlopen: %s\n", dlerror());
        return 0;
    }
#define FIND(field, name)                                                                                          \
    if (!(*(void **)(&fmu->field) = dlsym(fmu->library, name))) {                                                  \
        fprintf(stderr, "no %s in %s\n", name, path);                                                              \
        return 0;                                                                                                  \
    }
    FIND(instantiate, "fmi2Instantiate") FIND(free_instance, "fmi2FreeInstance")
    FIND(setup, "fmi2SetupExperiment") FIND(enter, "fmi2EnterInitializationMode")
    FIND(exit_init, "fmi2ExitInitializationMode") FIND(terminate, "fmi2Terminate") FIND(reset, "fmi2Reset")
    FIND(set_real, "fmi2SetReal") FIND(set_string, "fmi2SetString") FIND(set_boolean, "fmi2SetBoolean")
    FIND(get_real, "fmi2GetReal") FIND(get_boolean, "fmi2GetBoolean") FIND(do_step, "fmi2DoStep")
    FIND(get_state, "fmi2GetFMUstate") FIND(set_state, "fmi2SetFMUstate") FIND(free_state, "fmi2FreeFMUstate")
    FIND(state_size, "fmi2SerializedFMUstateSize") FIND(serialize, "fmi2SerializeFMUstate")
    FIND(deserialize, "fmi2DeSerializeFMUstate")
#undef FIND
    return 1;
}

/* the next n value references from the tokens; 0 on a malformed list */
static int read_vrs(char **tokens, size_t n, fmi2ValueReference vr[]) {
    if (n > MAX_VRS) return 0;
    for (size_t i = 0; i < n; i++) {
        if (!tokens[i]) return 0;
        vr[i] = (fmi2ValueReference)strtoul(tokens[i], NULL, 10);
    }
    return 1;
}

static fmi2Status worse(fmi2Status a, fmi2Status b) { return a > b ? a : b; }

/* replay IN OUT NI VR... NO VR... NB VR...: tokens from IN on */
static int replay(const Fmu *fmu, fmi2Component c, char **tokens, size_t count) {
    fmi2ValueReference in[MAX_VRS], out[MAX_VRS], bools[MAX_VRS];
    size_t at = 2, ni, no, nb;
    if (count < 3) return 0;
    ni = strtoul(tokens[at++], NULL, 10);
    if (at + ni > count || !read_vrs(tokens + at, ni, in)) return 0;
    at += ni;
    if (at >= count) return 0;
    no = strtoul(tokens[at++], NULL, 10);
    if (at + no > count || !read_vrs(tokens + at, no, out)) return 0;
    at += no;
    if (at >= count) return 0;
    nb = strtoul(tokens[at++], NULL, 10);
    if (at + nb != count || !read_vrs(tokens + at, nb, bools)) return 0;
    FILE *source = fopen(tokens[0], "rb"), *sink = fopen(tokens[1], "ab");
    if (!source || !sink) {
        if (source) fclose(source);
        if (sink) fclose(sink);
        return 0;
    }
    double row[2 + MAX_VRS], result[1 + 2 * MAX_VRS], values[MAX_VRS];
    fmi2Boolean flags[MAX_VRS];
    size_t rows = 0;
    fmi2Status worst = fmi2OK;
    while (fread(row, sizeof(double), 2 + ni, source) == 2 + ni) {
        fmi2Status status = fmu->set_real(c, in, ni, row + 2);
        if (status < fmi2Error) status = worse(status, fmu->do_step(c, row[0], row[1], fmi2True));
        result[0] = status;
        if (status < fmi2Error && (fmu->get_real(c, out, no, values) > fmi2Warning ||
                                   fmu->get_boolean(c, bools, nb, flags) > fmi2Warning))
            status = fmi2Error;
        for (size_t i = 0; i < no; i++) result[1 + i] = status < fmi2Error ? values[i] : 0.0;
        for (size_t i = 0; i < nb; i++) result[1 + no + i] = status < fmi2Error ? flags[i] : 0.0;
        fwrite(result, sizeof(double), 1 + no + nb, sink);
        worst = worse(worst, status);
        rows++;
        if (status >= fmi2Error) break;
    }
    fclose(source);
    fclose(sink);
    printf("replay %zu %d\n", rows, (int)worst);
    return 1;
}

static fmi2Status cycles(const Fmu *fmu, long n, const char *guid, const char *uri, double h) {
    fmi2Status worst = fmi2OK;
    for (long k = 0; k < n; k++) {
        fmi2Component c = fmu->instantiate("cycle", fmi2CoSimulation, guid, uri, &CALLBACKS, fmi2False, fmi2False);
        if (!c) return fmi2Fatal;
        worst = worse(worst, fmu->setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0));
        worst = worse(worst, fmu->enter(c));
        worst = worse(worst, fmu->exit_init(c));
        worst = worse(worst, fmu->do_step(c, 0.0, h, fmi2True));
        worst = worse(worst, fmu->terminate(c));
        fmu->free_instance(c);
    }
    return worst;
}

int main(int argc, char **argv) {
    if (argc != 2) {
        fprintf(stderr, "usage: fmi_runner SCRIPT\n");
        return 2;
    }
    FILE *script = fopen(argv[1], "r");
    if (!script) {
        perror(argv[1]);
        return 2;
    }
    Fmu fmu = {0};
    fmi2Component c = NULL;
    fmi2FMUstate saved = NULL;
    char line[8192];
    int ok = 1;
    while (ok && fgets(line, sizeof line, script)) {
        char path[sizeof line];
        if (strncmp(line, "load ", 5) == 0) { /* a path may hold spaces */
            strcpy(path, line + 5);
            path[strcspn(path, "\r\n")] = '\0';
        }
        char *tokens[3 * MAX_VRS + 8];
        size_t n = 0;
        for (char *t = strtok(line, " \t\r\n"); t && n < sizeof tokens / sizeof *tokens; t = strtok(NULL, " \t\r\n"))
            tokens[n++] = t;
        if (n == 0) continue;
        const char *command = tokens[0];
        char **args = tokens + 1;
        size_t nargs = n - 1;
        int status = -1;
        if (strcmp(command, "load") == 0 && nargs >= 1) {
            ok = load(&fmu, path);
            continue;
        } else if (!fmu.library) {
            ok = 0;
        } else if (strcmp(command, "instantiate") == 0 && nargs == 3) {
            c = fmu.instantiate("runner", fmi2CoSimulation, args[0], args[1], &CALLBACKS, fmi2False, atoi(args[2]));
            status = c ? fmi2OK : fmi2Error;
        } else if (strcmp(command, "unload") == 0) {
            if (saved && c) fmu.free_state(c, &saved);
            dlclose(fmu.library);
            fmu.library = NULL;
            continue;
        } else if (strcmp(command, "cycles") == 0 && nargs == 4) {
            status = cycles(&fmu, atol(args[0]), args[1], args[2], atof(args[3]));
        } else if (!c) {
            ok = 0;
        } else if (strcmp(command, "setup") == 0) {
            status = fmu.setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0);
        } else if (strcmp(command, "enter") == 0) {
            status = fmu.enter(c);
        } else if (strcmp(command, "exit") == 0) {
            status = fmu.exit_init(c);
        } else if (strcmp(command, "terminate") == 0) {
            status = fmu.terminate(c);
        } else if (strcmp(command, "reset") == 0) {
            status = fmu.reset(c);
        } else if (strcmp(command, "free") == 0) {
            if (saved) fmu.free_state(c, &saved);
            fmu.free_instance(c);
            c = NULL;
            status = fmi2OK;
        } else if (strcmp(command, "real") == 0 && nargs == 2) {
            fmi2ValueReference vr = (fmi2ValueReference)strtoul(args[0], NULL, 10);
            fmi2Real value = strtod(args[1], NULL);
            status = fmu.set_real(c, &vr, 1, &value);
        } else if (strcmp(command, "string") == 0 && nargs == 2) {
            fmi2ValueReference vr = (fmi2ValueReference)strtoul(args[0], NULL, 10);
            fmi2String value = args[1];
            status = fmu.set_string(c, &vr, 1, &value);
        } else if (strcmp(command, "boolean") == 0 && nargs == 2) {
            fmi2ValueReference vr = (fmi2ValueReference)strtoul(args[0], NULL, 10);
            fmi2Boolean value = atoi(args[1]) != 0;
            status = fmu.set_boolean(c, &vr, 1, &value);
        } else if (strcmp(command, "step") == 0 && nargs == 2) {
            status = fmu.do_step(c, strtod(args[0], NULL), strtod(args[1], NULL), fmi2True);
        } else if (strcmp(command, "get_real") == 0 && nargs >= 1 && nargs <= MAX_VRS) {
            fmi2ValueReference vr[MAX_VRS];
            fmi2Real values[MAX_VRS];
            read_vrs(args, nargs, vr);
            status = fmu.get_real(c, vr, nargs, values);
            printf("get_real %d", status);
            for (size_t i = 0; i < nargs; i++) printf(" %.17g", status < fmi2Error ? values[i] : 0.0);
            printf("\n");
            continue;
        } else if (strcmp(command, "replay") == 0) {
            ok = replay(&fmu, c, args, nargs);
            continue;
        } else if (strcmp(command, "save") == 0) {
            fmi2FMUstate state = NULL;
            size_t size = 0;
            status = fmu.get_state(c, &state);
            if (status < fmi2Error) status = worse(status, fmu.state_size(c, state, &size));
            fmi2Byte *bytes = status < fmi2Error ? malloc(size) : NULL;
            if (bytes) status = worse(status, fmu.serialize(c, state, bytes, size));
            if (saved) fmu.free_state(c, &saved);
            if (bytes && status < fmi2Error) status = worse(status, fmu.deserialize(c, bytes, size, &saved));
            free(bytes);
            if (state) fmu.free_state(c, &state);
        } else if (strcmp(command, "restore") == 0) {
            status = fmu.set_state(c, saved);
        } else {
            ok = 0;
        }
        if (ok) printf("%s %d\n", command, status);
    }
    fclose(script);
    if (!ok) {
        fprintf(stderr, "fmi_runner: cannot run the script's line: %s\n", line);
        return 2;
    }
    fflush(stdout);
    return 0;
}
