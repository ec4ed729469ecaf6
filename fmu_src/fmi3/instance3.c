/* instance3.c: FMI 3.0 instances on the plumbing's instances (instance3.h). */
#include "instance3.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

#include "fmi2/instance.h"

#define MESSAGE_SIZE 4096

/* the plumbing's logger (FMI 2.0's, whose message is a printf format) passing the message on, formatted,
 * to FMI 3.0's (plain text) */
static void forward(fmi2ComponentEnvironment environment, fmi2String name, fmi2Status status, fmi2String category,
                    fmi2String message, ...) {
    (void)name;
    const Fmi3Context *context = environment;
    char text[MESSAGE_SIZE];
    va_list args;
    va_start(args, message);
    vsnprintf(text, sizeof text, message, args);
    va_end(args);
    /* fmi2OK ... fmi2Fatal and fmi3OK ... fmi3Fatal are the same statuses in the same order */
    context->log_message(context->environment, (fmi3Status)status, category, text);
}

void fmi3_log_to(fmi3InstanceEnvironment environment, fmi3LogMessageCallback log_message, fmi3String name,
                 fmi3Status status, const char *message) {
    (void)name;
    if (log_message) log_message(environment, status, status == fmi3Error ? "logStatusError" : "logCalls", message);
}

Fmi2Instance *fmi3_instance_new(fmi3String name, fmi3Boolean logging_on, fmi3InstanceEnvironment environment,
                                fmi3LogMessageCallback log_message) {
    Fmi3Context *context = malloc(sizeof *context);
    if (!context) {
        fmi3_log_to(environment, log_message, name, fmi3Error, "fmi3InstantiateCoSimulation: out of memory");
        return NULL;
    }
    *context = (Fmi3Context){environment, log_message};
    fmi2CallbackFunctions callbacks = {log_message ? forward : NULL, NULL, NULL, NULL, context};
    Fmi2Instance *instance = fmi2_instance_new(name, &callbacks, logging_on ? fmi2True : fmi2False);
    if (!instance) free(context);
    return instance;
}

Fmi3Context *fmi3_context(Fmi2Instance *instance) { return instance->callbacks.componentEnvironment; }

void fmi3_instance_free(Fmi2Instance *instance) {
    Fmi3Context *context = fmi3_context(instance);
    fmi2_instance_free(instance);
    free(context);
}
