/* instance3.h: an FMI 3.0 co-simulation instance. It is the plumbing's instance (fmi2/instance.h:
 * the values, the state machine, FMU states and the model's own state, none of which differs
 * between the versions), whose logger forwards to the importer's FMI 3.0 logMessage callback,
 * with the simulation time beside it (FMI 3.0's independent variable). So a model file
 * (models/<Name>.c, against fmi2/fmi2_model.h) runs unchanged under FMI 2.0 and FMI 3.0. */
#ifndef FMI3_INSTANCE3_H
#define FMI3_INSTANCE3_H

#include "fmi3Functions.h"
#include "fmi2/fmi2_model.h"

/* what the FMI 3.0 side keeps beside the plumbing's instance */
typedef struct {
    fmi3InstanceEnvironment environment;
    fmi3LogMessageCallback log_message;
} Fmi3Context;

#define FMI3_TIME_VR ((fmi3ValueReference)fmi2_model.n_variables) /* `time`, after the table's variables */

/* a new instance at its start values, or NULL (logged through log_message) */
Fmi2Instance *fmi3_instance_new(fmi3String name, fmi3Boolean logging_on, fmi3InstanceEnvironment environment,
                                fmi3LogMessageCallback log_message);
void fmi3_instance_free(Fmi2Instance *instance);
Fmi3Context *fmi3_context(Fmi2Instance *instance);
/* log through log_message before an instance exists */
void fmi3_log_to(fmi3InstanceEnvironment environment, fmi3LogMessageCallback log_message, fmi3String name,
                 fmi3Status status, const char *message);

#endif
