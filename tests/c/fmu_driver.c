/* A C master for a packed fxbody FMU: includes the generated header, loads the FMU's
 * library with dlopen, checks all 34 FMI 2.0 co-simulation exports are there, runs
 * instantiate, setup, init, then N x (setReal force, doStep), getReal, free, and prints
 * the final output value. Built and run by tests/all/fmi/c_master.rs (and timed by the benchmark).
 *
 * usage: fmu_driver LIB RESOURCE_URI GUID VR_IN VR_OUT STEPS H FORCE [bench]
 */
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <time.h>

#include "fxbody.h"
#include "driver.h"

static const char *NAMES[34] = {
    "fmi2GetTypesPlatform", "fmi2GetVersion", "fmi2SetDebugLogging", "fmi2Instantiate",
    "fmi2FreeInstance", "fmi2SetupExperiment", "fmi2EnterInitializationMode",
    "fmi2ExitInitializationMode", "fmi2Terminate", "fmi2Reset", "fmi2GetReal", "fmi2GetInteger",
    "fmi2GetBoolean", "fmi2GetString", "fmi2SetReal", "fmi2SetInteger", "fmi2SetBoolean",
    "fmi2SetString", "fmi2GetFMUstate", "fmi2SetFMUstate", "fmi2FreeFMUstate",
    "fmi2SerializedFMUstateSize", "fmi2SerializeFMUstate", "fmi2DeSerializeFMUstate",
    "fmi2GetDirectionalDerivative", "fmi2SetRealInputDerivatives", "fmi2GetRealOutputDerivatives",
    "fmi2DoStep", "fmi2CancelStep", "fmi2GetStatus", "fmi2GetRealStatus", "fmi2GetIntegerStatus",
    "fmi2GetBooleanStatus", "fmi2GetStringStatus"};

static int n_errors_logged = 0;

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status,
                   fmi2String category, fmi2String message, ...) {
    va_list ap;
    (void)env;
    if (status >= fmi2Error) n_errors_logged++;
    fprintf(stderr, "[%s] %s: ", category, name);
    va_start(ap, message);
    vfprintf(stderr, message, ap);
    va_end(ap);
    fputc('\n', stderr);
}

int main(int argc, char **argv) {
    if (argc < 9) { fprintf(stderr, "usage: %s LIB URI GUID VR_IN VR_OUT STEPS H FORCE [bench]\n", argv[0]); return 1; }
    void *lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) { fprintf(stderr, "dlopen: %s\n", dlerror()); return 2; }
    for (int k = 0; k < 34; k++)
        if (!dlsym(lib, NAMES[k])) { fprintf(stderr, "missing export %s\n", NAMES[k]); return 2; }
    LOAD(instantiate, fmi2Instantiate);
    LOAD(setup, fmi2SetupExperiment);
    LOAD(enter, fmi2EnterInitializationMode);
    LOAD(exit_, fmi2ExitInitializationMode);
    LOAD(set_real, fmi2SetReal);
    LOAD(get_real, fmi2GetReal);
    LOAD(do_step, fmi2DoStep);
    LOAD(reset, fmi2Reset);
    LOAD(free_instance, fmi2FreeInstance);
    LOAD(version, fmi2GetVersion);

    if (strcmp(version(), "2.0") != 0) { fprintf(stderr, "version %s\n", version()); return 4; }
    fmi2CallbackFunctions cb = {logger, NULL, NULL, NULL, NULL};
    fmi2ValueReference vr_in = (fmi2ValueReference)atoi(argv[4]);
    fmi2ValueReference vr_out = (fmi2ValueReference)atoi(argv[5]);
    int steps = atoi(argv[6]);
    double h = atof(argv[7]), force = atof(argv[8]);
    int bench = argc > 9;

    free_instance(NULL); /* ignored by the standard */
    fmi2Component c = instantiate("driver", fmi2CoSimulation, argv[3], argv[2], &cb, fmi2False, fmi2False);
    if (!c) { fprintf(stderr, "instantiate failed\n"); return 3; }

    /* An illegal call first: an error, logged, and the instance recovers by Reset. */
    if (do_step(c, 0.0, h, fmi2True) != fmi2Error || n_errors_logged != 1) { fprintf(stderr, "illegal doStep not refused\n"); return 5; }
    CHECK(reset(c));

    CHECK(setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0));
    CHECK(enter(c));
    CHECK(exit_(c));
    double y = 0.0, t = 0.0;
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (int k = 0; k < steps; k++) {
        /* Bench mode: a load that changes every step, as in a coupled run. */
        double f = bench ? force * sin(1e-3 * k) : force;
        CHECK(set_real(c, &vr_in, 1, &f));
        CHECK(do_step(c, t, h, fmi2True));
        t = (k + 1) * h;
        if (bench) CHECK(get_real(c, &vr_out, 1, &y));
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    CHECK(get_real(c, &vr_out, 1, &y));
    free_instance(c);
    double ns = ((t1.tv_sec - t0.tv_sec) * 1e9 + (t1.tv_nsec - t0.tv_nsec)) / steps;
    printf("%.17g\n", y);
    if (bench) printf("ns_per_step %.1f\n", ns);
    dlclose(lib);
    return 0;
}
