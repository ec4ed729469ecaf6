/* fmi2_guard.c: the FMI 2.0 co-simulation entry points of the project's FMUs.
 *
 * pythonfmu's export library runs the Python model, but it cannot end a call in fmi2Error:
 * a Python exception becomes fmi2Fatal (and corrupts the embedded interpreter), and it
 * passes no log message on unless the importer switched debug logging on. This library is
 * the FMU's binary; it loads pythonfmu's library (PYTHONFMU_LIBRARY, beside it in the same
 * binaries/<platform> folder), forwards every call, and applies the FMI 2.0 meaning of the
 * status codes:
 *
 *   - a call during which the model logged a warning returns at least fmi2Warning, one that
 *     logged an error at least fmi2Error (the model logs, never raises: fmu_support.fail);
 *   - warnings and errors always reach the importer's logger; messages of status fmi2OK only
 *     with debug logging on, filtered by the categories of fmi2SetDebugLogging;
 *   - a call in a phase the standard does not allow it in (fmi2DoStep before initialisation
 *     or after fmi2Terminate, ...), or on a value reference that is not of the call's type
 *     (VARIABLE_TYPES in the resources), is refused with fmi2Error and a message, never
 *     passed on to pythonfmu, which would end it in fmi2Fatal; after an fmi2Fatal only
 *     fmi2FreeInstance is passed on.
 *
 * pythonfmu's library expects the host process to run Python (as fmpy or libcosimpy do).
 * In a host without it (most FMI tools), this library first loads the libpython the FMU
 * was built with (PYTHON_ENVIRONMENT in its resources: the library's path, its soname as a
 * fallback, and the build environment's package folders) and starts the interpreter with
 * those folders on sys.path.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PYTHONFMU_LIBRARY "pythonfmu-export.so"
#define PYTHON_ENVIRONMENT "python_environment.txt" /* lines: libpython path, its soname, sys.path list */
#define VARIABLE_TYPES "variable_types.txt"         /* one line: the type (R, I, B, S) of value reference 0, 1, ... */

/* FMI 2.0 types (fmi2TypesPlatform.h, fmi2FunctionTypes.h) */
typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef void *fmi2FMUstate;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef const char *fmi2String;
typedef char fmi2Byte;
typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef enum { fmi2DoStepStatus, fmi2PendingStatus, fmi2LastSuccessfulTime, fmi2Terminated } fmi2StatusKind;
typedef void (*fmi2CallbackLogger)(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String, ...);
typedef struct {
    fmi2CallbackLogger logger;
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(fmi2ComponentEnvironment, fmi2Status);
    fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

#define EXPORT __attribute__((visibility("default")))

/* FMI 2.0 co-simulation phases a call may come in (a bit each), and what a call needs */
enum { INSTANTIATED = 1, INITIALIZATION = 2, STEPPING = 4, TERMINATED = 8, ANY = 15, SETTABLE = 7 };
#define KEEP 0 /* the phase after a call: unchanged */

/* every entry point: return type, name, parameter list, argument list, the phases it is
 * allowed in, the phase it leads to when it succeeds (KEEP: none), the variable type its
 * value references must have ('R', 'I', 'B', 'S'; 0: none) */
#define FMI2_CALLS(X)                                                                                              \
    X(fmi2Status, fmi2SetupExperiment, (fmi2Component c, fmi2Boolean td, fmi2Real tol, fmi2Real t0, fmi2Boolean sd, \
                                        fmi2Real t1), (c, td, tol, t0, sd, t1), INSTANTIATED, KEEP, NONE)              \
    X(fmi2Status, fmi2EnterInitializationMode, (fmi2Component c), (c), INSTANTIATED, INITIALIZATION, NONE)            \
    X(fmi2Status, fmi2ExitInitializationMode, (fmi2Component c), (c), INITIALIZATION, STEPPING, NONE)                 \
    X(fmi2Status, fmi2Terminate, (fmi2Component c), (c), INITIALIZATION | STEPPING, TERMINATED, NONE)                 \
    X(fmi2Status, fmi2Reset, (fmi2Component c), (c), ANY, INSTANTIATED, NONE)                                         \
    X(fmi2Status, fmi2GetReal, (fmi2Component c, const fmi2ValueReference *vr, size_t n, fmi2Real *v), (c, vr, n, v), \
      ANY, KEEP, TYPED('R'))                                                                                              \
    X(fmi2Status, fmi2GetInteger, (fmi2Component c, const fmi2ValueReference *vr, size_t n, fmi2Integer *v),        \
      (c, vr, n, v), ANY, KEEP, TYPED('I'))                                                                               \
    X(fmi2Status, fmi2GetBoolean, (fmi2Component c, const fmi2ValueReference *vr, size_t n, fmi2Boolean *v),        \
      (c, vr, n, v), ANY, KEEP, TYPED('B'))                                                                               \
    X(fmi2Status, fmi2GetString, (fmi2Component c, const fmi2ValueReference *vr, size_t n, fmi2String *v),          \
      (c, vr, n, v), ANY, KEEP, TYPED('S'))                                                                               \
    X(fmi2Status, fmi2SetReal, (fmi2Component c, const fmi2ValueReference *vr, size_t n, const fmi2Real *v),        \
      (c, vr, n, v), SETTABLE, KEEP, TYPED('R'))                                                                          \
    X(fmi2Status, fmi2SetInteger, (fmi2Component c, const fmi2ValueReference *vr, size_t n, const fmi2Integer *v),  \
      (c, vr, n, v), SETTABLE, KEEP, TYPED('I'))                                                                          \
    X(fmi2Status, fmi2SetBoolean, (fmi2Component c, const fmi2ValueReference *vr, size_t n, const fmi2Boolean *v),  \
      (c, vr, n, v), SETTABLE, KEEP, TYPED('B'))                                                                          \
    X(fmi2Status, fmi2SetString, (fmi2Component c, const fmi2ValueReference *vr, size_t n, const fmi2String *v),    \
      (c, vr, n, v), SETTABLE, KEEP, TYPED('S'))                                                                          \
    X(fmi2Status, fmi2GetFMUstate, (fmi2Component c, fmi2FMUstate *s), (c, s), ANY, KEEP, NONE)                       \
    X(fmi2Status, fmi2SetFMUstate, (fmi2Component c, fmi2FMUstate s), (c, s), ANY, KEEP, NONE)                        \
    X(fmi2Status, fmi2FreeFMUstate, (fmi2Component c, fmi2FMUstate *s), (c, s), ANY, KEEP, NONE)                      \
    X(fmi2Status, fmi2SerializedFMUstateSize, (fmi2Component c, fmi2FMUstate s, size_t *n), (c, s, n), ANY, KEEP, NONE) \
    X(fmi2Status, fmi2SerializeFMUstate, (fmi2Component c, fmi2FMUstate s, fmi2Byte *b, size_t n), (c, s, b, n),   \
      ANY, KEEP, NONE)                                                                                                \
    X(fmi2Status, fmi2DeSerializeFMUstate, (fmi2Component c, const fmi2Byte *b, size_t n, fmi2FMUstate *s),         \
      (c, b, n, s), ANY, KEEP, NONE)                                                                                  \
    X(fmi2Status, fmi2GetDirectionalDerivative, (fmi2Component c, const fmi2ValueReference *u, size_t nu,           \
      const fmi2ValueReference *z, size_t nz, const fmi2Real *du, fmi2Real *dz), (c, u, nu, z, nz, du, dz),       \
      ANY, KEEP, NONE)                                                                                                \
    X(fmi2Status, fmi2SetRealInputDerivatives, (fmi2Component c, const fmi2ValueReference *vr, size_t n,            \
      const fmi2Integer *order, const fmi2Real *v), (c, vr, n, order, v), INITIALIZATION | STEPPING, KEEP, NONE)      \
    X(fmi2Status, fmi2GetRealOutputDerivatives, (fmi2Component c, const fmi2ValueReference *vr, size_t n,           \
      const fmi2Integer *order, fmi2Real *v), (c, vr, n, order, v), STEPPING | TERMINATED, KEEP, NONE)                \
    X(fmi2Status, fmi2DoStep, (fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean keep), (c, t, h, keep),        \
      STEPPING, KEEP, NONE)                                                                                           \
    X(fmi2Status, fmi2CancelStep, (fmi2Component c), (c), STEPPING, KEEP, NONE)                                       \
    X(fmi2Status, fmi2GetStatus, (fmi2Component c, const fmi2StatusKind k, fmi2Status *v), (c, k, v), ANY, KEEP, NONE) \
    X(fmi2Status, fmi2GetRealStatus, (fmi2Component c, const fmi2StatusKind k, fmi2Real *v), (c, k, v), ANY, KEEP,  \
      NONE)                                                                                                           \
    X(fmi2Status, fmi2GetIntegerStatus, (fmi2Component c, const fmi2StatusKind k, fmi2Integer *v), (c, k, v), ANY,  \
      KEEP, NONE)                                                                                                     \
    X(fmi2Status, fmi2GetBooleanStatus, (fmi2Component c, const fmi2StatusKind k, fmi2Boolean *v), (c, k, v), ANY,  \
      KEEP, NONE)                                                                                                     \
    X(fmi2Status, fmi2GetStringStatus, (fmi2Component c, const fmi2StatusKind k, fmi2String *v), (c, k, v), ANY,    \
      KEEP, NONE)
#define TYPED(letter) letter, vr, n /* the value references a call's type applies to */
#define NONE 0, NULL, 0

/* pythonfmu's entry points, loaded once */
static struct {
    fmi2Component (*fmi2Instantiate)(fmi2String, fmi2Type, fmi2String, fmi2String, const fmi2CallbackFunctions *,
                                     fmi2Boolean, fmi2Boolean);
    void (*fmi2FreeInstance)(fmi2Component);
#define MEMBER(ret, name, params, args, phases, next, type) ret(*name) params;
    FMI2_CALLS(MEMBER)
#undef MEMBER
} inner;
static const char *load_error = "not loaded";
static pthread_once_t load_once = PTHREAD_ONCE_INIT;

/* read a line of f into line (without its newline); 0 at the end of the file */
static int read_line(FILE *f, char *line, size_t size) {
    if (!fgets(line, (int)size, f)) return 0;
    line[strcspn(line, "\r\n")] = '\0';
    return 1;
}

/* Python in this process, started from the FMU's record of its build environment if the
 * host has none; NULL, or why not (in message) */
static const char *start_python(const char *binaries, char *message, size_t size) {
    if (dlsym(RTLD_DEFAULT, "Py_IsInitialized")) return NULL; /* the host runs Python: pythonfmu uses it */
    char file[4096], library[4096], soname[256], paths[16384];
    snprintf(file, sizeof file, "%s/../../resources/" PYTHON_ENVIRONMENT, binaries);
    FILE *f = fopen(file, "r");
    if (!f) {
        snprintf(message, size, "no Python in this process, and no %s to start one from", file);
        return message;
    }
    int complete = read_line(f, library, sizeof library) && read_line(f, soname, sizeof soname) &&
                   read_line(f, paths, sizeof paths);
    fclose(f);
    if (!complete) {
        snprintf(message, size, "%s is incomplete", file);
        return message;
    }
    void *py = library[0] ? dlopen(library, RTLD_NOW | RTLD_GLOBAL) : NULL;
    if (!py && soname[0]) py = dlopen(soname, RTLD_NOW | RTLD_GLOBAL);
    if (!py) {
        snprintf(message, size, "no Python in this process, and neither %s nor %s loads (%s): install that Python "
                 "with numpy, scipy and control, or start the importer with its libpython preloaded",
                 library[0] ? library : "(no shared libpython at the build)", soname[0] ? soname : "-", dlerror());
        return message;
    }
    int (*initialized)(void) = (int (*)(void))dlsym(py, "Py_IsInitialized");
    void (*initialize)(int) = (void (*)(int))dlsym(py, "Py_InitializeEx");
    int (*run)(const char *) = (int (*)(const char *))dlsym(py, "PyRun_SimpleString");
    void *(*release)(void) = (void *(*)(void))dlsym(py, "PyEval_SaveThread");
    if (!initialized || !initialize || !run || !release) {
        snprintf(message, size, "%s lacks the Python C API", library[0] ? library : soname);
        return message;
    }
    if (!initialized()) {
        static char code[16500];
        initialize(0);
        snprintf(code, sizeof code, "import sys\nsys.path[:0] = [p for p in %s if p not in sys.path]\n", paths);
        if (run(code) != 0) {
            snprintf(message, size, "cannot put the build environment's packages on sys.path (%s)", file);
            return message;
        }
        release(); /* the GIL: pythonfmu takes it in every call, from whichever thread */
    }
    return NULL;
}

/* the folder of this library (binaries/<platform>) into dir; 0 where it cannot be found */
static int own_folder(char *dir, size_t size) {
    Dl_info self;
    if (!dladdr((void *)&own_folder, &self) || !self.dli_fname) return 0;
    const char *slash = strrchr(self.dli_fname, '/');
    if (slash) snprintf(dir, size, "%.*s", (int)(slash - self.dli_fname), self.dli_fname);
    else snprintf(dir, size, ".");
    return 1;
}

static void load_inner(void) {
    static char path[4096], message[8192];
    char dir[4000];
    if (!own_folder(dir, sizeof dir)) {
        load_error = "cannot locate the FMU's own library";
        return;
    }
    if ((load_error = start_python(dir, message, sizeof message))) return;
    snprintf(path, sizeof path, "%s/" PYTHONFMU_LIBRARY, dir);
    /* never unloaded: pythonfmu finalises its embedded Python when its library goes */
    void *lib = dlopen(path, RTLD_NOW | RTLD_LOCAL | RTLD_NODELETE);
    if (!lib) {
        snprintf(message, sizeof message, "cannot load %s: %s", path, dlerror());
        load_error = message;
        return;
    }
#define LOAD(name)                                                                                                 \
    if (!(*(void **)&inner.name = dlsym(lib, #name))) {                                                            \
        snprintf(message, sizeof message, "%s has no %s", path, #name);                                           \
        load_error = message;                                                                                      \
        return;                                                                                                    \
    }
#define LOAD_CALL(ret, name, params, args, phases, next, type) LOAD(name)
    LOAD(fmi2Instantiate)
    LOAD(fmi2FreeInstance)
    FMI2_CALLS(LOAD_CALL)
#undef LOAD_CALL
#undef LOAD
    /* pythonfmu's library releases its static shared_ptr to its Python state twice when the
     * process exits with it loaded (as RTLD_NODELETE keeps it): exit() first runs the
     * shared_ptr's C++ destructor (registered with __cxa_atexit when the library loaded), which
     * frees the control block, then _dl_fini runs the library's __attribute__((destructor)),
     * finalizePythonInterpreter, whose `pyState = nullptr` decrements the use count inside that
     * freed block: the heap's free list is corrupted, and the next free() that walks it aborts
     * ("free(): corrupted unsorted chunks", in whichever library's destructor frees next: scipy's
     * libgfortran). Handlers registered later run earlier: finalizePythonInterpreter, registered
     * here, releases the state while it is alive, and both of pythonfmu's own releases then find
     * it empty. (A host that unloads this library runs the handler then; pythonfmu's stays.) */
    void (*finalize)(void);
    if ((*(void **)&finalize = dlsym(lib, "finalizePythonInterpreter"))) atexit(finalize);
    load_error = NULL;
}

typedef struct {
    fmi2Component model;           /* pythonfmu's instance */
    fmi2CallbackFunctions user;    /* the importer's callbacks */
    fmi2CallbackFunctions relayed; /* what pythonfmu gets: relay() as logger, this guard as environment */
    fmi2Status logged;             /* the most severe warning or error logged during the current call */
    int debug;                     /* debug logging on (fmi2Instantiate / fmi2SetDebugLogging) */
    size_t n_categories;           /* 0: every category */
    char **categories;
    int phase;                     /* INSTANTIATED, INITIALIZATION, STEPPING or TERMINATED */
    int fatal;                     /* pythonfmu answered fmi2Fatal: only fmi2FreeInstance is passed on */
    char *name;                    /* the instance's name, for messages */
    char *types;                   /* VARIABLE_TYPES: the type of each value reference (NULL: unchecked) */
    size_t n_types;
} Guard;

/* the FMU's VARIABLE_TYPES into g (none: value references are not checked) */
static void read_types(Guard *g) {
    char dir[4000], file[4200];
    if (!own_folder(dir, sizeof dir)) return;
    snprintf(file, sizeof file, "%s/../../resources/" VARIABLE_TYPES, dir);
    FILE *f = fopen(file, "r");
    if (!f) return;
    size_t size = 256, n = 0;
    char *types = malloc(size);
    int ch;
    while (types && (ch = fgetc(f)) != EOF && ch != '\n') {
        if (n == size) {
            char *more = realloc(types, size *= 2);
            if (!more) free(types);
            types = more;
            if (!types) break;
        }
        types[n++] = (char)ch;
    }
    fclose(f);
    g->types = types;
    g->n_types = types ? n : 0;
}

static const char *type_name(char letter) {
    switch (letter) {
    case 'R': return "a Real";
    case 'I': return "an Integer";
    case 'B': return "a Boolean";
    case 'S': return "a String";
    default: return "none";
    }
}

static const char *phase_text(int phase) {
    switch (phase) {
    case INSTANTIATED: return "before initialisation (fmi2EnterInitializationMode)";
    case INITIALIZATION: return "in initialisation mode";
    case STEPPING: return "after initialisation";
    default: return "after fmi2Terminate (fmi2Reset starts the instance again)";
    }
}

static int wanted(const Guard *g, fmi2String category) {
    if (!g->debug) return 0;
    if (g->n_categories == 0) return 1;
    for (size_t i = 0; i < g->n_categories; i++)
        if (category && strcmp(category, g->categories[i]) == 0) return 1;
    return 0;
}

/* pass text on to the importer's logger, which reads the message as a printf format */
static void deliver(const fmi2CallbackFunctions *f, fmi2String name, fmi2Status status, fmi2String category,
                    const char *text) {
    char escaped[8192];
    size_t j = 0;
    for (size_t i = 0; text[i] && j + 2 < sizeof escaped; i++) {
        if (text[i] == '%') escaped[j++] = '%';
        escaped[j++] = text[i];
    }
    escaped[j] = '\0';
    f->logger(f->componentEnvironment, name, status, category, escaped);
}

static void relay(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                  fmi2String message, ...) {
    Guard *g = env;
    int severe = status == fmi2Warning || status == fmi2Error || status == fmi2Fatal;
    if (severe && status > g->logged) g->logged = status;
    if (!g->user.logger || !(severe || wanted(g, category))) return;
    char text[4096];
    va_list args;
    va_start(args, message);
    vsnprintf(text, sizeof text, message ? message : "", args);
    va_end(args);
    deliver(&g->user, name, status, category, text);
}

static void set_categories(Guard *g, size_t n, const fmi2String *categories) {
    for (size_t i = 0; i < g->n_categories; i++) free(g->categories[i]);
    free(g->categories);
    g->categories = n ? calloc(n, sizeof *g->categories) : NULL;
    g->n_categories = g->categories ? n : 0;
    for (size_t i = 0; i < g->n_categories; i++) g->categories[i] = strdup(categories[i] ? categories[i] : "");
}

/* fmi2OK if call may go on to pythonfmu in g's phase with value references vr[0..n) of the
 * type letter (0: no check), else the status it ends with, its reason logged */
static fmi2Status admit(Guard *g, const char *call, int phases, char letter, const fmi2ValueReference *vr, size_t n) {
    char text[512];
    fmi2Status status = fmi2Error;
    if (g->fatal) {
        snprintf(text, sizeof text, "%s refused: the instance ended in fmi2Fatal; only fmi2FreeInstance remains", call);
        status = fmi2Fatal;
    } else if (!(phases & g->phase)) {
        snprintf(text, sizeof text, "%s refused: not allowed %s (FMI 2.0 co-simulation)", call, phase_text(g->phase));
    } else if (letter && n && !vr) {
        snprintf(text, sizeof text, "%s refused: no value references for %zu values", call, n);
    } else {
        for (size_t i = 0; letter && g->types && i < n; i++) {
            char type = vr[i] < g->n_types ? g->types[vr[i]] : 0;
            if (type != letter) {
                if (type) snprintf(text, sizeof text, "%s refused: value reference %u is %s variable, not %s", call,
                                   vr[i], type_name(type), type_name(letter));
                else snprintf(text, sizeof text, "%s refused: value reference %u names no variable", call, vr[i]);
                goto refused;
            }
        }
        return fmi2OK;
    }
refused:
    if (g->user.logger) deliver(&g->user, g->name, status, status == fmi2Fatal ? "logStatusFatal" : "logStatusError",
                                text);
    return status;
}

EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char *fmi2GetVersion(void) { return "2.0"; }

EXPORT fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String guid,
                                     fmi2String resources, const fmi2CallbackFunctions *functions,
                                     fmi2Boolean visible, fmi2Boolean loggingOn) {
    pthread_once(&load_once, load_inner);
    if (load_error) {
        if (functions && functions->logger) deliver(functions, instanceName, fmi2Fatal, "logStatusFatal", load_error);
        return NULL;
    }
    Guard *g = calloc(1, sizeof *g);
    if (!g) return NULL;
    if (functions) g->user = *functions;
    g->relayed = g->user;
    g->relayed.logger = relay;
    g->relayed.componentEnvironment = g;
    g->debug = loggingOn;
    g->phase = INSTANTIATED;
    g->name = strdup(instanceName ? instanceName : "");
    read_types(g);
    /* pythonfmu drops every message without debug logging: it always gets it, relay() filters */
    g->model = inner.fmi2Instantiate(instanceName, fmuType, guid, resources, &g->relayed, visible, 1);
    if (!g->model) {
        free(g->types);
        free(g->name);
        free(g);
        return NULL;
    }
    return g;
}

EXPORT void fmi2FreeInstance(fmi2Component c) {
    Guard *g = c;
    if (!g) return;
    inner.fmi2FreeInstance(g->model);
    set_categories(g, 0, NULL);
    free(g->types);
    free(g->name);
    free(g);
}

EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t n, const fmi2String *categories) {
    Guard *g = c;
    g->debug = loggingOn;
    set_categories(g, n, categories);
    return fmi2OK;
}

#define FORWARD(ret, name, params, args, phases, next, type)                                                     \
    EXPORT ret name params {                                                                                       \
        Guard *g = c;                                                                                              \
        if (!g) return fmi2Error;                                                                                  \
        fmi2Status refused = admit(g, #name, phases, type);                                                        \
        if (refused != fmi2OK) return refused;                                                                     \
        g->logged = fmi2OK;                                                                                        \
        c = g->model;                                                                                              \
        fmi2Status status = inner.name args;                                                                       \
        if (status < g->logged) status = g->logged;                                                                \
        if (status == fmi2Fatal) g->fatal = 1;                                                                     \
        else if (status <= fmi2Warning && next != KEEP) g->phase = next;                                           \
        return status;                                                                                             \
    }
FMI2_CALLS(FORWARD)
#undef FORWARD
