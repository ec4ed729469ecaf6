/* fmi_runner.c: an FMI 2.0 and FMI 3.0 co-simulation importer with no Python in its process, as most
 * FMI tools are, driven by a script (tests/test_native_fmu.py; built for Linux, macOS and Windows, it runs
 * the other platforms' binaries in tests/test_platforms.py). Usage: fmi_runner SCRIPT
 *
 * One command a line; each FMI call prints "<command> <status>" on stdout, the logger's messages
 * go to stderr as "[<status> <category>] <message>". Commands:
 *   load BINARY                   dlopen the FMU's shared library (the rest of the line) and find its functions
 *   load3 BINARY                  the same for an FMI 3.0 FMU: the commands below then make the FMI 3.0 calls
 *                                 (instantiate: fmi3InstantiateCoSimulation, its URI a resource path; enter
 *                                 with no tolerance, start 0, no stop time; real: fmi3SetFloat64; step, get_real,
 *                                 replay: fmi3DoStep, fmi3GetFloat64, fmi3GetBoolean; exit, terminate, free, unload);
 *                                 the others are FMI 2.0's only
 *   instantiate GUID URI LOGGING  fmi2Instantiate (co-simulation; LOGGING 0 or 1)
 *   setup | enter | exit | terminate | reset | free
 *   real VR VALUE | integer VR VALUE | string VR TEXT | boolean VR 0|1
 *                                 one fmi2Set* (an Enumeration's VALUE by integer; TEXT without spaces)
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
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2FunctionTypes.h"
#include "fmi3FunctionTypes.h"

#ifdef _WIN32
#include <windows.h>
typedef HMODULE Library;
static Library open_library(const char *path) { return LoadLibraryA(path); }
static void *find_symbol(Library library, const char *name) { return (void *)GetProcAddress(library, name); }
static void close_library(Library library) { FreeLibrary(library); }
static void report_library_error(const char *path) {
    fprintf(stderr, "LoadLibrary %s: error %lu\n", path, (unsigned long)GetLastError());
}
#else
#include <dlfcn.h>
typedef void *Library;
static Library open_library(const char *path) { return dlopen(path, RTLD_NOW | RTLD_LOCAL); }
static void *find_symbol(Library library, const char *name) { return dlsym(library, name); }
static void close_library(Library library) { dlclose(library); }
static void report_library_error(const char *path) { fprintf(stderr, "dlopen %s: %s\n", path, dlerror()); }
#endif

#define MAX_VRS 128

typedef struct {
    Library library;
    int version; /* 2 or 3: the FMI version of the functions found */
    fmi2InstantiateTYPE *instantiate;
    fmi2FreeInstanceTYPE *free_instance;
    fmi2SetupExperimentTYPE *setup;
    fmi2EnterInitializationModeTYPE *enter;
    fmi2ExitInitializationModeTYPE *exit_init;
    fmi2TerminateTYPE *terminate;
    fmi2ResetTYPE *reset;
    fmi2SetRealTYPE *set_real;
    fmi2SetIntegerTYPE *set_integer;
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
    fmi3InstantiateCoSimulationTYPE *instantiate3;
    fmi3FreeInstanceTYPE *free_instance3;
    fmi3EnterInitializationModeTYPE *enter3;
    fmi3ExitInitializationModeTYPE *exit_init3;
    fmi3TerminateTYPE *terminate3;
    fmi3SetFloat64TYPE *set_float64;
    fmi3GetFloat64TYPE *get_float64;
    fmi3GetBooleanTYPE *get_boolean3;
    fmi3DoStepTYPE *do_step3;
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

static void logger3(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message) {
    (void)env;
    fprintf(stderr, "[%d %s] %s\n", (int)status, category, message);
}

static const fmi2CallbackFunctions CALLBACKS = {logger, calloc, free, NULL, NULL};

/* the library at path opened, and its functions of FMI version (2 or 3) found; 0 where one is missing */
static int load(Fmu *fmu, const char *path, int version) {
    fmu->library = open_library(path);
    fmu->version = version;
    if (!fmu->library) {
        report_library_error(path);
        return 0;
    }
#define FIND(field, name)                                                                                          \
    if (!(*(void **)(&fmu->field) = find_symbol(fmu->library, name))) {                                            \
        fprintf(stderr, "no %s in %s\n", name, path);                                                              \
        return 0;                                                                                                  \
    }
    if (version == 3) {
        FIND(instantiate3, "fmi3InstantiateCoSimulation") FIND(free_instance3, "fmi3FreeInstance")
        FIND(enter3, "fmi3EnterInitializationMode") FIND(exit_init3, "fmi3ExitInitializationMode")
        FIND(terminate3, "fmi3Terminate") FIND(set_float64, "fmi3SetFloat64") FIND(get_float64, "fmi3GetFloat64")
        FIND(get_boolean3, "fmi3GetBoolean") FIND(do_step3, "fmi3DoStep")
        return 1;
    }
    FIND(instantiate, "fmi2Instantiate") FIND(free_instance, "fmi2FreeInstance")
    FIND(setup, "fmi2SetupExperiment") FIND(enter, "fmi2EnterInitializationMode")
    FIND(exit_init, "fmi2ExitInitializationMode") FIND(terminate, "fmi2Terminate") FIND(reset, "fmi2Reset")
    FIND(set_real, "fmi2SetReal") FIND(set_integer, "fmi2SetInteger")
    FIND(set_string, "fmi2SetString") FIND(set_boolean, "fmi2SetBoolean")
    FIND(get_real, "fmi2GetReal") FIND(get_boolean, "fmi2GetBoolean") FIND(do_step, "fmi2DoStep")
    FIND(get_state, "fmi2GetFMUstate") FIND(set_state, "fmi2SetFMUstate") FIND(free_state, "fmi2FreeFMUstate")
    FIND(state_size, "fmi2SerializedFMUstateSize") FIND(serialize, "fmi2SerializeFMUstate")
    FIND(deserialize, "fmi2DeSerializeFMUstate")
#undef FIND
    return 1;
}

/* The calls both versions make, as FMI 2.0's (fmi3Status has fmi2Status's first five values) */
static fmi2Status set_reals(const Fmu *fmu, void *c, const fmi2ValueReference vr[], size_t n, const double values[]) {
    return fmu->version == 3 ? (fmi2Status)fmu->set_float64(c, vr, n, values, n) : fmu->set_real(c, vr, n, values);
}

static fmi2Status get_reals(const Fmu *fmu, void *c, const fmi2ValueReference vr[], size_t n, double values[]) {
    return fmu->version == 3 ? (fmi2Status)fmu->get_float64(c, vr, n, values, n) : fmu->get_real(c, vr, n, values);
}

static fmi2Status get_booleans(const Fmu *fmu, void *c, const fmi2ValueReference vr[], size_t n, double values[]) {
    fmi2Boolean flags[MAX_VRS];
    fmi3Boolean flags3[MAX_VRS];
    fmi2Status status = fmu->version == 3 ? (fmi2Status)fmu->get_boolean3(c, vr, n, flags3, n)
                                          : fmu->get_boolean(c, vr, n, flags);
    for (size_t i = 0; i < n; i++) values[i] = fmu->version == 3 ? flags3[i] : flags[i] != fmi2False;
    return status;
}

static fmi2Status do_step(const Fmu *fmu, void *c, double t, double h) {
    if (fmu->version == 2) return fmu->do_step(c, t, h, fmi2True);
    fmi3Boolean event = fmi3False, terminate = fmi3False, early = fmi3False;
    fmi3Float64 last = t;
    return (fmi2Status)fmu->do_step3(c, t, h, fmi3True, &event, &terminate, &early, &last);
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
static int replay(const Fmu *fmu, void *c, char **tokens, size_t count) {
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
    double row[2 + MAX_VRS], result[1 + 2 * MAX_VRS], values[MAX_VRS], flags[MAX_VRS];
    size_t rows = 0;
    fmi2Status worst = fmi2OK;
    while (fread(row, sizeof(double), 2 + ni, source) == 2 + ni) {
        fmi2Status status = set_reals(fmu, c, in, ni, row + 2);
        if (status < fmi2Error) status = worse(status, do_step(fmu, c, row[0], row[1]));
        result[0] = status;
        if (status < fmi2Error &&
            (get_reals(fmu, c, out, no, values) > fmi2Warning || get_booleans(fmu, c, bools, nb, flags) > fmi2Warning))
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
    printf("replay %lu %d\n", (unsigned long)rows, (int)worst);
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
        int load_version = strncmp(line, "load ", 5) == 0 ? 2 : strncmp(line, "load3 ", 6) == 0 ? 3 : 0;
        if (load_version) { /* a path may hold spaces */
            strcpy(path, line + 3 + load_version);
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
        if (load_version && nargs >= 1) {
            ok = load(&fmu, path, load_version);
            continue;
        } else if (!fmu.library) {
            ok = 0;
        } else if (strcmp(command, "instantiate") == 0 && nargs == 3) {
            c = fmu.version == 3 ? fmu.instantiate3("runner", args[0], args[1], fmi3False, atoi(args[2]) != 0, fmi3False,
                                                    fmi3False, NULL, 0, NULL, logger3, NULL)
                                 : fmu.instantiate("runner", fmi2CoSimulation, args[0], args[1], &CALLBACKS, fmi2False,
                                                   atoi(args[2]));
            status = c ? fmi2OK : fmi2Error;
        } else if (strcmp(command, "unload") == 0) {
            if (saved && c) fmu.free_state(c, &saved);
            close_library(fmu.library);
            fmu.library = NULL;
            continue;
        } else if (fmu.version == 2 && strcmp(command, "cycles") == 0 && nargs == 4) {
            status = cycles(&fmu, atol(args[0]), args[1], args[2], atof(args[3]));
        } else if (!c) {
            ok = 0;
        } else if (fmu.version == 2 && strcmp(command, "setup") == 0) {
            status = fmu.setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0);
        } else if (strcmp(command, "enter") == 0) {
            status = fmu.version == 3 ? fmu.enter3(c, fmi3False, 0.0, 0.0, fmi3False, 0.0) : fmu.enter(c);
        } else if (strcmp(command, "exit") == 0) {
            status = fmu.version == 3 ? fmu.exit_init3(c) : fmu.exit_init(c);
        } else if (strcmp(command, "terminate") == 0) {
            status = fmu.version == 3 ? fmu.terminate3(c) : fmu.terminate(c);
        } else if (fmu.version == 2 && strcmp(command, "reset") == 0) {
            status = fmu.reset(c);
        } else if (strcmp(command, "free") == 0) {
            if (saved) fmu.free_state(c, &saved);
            if (fmu.version == 3) fmu.free_instance3(c);
            else fmu.free_instance(c);
            c = NULL;
            status = fmi2OK;
        } else if (strcmp(command, "real") == 0 && nargs == 2) {
            fmi2ValueReference vr = (fmi2ValueReference)strtoul(args[0], NULL, 10);
            fmi2Real value = strtod(args[1], NULL);
            status = set_reals(&fmu, c, &vr, 1, &value);
        } else if (fmu.version == 2 && strcmp(command, "integer") == 0 && nargs == 2) {
            fmi2ValueReference vr = (fmi2ValueReference)strtoul(args[0], NULL, 10);
            fmi2Integer value = (fmi2Integer)strtol(args[1], NULL, 10);
            status = fmu.set_integer(c, &vr, 1, &value);
        } else if (fmu.version == 2 && strcmp(command, "string") == 0 && nargs == 2) {
            fmi2ValueReference vr = (fmi2ValueReference)strtoul(args[0], NULL, 10);
            fmi2String value = args[1];
            status = fmu.set_string(c, &vr, 1, &value);
        } else if (fmu.version == 2 && strcmp(command, "boolean") == 0 && nargs == 2) {
            fmi2ValueReference vr = (fmi2ValueReference)strtoul(args[0], NULL, 10);
            fmi2Boolean value = atoi(args[1]) != 0;
            status = fmu.set_boolean(c, &vr, 1, &value);
        } else if (strcmp(command, "step") == 0 && nargs == 2) {
            status = do_step(&fmu, c, strtod(args[0], NULL), strtod(args[1], NULL));
        } else if (strcmp(command, "get_real") == 0 && nargs >= 1 && nargs <= MAX_VRS) {
            fmi2ValueReference vr[MAX_VRS];
            fmi2Real values[MAX_VRS];
            read_vrs(args, nargs, vr);
            status = get_reals(&fmu, c, vr, nargs, values);
            printf("get_real %d", status);
            for (size_t i = 0; i < nargs; i++) printf(" %.17g", status < fmi2Error ? values[i] : 0.0);
            printf("\n");
            continue;
        } else if (strcmp(command, "replay") == 0) {
            ok = replay(&fmu, c, args, nargs);
            continue;
        } else if (fmu.version == 2 && strcmp(command, "save") == 0) {
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
        } else if (fmu.version == 2 && strcmp(command, "restore") == 0) {
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
