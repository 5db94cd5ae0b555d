/* A careless C master for a packed fxbody FMU, written to run under valgrind (memcheck):
 * every misuse of docs/ROBUSTNESS.md that is defined behaviour in C (NULL component and
 * arrays, illegal states, NaN forces, bad steps, damaged and random serialised states,
 * '%' in the instance name with a logger that really runs vfprintf), then STEPS steps
 * of a varying load with state save / serialise / restore on the way, two instances at
 * once, everything freed, the library unloaded. Exit 0 when every check held; prints
 * the number of checks and the final output.
 *
 * usage: robust_driver LIB RESOURCE_URI GUID VR_IN VR_OUT STEPS [METHOD_VR METHOD]
 */
#include <dlfcn.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fxbody.h"

static int checks = 0, failures = 0, errors_logged = 0;
static int quiet = 1;
static char last_error[4096];

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status,
                   fmi2String category, fmi2String message, ...) {
    char buf[4096];
    va_list ap;
    (void)env;
    if (status >= fmi2Error) errors_logged++;
    /* Real printf formatting: a '%' the library did not escape would misread. */
    va_start(ap, message);
    vsnprintf(buf, sizeof buf, message, ap);
    va_end(ap);
    if (status >= fmi2Error) snprintf(last_error, sizeof last_error, "%s", buf);
    if (!quiet) fprintf(stderr, "[%s] %s: %s\n", category, name, buf);
}

#define EXPECT(cond)                                                               \
    do { checks++; if (!(cond)) { failures++;                                      \
        fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond); } } while (0)

#define LOAD(var, fn)                                                              \
    __typeof__(fn) *var = (__typeof__(fn) *)dlsym(lib, #fn);                       \
    if (!var) { fprintf(stderr, "missing %s\n", #fn); return 2; }

static unsigned long long rng = 0x9e3779b97f4a7c15ULL;
static unsigned long long next_rand(void) {
    rng ^= rng << 13; rng ^= rng >> 7; rng ^= rng << 17; return rng;
}

int main(int argc, char **argv) {
    if (argc < 7) { fprintf(stderr, "usage: %s LIB URI GUID VR_IN VR_OUT STEPS [METHOD_VR METHOD]\n", argv[0]); return 1; }
    if (getenv("ROBUST_VERBOSE")) quiet = 0;
    void *lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) { fprintf(stderr, "dlopen: %s\n", dlerror()); return 2; }
    LOAD(instantiate, fmi2Instantiate);
    LOAD(free_instance, fmi2FreeInstance);
    LOAD(setup, fmi2SetupExperiment);
    LOAD(enter, fmi2EnterInitializationMode);
    LOAD(exit_, fmi2ExitInitializationMode);
    LOAD(terminate, fmi2Terminate);
    LOAD(reset, fmi2Reset);
    LOAD(set_real, fmi2SetReal);
    LOAD(get_real, fmi2GetReal);
    LOAD(set_integer, fmi2SetInteger);
    LOAD(get_integer, fmi2GetInteger);
    LOAD(do_step, fmi2DoStep);
    LOAD(get_state, fmi2GetFMUstate);
    LOAD(set_state, fmi2SetFMUstate);
    LOAD(free_state, fmi2FreeFMUstate);
    LOAD(state_size, fmi2SerializedFMUstateSize);
    LOAD(serialize, fmi2SerializeFMUstate);
    LOAD(deserialize, fmi2DeSerializeFMUstate);
    LOAD(set_debug, fmi2SetDebugLogging);
    LOAD(in_derivs, fmi2SetRealInputDerivatives);
    LOAD(out_derivs, fmi2GetRealOutputDerivatives);
    LOAD(real_status, fmi2GetRealStatus);
    LOAD(dir_deriv, fmi2GetDirectionalDerivative);

    const char *uri = argv[2], *guid = argv[3];
    fmi2ValueReference vin = (fmi2ValueReference)atoi(argv[4]);
    fmi2ValueReference vout = (fmi2ValueReference)atoi(argv[5]);
    int steps = atoi(argv[6]);
    const double h = 1e-4;
    fmi2CallbackFunctions cb = {logger, NULL, NULL, NULL, NULL};
    fmi2CallbackFunctions nolog = {NULL, NULL, NULL, NULL, NULL};
    double v = 0.0, y = 0.0;
    fmi2ValueReference unknown = 4000000000u;
    size_t n = 0;

    /* NULL component everywhere; FreeInstance(NULL) twice. */
    free_instance(NULL);
    free_instance(NULL);
    EXPECT(setup(NULL, 0, 0, 0, 0, 0) == fmi2Error);
    EXPECT(do_step(NULL, 0, h, 1) == fmi2Error);
    EXPECT(set_real(NULL, &vin, 1, &v) == fmi2Error);
    EXPECT(get_real(NULL, &vout, 1, &v) == fmi2Error);
    EXPECT(reset(NULL) == fmi2Error);

    /* Refused instantiations. */
    EXPECT(instantiate(NULL, fmi2CoSimulation, guid, uri, &cb, 0, 0) == NULL);
    EXPECT(instantiate("x", fmi2CoSimulation, "{wrong}", uri, &cb, 0, 0) == NULL);
    EXPECT(instantiate("x", fmi2CoSimulation, guid, "file:///no/such/%zz", &cb, 0, 0) == NULL);
    EXPECT(instantiate("x", fmi2ModelExchange, guid, uri, &cb, 0, 0) == NULL);
    EXPECT(instantiate("x", fmi2CoSimulation, guid, uri, NULL, 0, 0) == NULL);

    /* '%' in the name, debug logging on: every message goes through vsnprintf. */
    fmi2Component c = instantiate("100%s%n%d%%", fmi2CoSimulation, guid, uri, &cb, 0, 1);
    EXPECT(c != NULL);
    if (!c) return 3;
    fmi2Component q = instantiate("quiet", fmi2CoSimulation, guid, uri, &nolog, 0, 1);
    EXPECT(q != NULL);

    /* Illegal calls in Instantiated, each followed by Reset. */
    EXPECT(do_step(c, 0, h, 1) == fmi2Error); EXPECT(reset(c) == fmi2OK);
    EXPECT(exit_(c) == fmi2Error); EXPECT(reset(c) == fmi2OK);
    EXPECT(get_real(c, &vout, 1, &v) == fmi2Error); EXPECT(reset(c) == fmi2OK);
    EXPECT(terminate(c) == fmi2Error); EXPECT(reset(c) == fmi2OK);
    EXPECT(do_step(q, 0, h, 1) == fmi2Error); EXPECT(reset(q) == fmi2OK);
    const char *cats[2] = {"%s%s%s%n", NULL};
    EXPECT(set_debug(c, 1, 1, cats) == fmi2Error); EXPECT(reset(c) == fmi2OK);
    EXPECT(set_debug(c, 1, 2, cats) == fmi2Error); EXPECT(reset(c) == fmi2OK);

    /* Optional METHOD_VR METHOD: choose the integration method of both instances. */
    if (argc >= 9) {
        fmi2ValueReference mvr = (fmi2ValueReference)atoi(argv[7]);
        fmi2Integer method = atoi(argv[8]);
        EXPECT(set_integer(c, &mvr, 1, &method) == fmi2OK);
        EXPECT(set_integer(q, &mvr, 1, &method) == fmi2OK);
    }
    EXPECT(setup(c, 0, 0, 0, 0, 0) == fmi2OK);
    EXPECT(enter(c) == fmi2OK);
    EXPECT(exit_(c) == fmi2OK);
    EXPECT(setup(q, 0, 0, 0, 1, (steps + 1) * h) == fmi2OK);
    EXPECT(enter(q) == fmi2OK);
    EXPECT(exit_(q) == fmi2OK);

    fmi2FMUstate s0 = NULL;
    EXPECT(get_state(c, &s0) == fmi2OK);
    /* Misuse in StepComplete, each recovered from by SetFMUstate. */
    double bad[3] = {NAN, INFINITY, -INFINITY};
    for (int k = 0; k < 3; k++) {
        EXPECT(set_real(c, &vin, 1, &bad[k]) == fmi2Error); EXPECT(set_state(c, s0) == fmi2OK);
        fmi2Integer one = 1;
        EXPECT(in_derivs(c, &vin, 1, &one, &bad[k]) == fmi2Error); EXPECT(set_state(c, s0) == fmi2OK);
        EXPECT(do_step(c, 0, bad[k], 1) == fmi2Error); EXPECT(set_state(c, s0) == fmi2OK);
        EXPECT(do_step(c, bad[k], h, 1) == fmi2Error); EXPECT(set_state(c, s0) == fmi2OK);
    }
    /* Issue 13: a finite but huge load or input rate whose step would be non-finite is
     * refused at doStep, naming the output and the input; the long run below, continued
     * after SetFMUstate, must still equal the Rust solver driven directly. */
    {
        double huge = 1.7976931348623157e308, big_rate = 1e308;
        fmi2Integer one = 1;
        EXPECT(set_real(c, &vin, 1, &huge) == fmi2OK);
        EXPECT(do_step(c, 0, h, 1) == fmi2Error);
        /* Blocked bodies: the step would be non-finite; free bodies may be refused earlier
         * (frame no longer a rotation, step budget): either way the input is named. */
        EXPECT(strstr(last_error, "refused") && strstr(last_error, "= 1.7976931348623157e308"));
        EXPECT(set_state(c, s0) == fmi2OK);
        EXPECT(in_derivs(c, &vin, 1, &one, &big_rate) == fmi2OK);
        EXPECT(do_step(c, 0, h, 1) == fmi2Error);
        EXPECT(strstr(last_error, "refused") && strstr(last_error, "= 1e308"));
        EXPECT(set_state(c, s0) == fmi2OK);
    }
    EXPECT(do_step(c, 0, 0.0, 1) == fmi2Error); EXPECT(set_state(c, s0) == fmi2OK);
    EXPECT(do_step(c, 0, -h, 1) == fmi2Error); EXPECT(set_state(c, s0) == fmi2OK);
    EXPECT(do_step(c, 1.0, h, 1) == fmi2Error); EXPECT(set_state(c, s0) == fmi2OK);
    EXPECT(set_real(c, NULL, 1, &v) == fmi2Error); EXPECT(set_state(c, s0) == fmi2OK);
    EXPECT(set_real(c, &vin, 1, NULL) == fmi2Error); EXPECT(set_state(c, s0) == fmi2OK);
    EXPECT(get_real(c, &vout, 1, NULL) == fmi2Error); EXPECT(set_state(c, s0) == fmi2OK);
    EXPECT(set_real(c, &vout, 1, &v) == fmi2Error); EXPECT(set_state(c, s0) == fmi2OK);
    EXPECT(set_real(c, &unknown, 1, &v) == fmi2Error); EXPECT(set_state(c, s0) == fmi2OK);
    EXPECT(get_integer(c, &unknown, 1, NULL) == fmi2Error); EXPECT(set_state(c, s0) == fmi2OK);
    EXPECT(set_integer(c, &vin, 1, NULL) == fmi2Error); EXPECT(set_state(c, s0) == fmi2OK);
    EXPECT(set_real(c, NULL, 0, NULL) == fmi2OK);
    EXPECT(get_real(c, NULL, 0, NULL) == fmi2OK);
    EXPECT(real_status(c, 99, &v) == fmi2Discard);
    EXPECT(dir_deriv(c, NULL, 0, NULL, 0, NULL, NULL) == fmi2Error); EXPECT(set_state(c, s0) == fmi2OK);
    EXPECT(get_state(c, NULL) == fmi2Error); EXPECT(set_state(c, s0) == fmi2OK);
    EXPECT(set_state(c, NULL) == fmi2Error); EXPECT(set_state(c, s0) == fmi2OK);

    /* Serialise, then feed back truncated, flipped and random bytes. */
    EXPECT(state_size(c, s0, &n) == fmi2OK);
    unsigned char *bytes = malloc(n + 1), *junk = malloc(4096);
    EXPECT(serialize(c, s0, (fmi2Byte *)bytes, n) == fmi2OK);
    EXPECT(serialize(c, s0, (fmi2Byte *)bytes, n + 1) == fmi2Error); EXPECT(set_state(c, s0) == fmi2OK);
    fmi2FMUstate s1 = NULL;
    for (size_t k = 0; k < n; k += 7) {
        EXPECT(deserialize(c, (const fmi2Byte *)bytes, k, &s1) == fmi2Error && s1 == NULL);
        unsigned char keep = bytes[k];
        bytes[k] ^= 0x5a;
        EXPECT(deserialize(c, (const fmi2Byte *)bytes, n, &s1) == fmi2Error && s1 == NULL);
        bytes[k] = keep;
    }
    for (int k = 0; k < 200; k++) {
        size_t len = next_rand() % 4096;
        for (size_t i = 0; i < len; i++) junk[i] = (unsigned char)next_rand();
        if (k % 2 == 0 && len >= 8) memcpy(junk, "FXBSTATE", 8);
        EXPECT(deserialize(c, (const fmi2Byte *)junk, len, &s1) == fmi2Error && s1 == NULL);
    }
    EXPECT(deserialize(c, (const fmi2Byte *)bytes, n, &s1) == fmi2OK && s1 != NULL);
    EXPECT(set_state(c, s1) == fmi2OK);

    /* The long run: two instances side by side, a varying load, a state saved halfway
     * (overwriting s1 in place), serialised and restored into the quiet instance. */
    double t = 0.0, yq = 0.0;
    fmi2Integer one = 1;
    for (int k = 0; k < steps; k++) {
        double f = sin(300.0 * t) + (k % 50 == 0 ? 0.5 : 0.0), rate = 300.0 * cos(300.0 * t);
        EXPECT(set_real(c, &vin, 1, &f) == fmi2OK);
        EXPECT(in_derivs(c, &vin, 1, &one, &rate) == fmi2OK);
        /* The first step may warn once (the explicit method on modes that drag rigid
         * motion, e.g. the truss); every later one is fmi2OK. */
        fmi2Status st = do_step(c, t, h, 1);
        EXPECT(st == fmi2OK || (k == 0 && st == fmi2Warning));
        EXPECT(get_real(c, &vout, 1, &y) == fmi2OK);
        fmi2Integer order = 2;
        EXPECT(out_derivs(c, &vout, 1, &order, &v) == fmi2OK && isfinite(v));
        EXPECT(set_real(q, &vin, 1, &f) == fmi2OK);
        st = do_step(q, t, h, 1);
        EXPECT(st == fmi2OK || (k == 0 && st == fmi2Warning));
        if (k == steps / 2) {
            EXPECT(get_state(c, &s1) == fmi2OK);
            size_t m = 0;
            EXPECT(state_size(c, s1, &m) == fmi2OK);
            unsigned char *b2 = malloc(m);
            EXPECT(serialize(c, s1, (fmi2Byte *)b2, m) == fmi2OK);
            fmi2FMUstate s2 = NULL;
            EXPECT(deserialize(q, (const fmi2Byte *)b2, m, &s2) == fmi2OK);
            free(b2);
            EXPECT(free_state(q, &s2) == fmi2OK && s2 == NULL);
            EXPECT(free_state(q, &s2) == fmi2OK);
        }
        t = (k + 1) * h;
    }
    EXPECT(get_real(q, &vout, 1, &yq) == fmi2OK);
    EXPECT(isfinite(y) && isfinite(yq));
    /* Past stopTime on the quiet instance (stop = (steps + 1) h). */
    EXPECT(do_step(q, t, 2 * h, 1) == fmi2Error);
    EXPECT(terminate(c) == fmi2OK);
    EXPECT(do_step(c, t, h, 1) == fmi2Error);
    EXPECT(free_state(c, &s0) == fmi2OK);
    EXPECT(free_state(c, &s1) == fmi2OK);
    free_instance(c);
    free_instance(q);
    free(bytes);
    free(junk);
    dlclose(lib);
    printf("checks %d failures %d errors_logged %d\n%.17g\n", checks, failures, errors_logged, y);
    return failures == 0 ? 0 : 6;
}
