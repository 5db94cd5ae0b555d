/* An FMI 3.0 co-simulation master in C for a packed fxbody FMU (`pack --fmi 3`), the
 * counterpart of fmu_driver.c: includes the generated header (whose fmi3 declarations
 * follow the FMI 3.0 standard's fmi3FunctionTypes.h), loads the FMU's library with
 * dlopen, checks the FMI 3.0 co-simulation exports are there, refuses an illegal call
 * and recovers by fmi3Reset, then fmi3InstantiateCoSimulation, fmi3EnterInitialization
 * Mode, fmi3ExitInitializationMode, N x (fmi3SetFloat64 force, fmi3DoStep), fmi3GetFloat64,
 * fmi3Terminate, fmi3FreeInstance, and prints the final output value. Built and run by
 * tests/all/fmi/c_master.rs, which compares its output with fmu_driver.c's on the FMI 2.0
 * FMU of the same body, bit for bit.
 *
 * usage: fmu3_driver LIB RESOURCE_PATH TOKEN VR_IN VR_OUT STEPS H FORCE
 * (RESOURCE_PATH: the resources folder as an absolute path with a trailing separator,
 * as FMI 3.0 passes it; TOKEN: the model description's instantiationToken.)
 */
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fxbody.h"
#include "driver.h"

/* The FMI 3.0 co-simulation functions a master calls (standard, section 4). */
static const char *NAMES[] = {
    "fmi3GetVersion", "fmi3SetDebugLogging", "fmi3InstantiateCoSimulation",
    "fmi3FreeInstance", "fmi3EnterInitializationMode", "fmi3ExitInitializationMode",
    "fmi3Terminate", "fmi3Reset", "fmi3GetFloat64", "fmi3SetFloat64", "fmi3GetInt32",
    "fmi3SetInt32", "fmi3GetFMUState", "fmi3SetFMUState", "fmi3FreeFMUState",
    "fmi3SerializedFMUStateSize", "fmi3SerializeFMUState", "fmi3DeserializeFMUState",
    "fmi3GetOutputDerivatives", "fmi3DoStep", "fmi3EnterStepMode"};

static int n_errors_logged = 0;

/* FMI 3.0's logMessage is not variadic: the message is already formatted. */
static void logger(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category,
                   fmi3String message) {
    (void)env;
    if (status >= fmi3Error) n_errors_logged++;
    fprintf(stderr, "[%s] %s\n", category ? category : "", message ? message : "");
}

int main(int argc, char **argv) {
    if (argc < 9) { fprintf(stderr, "usage: %s LIB PATH TOKEN VR_IN VR_OUT STEPS H FORCE\n", argv[0]); return 1; }
    void *lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) { fprintf(stderr, "dlopen: %s\n", dlerror()); return 2; }
    for (size_t k = 0; k < sizeof NAMES / sizeof NAMES[0]; k++)
        if (!dlsym(lib, NAMES[k])) { fprintf(stderr, "missing export %s\n", NAMES[k]); return 2; }
    LOAD(instantiate, fmi3InstantiateCoSimulation);
    LOAD(enter, fmi3EnterInitializationMode);
    LOAD(exit_, fmi3ExitInitializationMode);
    LOAD(set_f64, fmi3SetFloat64);
    LOAD(get_f64, fmi3GetFloat64);
    LOAD(do_step, fmi3DoStep);
    LOAD(reset, fmi3Reset);
    LOAD(terminate, fmi3Terminate);
    LOAD(free_instance, fmi3FreeInstance);
    LOAD(version, fmi3GetVersion);

    if (strcmp(version(), "3.0") != 0) { fprintf(stderr, "version %s\n", version()); return 4; }
    fmi3ValueReference vr_in = (fmi3ValueReference)atoi(argv[4]);
    fmi3ValueReference vr_out = (fmi3ValueReference)atoi(argv[5]);
    int steps = atoi(argv[6]);
    double h = atof(argv[7]), force = atof(argv[8]);

    free_instance(NULL); /* ignored by the standard */
    fmi3Instance c = instantiate("driver3", argv[3], argv[2], false, true, false, false,
                                 NULL, 0, NULL, logger, NULL);
    if (!c) { fprintf(stderr, "instantiate failed\n"); return 3; }

    /* An illegal call first (a step before initialisation): an error, logged, and the
     * instance recovers by Reset. */
    fmi3Boolean event, stop, early;
    fmi3Float64 last;
    if (do_step(c, 0.0, h, true, &event, &stop, &early, &last) != fmi3Error || n_errors_logged != 1) {
        fprintf(stderr, "illegal fmi3DoStep not refused\n");
        return 5;
    }
    CHECK(reset(c));

    CHECK(enter(c, false, 0.0, 0.0, false, 0.0));
    CHECK(exit_(c));
    double y = 0.0, t = 0.0;
    for (int k = 0; k < steps; k++) {
        CHECK(set_f64(c, &vr_in, 1, &force, 1));
        CHECK(do_step(c, t, h, true, &event, &stop, &early, &last));
        double end = t + h;
        t = (k + 1) * h;
        /* No event, no early return, the whole step done. */
        if (event || stop || early || last != end) {
            fprintf(stderr, "step %d: flags %d %d %d, last %.17g\n", k, event, stop, early, last);
            return 6;
        }
    }
    CHECK(get_f64(c, &vr_out, 1, &y, 1));
    CHECK(terminate(c));
    free_instance(c);
    printf("%.17g\n", y);
    dlclose(lib);
    return 0;
}
