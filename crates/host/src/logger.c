/* The host's FMI 2.0 logger: a C-variadic function, as fmi2CallbackLogger is declared
 * (fmi2FunctionTypes.h), which stable Rust cannot define. It formats the message with
 * vsnprintf into a buffer of the exact size and passes the text to the Rust sink the
 * environment names. Sound on every platform with a C compiler: no calling-convention
 * assumption is made about variadic calls. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

/* The environment the host passes as componentEnvironment (crates/host/src/lib.rs,
 * `LogEnv`, same layout): a fixed-arity Rust function and its data. The sink gets the
 * instance name, status, category, the format as the FMU passed it (so a test can check
 * it) and the formatted text. */
typedef struct {
    void (*sink)(void *data, const char *name, int status, const char *category,
                 const char *fmt, const char *text);
    void *data;
} fxbody_host_env;

void fxbody_host_logger(void *env, const char *name, int status, const char *category,
                        const char *fmt, ...) {
    fxbody_host_env *e = (fxbody_host_env *)env;
    if (e == NULL || e->sink == NULL) {
        return;
    }
    if (fmt == NULL) {
        e->sink(e->data, name, status, category, fmt, "");
        return;
    }
    va_list args;
    va_start(args, fmt);
    va_list measure;
    va_copy(measure, args);
    int n = vsnprintf(NULL, 0, fmt, measure);
    va_end(measure);
    if (n < 0) {
        va_end(args);
        e->sink(e->data, name, status, category, fmt, "(logger: message could not be formatted)");
        return;
    }
    char *text = (char *)malloc((size_t)n + 1);
    if (text == NULL) {
        va_end(args);
        e->sink(e->data, name, status, category, fmt, "(logger: out of memory)");
        return;
    }
    vsnprintf(text, (size_t)n + 1, fmt, args);
    va_end(args);
    e->sink(e->data, name, status, category, fmt, text);
    free(text);
}
