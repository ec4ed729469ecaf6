/* fuzz_state.c: a fuzz target of an FMU's state deserialiser, built for one model (the macro
 * AF_MODEL_SOURCE names its file, models/<Name>.c, whose Model struct it reads) with the FMI 2.0
 * plumbing linked in (CMakeLists.txt: fuzz_state_<Name>).
 *
 * An input is one byte, the case, then the bytes of a serialised FMU state. The case picks the
 * configuration (every Enumeration parameter's item and the parameter `latency` cycled through)
 * of an instance initialised and stepped a few times, or (bit 7) an instance only instantiated.
 * The state's header is made to agree with its data as anyone can make it (its configuration hash
 * and checksum recomputed), so that the bytes reach the checks of every field; with bit 6 the
 * forgery is a consistent one: the model's clocks are made to agree with its counts first (a
 * motion's time with the grid cells drawn, the header's time with the steps taken), so a forged
 * count near 2^64 passes every check that compares the two. Then, as an importer
 * would: fmi2DeSerializeFMUstate, fmi2SetFMUstate, ten fmi2DoSteps and fmi2GetReal of every
 * variable. A refused state must leave the instance as it was (its serialised state the same
 * bytes): anything else aborts, as the sanitizers (ASan, UBSan) do on a fault.
 *
 * Built with libFuzzer (clang, CMake option AF_FUZZ) it is LLVMFuzzerTestOneInput; built without
 * (AF_TESTS), main is a driver of its own:
 *   fuzz_state_<Name> --fields                 the fields of the model's state and the variables' values
 *                                              (name, offset in the serialised bytes, type), for
 *                                              tests/test_fmu_state.py
 *   fuzz_state_<Name> --write CASE FILE        a valid input of CASE (its serialised state) into FILE
 *   fuzz_state_<Name> SECONDS SEED FILE...     every FILE (inputs) run, then mutations of them (bytes
 *                                              flipped, fields set to edge values, cut short; half of
 *                                              them consistent forgeries) for SECONDS; prints "runs N
 *                                              refused R taken T". A run of one input longer than
 *                                              CALL_LIMIT seconds ends the driver (SIGALRM): a hang
 *                                              is a finding, as libFuzzer's -timeout makes it. */
#if defined(__unix__) || defined(__APPLE__)
#define _POSIX_C_SOURCE 200809L /* alarm */
#include <unistd.h>
#define HAVE_ALARM 1
#endif
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "fmi2/fmu_state.h"
#include "fmi2/instance.h"

#include AF_MODEL_SOURCE

#define STEP 0.01  /* s: the steps of a case */
#define WARM_UP 25 /* steps before the state is set */
#define STEPS 10   /* steps after */
#define CASE_HUMBLE 0x80 /* bit of the case byte: an instance only instantiated */
#define CASE_AGREE 0x40  /* bit of the case byte: a consistent forgery (agree) */
#define CALL_LIMIT 20    /* s: the longest run of one input the driver waits for */

static void quiet(fmi2ComponentEnvironment environment, fmi2String name, fmi2Status status, fmi2String category,
                  fmi2String message, ...) {
    (void)environment, (void)name, (void)status, (void)category, (void)message;
}

static const fmi2CallbackFunctions CALLBACKS = {quiet, calloc, free, NULL, NULL};

/* the model's inputs at step k: smooth, plausible values (an IMU's, a field's) */
static void set_inputs(fmi2Component c, int k) {
    for (fmi2ValueReference vr = 0; vr < fmi2_model.n_variables; vr++) {
        const Fmi2Variable *v = &fmi2_model.variables[vr];
        if (v->causality != FMI2_INPUT || v->type != FMI2_REAL) continue;
        fmi2Real value = 0.3 * sin(0.05 * k + vr) + (vr % 3 == 2 ? 9.0 : 0.5);
        fmi2SetReal(c, &vr, 1, &value);
    }
}

/* the configuration of case c: each Enumeration parameter's item and `latency` cycled through */
static void configure(fmi2Component c, unsigned which) {
    for (fmi2ValueReference vr = 0; vr < fmi2_model.n_variables; vr++) {
        const Fmi2Variable *v = &fmi2_model.variables[vr];
        if (v->causality != FMI2_PARAMETER) continue;
        if (v->type == FMI2_ENUMERATION && v->n_items > 0) {
            fmi2Integer item = (fmi2Integer)(which % v->n_items) + 1;
            which /= (unsigned)v->n_items;
            fmi2SetInteger(c, &vr, 1, &item);
        } else if (v->type == FMI2_REAL && strcmp(v->name, "latency") == 0) {
            fmi2Real latency = which % 2 ? 0.013 : 0.0;
            which /= 2;
            fmi2SetReal(c, &vr, 1, &latency);
        }
    }
}

/* an instance of the case, initialised and stepped (but for CASE_HUMBLE) */
static fmi2Component instance_of(unsigned char which) {
    fmi2Component c = fmi2Instantiate("fuzz", fmi2CoSimulation, fmi2_model.guid, "", &CALLBACKS, fmi2False, fmi2False);
    if (!c || which & CASE_HUMBLE) return c;
    configure(c, which);
    fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0);
    fmi2EnterInitializationMode(c);
    fmi2ExitInitializationMode(c);
    for (int k = 0; k < WARM_UP; k++) {
        set_inputs(c, k);
        fmi2DoStep(c, k * STEP, STEP, fmi2True);
    }
    return c;
}

/* the instance's serialised state (malloc'd), its size in *size; NULL where it has none */
static fmi2Byte *serialised(fmi2Component c, size_t *size) {
    fmi2FMUstate state = NULL;
    fmi2Byte *bytes = NULL;
    if (fmi2GetFMUstate(c, &state) == fmi2OK && fmi2SerializedFMUstateSize(c, state, size) == fmi2OK &&
        (bytes = malloc(*size)) != NULL && fmi2SerializeFMUstate(c, state, bytes, *size) != fmi2OK) {
        free(bytes);
        bytes = NULL;
    }
    fmi2FreeFMUstate(c, &state);
    return bytes;
}

/* a consistent forgery (CASE_AGREE): the model's clocks set from its counts in the state's data, the
 * header's time with them, as a forger who knows the format would, so only the bounds on the counts
 * themselves stand between a forged count and the loops it drives */
static void agree(Fmi2Instance *view, Fmi2StateHeader *header) {
    Model *model = view->state;
#if defined(AF_MODEL_MotionProfile)
    if (model->human) model->stream.t = (double)model->stream.k * model->stream.grid;
    header->time = model->human ? model->stream.t : header->time;
#elif defined(AF_MODEL_ImuSensor)
    header->time = (double)model->k * model->step_size;
#else
    header->time = model->estimator.state.offset.t;
#endif
}

/* the header of serialised bytes made to agree with their data and the FMU (its guid, which its
 * modelDescription.xml gives anyone), as an attacker would make it: a corpus written by another build
 * of the FMU still reaches the checks of the data; consistent: a consistent forgery (agree) */
static void forge(unsigned char *bytes, size_t size, int consistent) {
    Fmi2StateHeader header;
    if (size < sizeof header) return;
    memcpy(&header, bytes, sizeof header);
    memset(header.guid, 0, sizeof header.guid);
    strncpy(header.guid, fmi2_model.guid, sizeof header.guid - 1);
    Fmi2Instance view;
    memset(&view, 0, sizeof view);
    if (size - sizeof header == fmi2_data_size()) {
        fmi2_instance_bind(&view, bytes + sizeof header);
        if (consistent) agree(&view, &header);
        header.configuration = fmi2_state_configuration(&view);
    }
    header.check = fmi2_state_checksum(bytes + sizeof header, size - sizeof header);
    memcpy(bytes, &header, sizeof header);
}

/* 1 where the state was taken, 0 where refused; aborts where a refusal changed the instance */
static int run_case(const unsigned char *data, size_t size) {
    if (size < 1) return 0;
    fmi2Component c = instance_of(data[0]);
    if (!c) abort();
    size_t n = size - 1, before_size = 0, after_size = 0;
    unsigned char *bytes = malloc(n ? n : 1);
    if (!bytes) abort();
    memcpy(bytes, data + 1, n);
    forge(bytes, n, data[0] & CASE_AGREE);
    fmi2Byte *before = serialised(c, &before_size);
    fmi2FMUstate state = NULL;
    int taken = fmi2DeSerializeFMUstate(c, (const fmi2Byte *)bytes, n, &state) == fmi2OK &&
                fmi2SetFMUstate(c, state) == fmi2OK;
    if (!taken) { /* the instance as it was */
        fmi2Byte *after = serialised(c, &after_size);
        if (!before || !after || before_size != after_size || memcmp(before, after, before_size) != 0) {
            fprintf(stderr, "fuzz_state: a refused state changed the instance\n");
            abort();
        }
        free(after);
    }
    double t = 0.0;
    for (int k = 0; k < STEPS; k++) {
        set_inputs(c, k);
        fmi2DoStep(c, t, STEP, fmi2True);
        t += STEP;
    }
    for (fmi2ValueReference vr = 0; vr < fmi2_model.n_variables; vr++) {
        const Fmi2Variable *v = &fmi2_model.variables[vr];
        fmi2Real real;
        fmi2Integer integer;
        fmi2Boolean boolean;
        fmi2String text;
        switch (v->type) {
        case FMI2_REAL: fmi2GetReal(c, &vr, 1, &real); break;
        case FMI2_BOOLEAN: fmi2GetBoolean(c, &vr, 1, &boolean); break;
        case FMI2_STRING:
            if (fmi2GetString(c, &vr, 1, &text) == fmi2OK && strlen(text) >= FMI2_STRING_SIZE) abort();
            break;
        default: fmi2GetInteger(c, &vr, 1, &integer);
        }
    }
    free(before);
    free(bytes);
    fmi2FreeInstance(c); /* with the state it still holds */
    return taken;
}

#ifdef AF_FUZZ_LIBFUZZER

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size);
int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size) {
    run_case(data, size);
    return 0;
}

#else

/* the fields of the model's own state a test or a mutation aims at: name, offset in Model, type */
typedef enum { F_INT, F_DOUBLE, F_UINT64 } Kind;
typedef struct {
    const char *name;
    size_t offset;
    Kind kind;
} Field;

#define FIELD(name, member, kind) {name, offsetof(Model, member), kind}

static const Field FIELDS[] = {
#if defined(AF_MODEL_AttitudeEstimator)
    FIELD("discretised", estimator.discretised, F_INT),
    FIELD("pipeline.method.method", estimator.pipeline.method.method, F_INT),
    FIELD("pipeline.method.kernel", estimator.pipeline.method.kernel, F_INT),
    FIELD("pipeline.method.filter.n", estimator.pipeline.method.filter.n, F_INT),
    FIELD("pipeline.offset_runs", estimator.pipeline.offset_runs, F_INT),
    FIELD("pipeline.heading_runs", estimator.pipeline.heading_runs, F_INT),
    FIELD("pipeline.point_gyr", estimator.pipeline.point_gyr, F_INT),
    FIELD("pipeline.latency", estimator.pipeline.latency, F_DOUBLE),
    FIELD("step.Ts", estimator.step.Ts, F_DOUBLE),
    FIELD("step.stepper.kernel", estimator.step.stepper.kernel, F_INT),
    FIELD("step.stepper.state_size", estimator.step.stepper.state_size, F_INT),
    FIELD("step.stepper.coef.sensor_frame.n", estimator.step.stepper.coef.sensor_frame.n, F_INT),
    FIELD("step.stepper.coef.sensor_frame.Ad", estimator.step.stepper.coef.sensor_frame.Ad, F_DOUBLE),
    FIELD("state.has_last_gyr", estimator.state.has_last_gyr, F_INT),
    FIELD("state.started", estimator.state.started, F_INT),
    FIELD("state.last_gyr", estimator.state.last_gyr, F_DOUBLE),
    FIELD("state.offset.t", estimator.state.offset.t, F_DOUBLE),
    FIELD("state.method", estimator.state.method, F_DOUBLE),
    FIELD("state.heading.steps", estimator.state.heading.steps, F_DOUBLE),
    FIELD("state.heading.hard_iron.fit_steps", estimator.state.heading.hard_iron.fit_steps, F_DOUBLE),
    FIELD("quat", estimator.quat, F_DOUBLE),
    FIELD("mag_delay", estimator.mag_delay, F_DOUBLE),
#elif defined(AF_MODEL_ImuSensor)
    FIELD("params.latency", params.latency, F_DOUBLE),
    FIELD("params.delta_n", params.delta_n, F_DOUBLE),
    FIELD("seed", seed, F_UINT64),
    FIELD("k", k, F_UINT64),
    FIELD("step_size", step_size, F_DOUBLE),
    FIELD("delay.latency", delay.latency, F_DOUBLE),
    FIELD("delay.fs", delay.fs, F_DOUBLE),
    FIELD("delay.rows", delay.rows, F_INT),
    FIELD("delay.head", delay.head, F_INT),
    FIELD("delay.x", delay.x, F_DOUBLE),
#elif defined(AF_MODEL_MotionProfile)
    FIELD("human", human, F_INT),
    FIELD("stream.params.delta_v", stream.params.delta_v, F_DOUBLE),
    FIELD("stream.seed", stream.seed, F_UINT64),
    FIELD("stream.k", stream.k, F_UINT64),
    FIELD("stream.grid", stream.grid, F_DOUBLE),
    FIELD("stream.coef", stream.coef, F_DOUBLE),
    FIELD("stream.state", stream.state, F_DOUBLE),
    FIELD("stream.q0", stream.q0, F_DOUBLE),
    FIELD("stream.t", stream.t, F_DOUBLE),
    FIELD("closed.profile", closed.profile, F_INT),
    FIELD("closed.p", closed.p, F_DOUBLE),
    FIELD("closed.g", closed.g, F_DOUBLE),
#endif
};
#define N_FIELDS (sizeof FIELDS / sizeof *FIELDS)

static const char *const KIND_NAMES[] = {"int32", "float64", "uint64"};

/* where the model's state starts in serialised bytes */
static size_t state_offset(void) {
    Fmi2Instance view;
    unsigned char *data = calloc(1, fmi2_data_size());
    if (!data) abort();
    fmi2_instance_bind(&view, data);
    size_t offset = sizeof(Fmi2StateHeader) + (size_t)((unsigned char *)view.state - data);
    free(data);
    return offset;
}

/* the offset in serialised bytes of every variable's value, and its type */
static void print_values(void) {
    static const char *const TYPES[] = {"float64", "int32", "bool", "string", "enumeration"};
    Fmi2Instance view;
    unsigned char *data = calloc(1, fmi2_data_size());
    if (!data) abort();
    fmi2_instance_bind(&view, data);
    for (size_t vr = 0; vr < fmi2_model.n_variables; vr++) {
        const Fmi2Variable *v = &fmi2_model.variables[vr];
        const void *at = v->type == FMI2_REAL      ? (const void *)&view.reals[v->index]
                         : v->type == FMI2_BOOLEAN ? (const void *)&view.booleans[v->index]
                         : v->type == FMI2_STRING  ? (const void *)view.strings[v->index]
                                                   : (const void *)&view.integers[v->index];
        printf("value %s %lu %s\n", v->name,
               (unsigned long)(sizeof(Fmi2StateHeader) + (size_t)((const unsigned char *)at - data)), TYPES[v->type]);
    }
    free(data);
}

static int print_fields(void) {
    size_t at = state_offset();
    printf("header %lu\nsize %lu\n", (unsigned long)sizeof(Fmi2StateHeader),
           (unsigned long)(sizeof(Fmi2StateHeader) + fmi2_data_size()));
    print_values();
    for (size_t i = 0; i < N_FIELDS; i++)
        printf("field %s %lu %s\n", FIELDS[i].name, (unsigned long)(at + FIELDS[i].offset),
               KIND_NAMES[FIELDS[i].kind]);
    return 0;
}

static int write_case(unsigned which, const char *path) {
    fmi2Component c = instance_of((unsigned char)which);
    size_t size = 0;
    fmi2Byte *bytes = c ? serialised(c, &size) : NULL;
    FILE *file = bytes ? fopen(path, "wb") : NULL;
    unsigned char head = (unsigned char)which;
    int ok = file && fwrite(&head, 1, 1, file) == 1 && fwrite(bytes, 1, size, file) == size;
    if (file) fclose(file);
    free(bytes);
    if (c) fmi2FreeInstance(c);
    return ok ? 0 : 1;
}

static unsigned long long next(unsigned long long *seed) { /* splitmix64 */
    unsigned long long z = (*seed += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* an edge value of the field's kind, or a random one */
static void set_field(unsigned char *bytes, size_t size, const Field *f, size_t at, unsigned long long *seed) {
    static const int INTS[] = {-1, 0, 1, 2, 5, 6, 7, 1023, 1024, 1025, 2147483647, -2147483647 - 1};
    static const double DOUBLES[] = {0.0, -0.0, -1.0, 1e-310, 1e300, -1e300, 2.0, 0.5};
    unsigned long long r = next(seed);
    size_t place = 1 + at + f->offset + (f->kind == F_INT ? 0 : 8 * (r >> 40 & 3)); /* an element of an array */
    unsigned char value[8];
    size_t width = f->kind == F_INT ? 4 : 8;
    if (f->kind == F_INT) {
        int v = r & 1 ? INTS[r / 2 % (sizeof INTS / sizeof *INTS)] : (int)(unsigned)(r >> 8);
        memcpy(value, &v, 4);
    } else if (f->kind == F_DOUBLE) {
        double v = r % 4 == 0 ? NAN : r % 4 == 1 ? INFINITY : DOUBLES[r / 4 % (sizeof DOUBLES / sizeof *DOUBLES)];
        memcpy(value, &v, 8);
    } else {
        unsigned long long v = r & 1 ? ~0ull >> (r % 64) : r;
        memcpy(value, &v, 8);
    }
    if (place + width <= size) memcpy(bytes + place, value, width);
}

/* run_case within CALL_LIMIT seconds: SIGALRM's default action ends the driver where it hangs */
static int timed_case(const unsigned char *data, size_t size) {
#ifdef HAVE_ALARM
    alarm(CALL_LIMIT);
#endif
    int taken = run_case(data, size);
#ifdef HAVE_ALARM
    alarm(0);
#endif
    return taken;
}

static int fuzz(double seconds, unsigned long long seed, int n, char **paths) {
    unsigned char *inputs[64];
    size_t sizes[64];
    int count = 0;
    for (int i = 0; i < n && count < 64; i++) {
        FILE *file = fopen(paths[i], "rb");
        if (!file) continue;
        unsigned char buffer[1 << 17];
        size_t size = fread(buffer, 1, sizeof buffer, file);
        fclose(file);
        if (!(inputs[count] = malloc(size ? size : 1))) abort();
        memcpy(inputs[count], buffer, size);
        sizes[count++] = size;
    }
    if (count == 0) {
        fprintf(stderr, "fuzz_state: no input read\n");
        return 2;
    }
    size_t at = state_offset();
    unsigned long runs = 0, taken = 0;
    for (int i = 0; i < count; i++, runs++) taken += (unsigned long)timed_case(inputs[i], sizes[i]);
    clock_t end = clock() + (clock_t)(seconds * CLOCKS_PER_SEC);
    while (clock() < end) {
        unsigned long long r = next(&seed);
        int from = (int)(r % (unsigned long long)count);
        size_t size = sizes[from];
        unsigned char *bytes = malloc(size ? size : 1);
        if (!bytes) abort();
        memcpy(bytes, inputs[from], size);
        switch (r >> 32 & 3) {
        case 0: /* bytes flipped anywhere */
            for (int k = 0; k < 1 + (int)(r >> 40 & 7); k++)
                bytes[next(&seed) % size] ^= (unsigned char)(1u << (r >> 50 & 7));
            break;
        case 1: /* a field set to an edge or random value */
        case 2:
            if (N_FIELDS > 0) set_field(bytes, size, &FIELDS[next(&seed) % N_FIELDS], at, &seed);
            break;
        default: /* cut short, or the case changed */
            if (r >> 40 & 1) size = next(&seed) % size;
            else bytes[0] = (unsigned char)next(&seed);
        }
        if (size > 0) bytes[0] = (unsigned char)(r >> 63 ? bytes[0] | CASE_AGREE : bytes[0] & ~CASE_AGREE);
        taken += (unsigned long)timed_case(bytes, size);
        runs++;
        free(bytes);
    }
    for (int i = 0; i < count; i++) free(inputs[i]);
    printf("runs %lu refused %lu taken %lu\n", runs, runs - taken, taken);
    return 0;
}

int main(int argc, char **argv) {
    if (argc == 2 && strcmp(argv[1], "--fields") == 0) return print_fields();
    if (argc == 4 && strcmp(argv[1], "--write") == 0) return write_case((unsigned)strtoul(argv[2], NULL, 0), argv[3]);
    if (argc >= 4) return fuzz(strtod(argv[1], NULL), strtoull(argv[2], NULL, 0), argc - 3, argv + 3);
    fprintf(stderr, "usage: %s --fields | --write CASE FILE | SECONDS SEED FILE...\n", argv[0]);
    return 2;
}

#endif
