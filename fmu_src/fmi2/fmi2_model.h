/* fmi2_model.h: what a model gives the FMI 2.0 co-simulation plumbing of this folder, and what it
 * gets from it.
 *
 * The plumbing knows nothing of what a model computes. It holds the instance, the values of the
 * model's variables and the FMI state machine; it checks every call against the FMI 2.0 standard
 * (a call in a state that does not allow it, a value reference of another type, a set the
 * variable's causality and variability forbid: fmi2Error with a log message), saves and
 * serialises FMU states, and logs through the importer's callback. A model file (models/<Name>.c)
 * defines `fmi2_model`: its variables (a table generated from the project's table of FMU
 * variables, systems/fmi/interface/variables.py, into <Name>_variables.h), the size of its own state and its
 * functions: called at fmi2ExitInitializationMode, at each fmi2DoStep, on an FMU state before
 * fmi2SetFMUstate or fmi2DeSerializeFMUstate takes it (fmi2/fmu_state.h), and for the outputs at the start
 * time. */
#ifndef FMI2_MODEL_H
#define FMI2_MODEL_H

#include <stddef.h>

#include "fmi2Functions.h"

/* An Enumeration's value is an fmi2Integer (1 ... its number of items), held among the integers. */
typedef enum { FMI2_REAL, FMI2_INTEGER, FMI2_BOOLEAN, FMI2_STRING, FMI2_ENUMERATION } Fmi2Type;
typedef enum { FMI2_PARAMETER, FMI2_CALCULATED_PARAMETER, FMI2_INPUT, FMI2_OUTPUT, FMI2_LOCAL, FMI2_INDEPENDENT }
    Fmi2Causality;
typedef enum { FMI2_CONSTANT, FMI2_FIXED, FMI2_TUNABLE, FMI2_DISCRETE, FMI2_CONTINUOUS } Fmi2Variability;
typedef enum { FMI2_INITIAL_UNSET, FMI2_EXACT, FMI2_APPROX, FMI2_CALCULATED } Fmi2Initial;

#define FMI2_STRING_SIZE 256   /* bytes a String variable holds, its terminating 0 included */
#define FMI2_MAX_CATEGORIES 32 /* log categories a model may have */

/* One variable of the model description. */
typedef struct {
    const char *name;
    Fmi2Type type;
    Fmi2Causality causality;
    Fmi2Variability variability;
    Fmi2Initial initial;
    size_t index;             /* its place among the values of its type (Fmi2Instance.reals, ...; an
                                 Enumeration's among the integers) */
    double start;             /* the start value of a Real, Integer or Enumeration (whole) or Boolean (0 or 1) */
    const char *start_string; /* the start value of a String; NULL for the other types */
    const char *const *items; /* an Enumeration's item names, of the values 1 ... n_items; NULL for the others */
    size_t n_items;
    size_t fmi3_count;        /* the values FMI 3.0 gets and sets at its value reference: 1 for a scalar; an FMI 3.0
                                 array's size at its first element (its elements are the variables of the value
                                 references that follow), 0 at its other elements (no variable of FMI 3.0's) */
} Fmi2Variable;

typedef struct Fmi2Instance Fmi2Instance;

typedef struct {
    const char *identifier;          /* the model identifier */
    const char *guid;                /* the model description's guid */
    const Fmi2Variable *variables;   /* indexed by value reference, 0 ... n_variables - 1 */
    size_t n_variables;
    size_t n_reals, n_integers, n_booleans, n_strings;
    const char *const *log_categories; /* the model description's LogCategories */
    size_t n_log_categories;
    size_t state_size;               /* bytes of the model's own state: plain data, copied into FMU states */
    /* fmi2ExitInitializationMode: build the model from its parameters. fmi2OK, fmi2Warning, or
     * fmi2Error with a logged message (an invalid parameter). */
    fmi2Status (*initialise)(Fmi2Instance *instance);
    /* fmi2DoStep from t over h seconds (t and h finite, h > 0): inputs read, outputs written; fmi2Error
     * with the model's state and outputs as they were where its arithmetic cannot take the step (its end
     * t + h not finite, an overflow). */
    fmi2Status (*step)(Fmi2Instance *instance, fmi2Real t, fmi2Real h);
    /* An initialised model's state from an FMU state (state_size bytes nobody vouches for), checked
     * against configured: the state initialise makes from the same FMU state's parameters. 0 where
     * every field is in its range and whatever is derived from the parameters is configured's, else
     * -1 with the reason in message (size bytes). It reads the bytes only. */
    int (*validate)(const void *state, const void *configured, char *message, size_t size);
    /* The outputs whose initial is "calculated" (those of a motion or a sensor, which a Jacobi master reads before
     * the first step): their values at the start time (instance->start_time) from the parameters and inputs as
     * they are, written by a model initialise made (its state left as it is). Called at the exit of
     * Initialization Mode and, on a scratch copy of the instance, at each get within it
     * (fmi2/instance.h: fmi2_initialise, fmi2_start_outputs). NULL: the outputs start exact. */
    void (*start)(Fmi2Instance *instance);
} Fmi2Model;

extern const Fmi2Model fmi2_model; /* defined by the model file */

/* An instance as a model sees it: the values of its variables, by Fmi2Variable.index within each
 * type, and its own state, all zero after fmi2Instantiate and fmi2Reset but for the values, which
 * start at their start values. The plumbing's own fields follow (fmi2/instance.h). */
struct Fmi2Instance {
    fmi2Real *reals;
    fmi2Integer *integers;
    fmi2Boolean *booleans;
    char (*strings)[FMI2_STRING_SIZE];
    void *state;
    /* the plumbing's */
    unsigned char *data;      /* one block: reals, integers, booleans, strings, state */
    size_t data_size;
    int phase;                /* Fmi2Phase (fmi2/instance.h) */
    char *name;               /* the instance name, copied */
    fmi2CallbackFunctions callbacks;
    int debug;                /* debug logging on */
    unsigned long categories; /* bit k: category k of log_categories on */
    fmi2Status logged;        /* the most severe status logged during the current call */
    fmi2Real time;            /* FMI 3.0's independent variable `time` (s): the start time, then the end of
                                 each step taken; held in FMU states */
    fmi2Real start_time;      /* the experiment's start time (s; fmi2SetupExperiment, fmi3EnterInitializationMode):
                                 where a sample time's grid begins (timing.h: grid_samples); not held in FMU states */
    void **states;            /* the FMU states this instance made and has not freed (fmi2/fmu_state.h) */
    size_t n_states, states_capacity;
};

/* Log a message (printf format) with the status's category (logStatusWarning, logStatusError, ...):
 * warnings and errors always reach the importer's logger, fmi2OK messages only with debug logging
 * on for the category. The call that logs it returns at least status. */
void fmi2_log(Fmi2Instance *instance, fmi2Status status, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* The item name of the value of the Enumeration held at integers[index], or NULL with an error logged
 * if the value is none of its items' (sets are checked: a restored FMU state is not) or no Enumeration
 * is held there. */
const char *fmi2_item(Fmi2Instance *instance, size_t index);

#endif
