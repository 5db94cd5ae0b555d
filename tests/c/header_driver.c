/* A C master that names the variables through the header `fxbody pack --header` wrote
 * (force-included by the test with -include, model name "tip"): loads the FMU's library,
 * reads the method the FMU starts with, holds a tip load for N steps and prints the tip
 * y position and the method value. Built and run by tests/all/cli/pack_extras.rs.
 *
 * usage: header_driver LIB RESOURCE_URI STEPS H FORCE
 */
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

#include "fxbody.h"
#include "driver.h"

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status,
                   fmi2String category, fmi2String message, ...) {
    va_list ap;
    (void)env;
    (void)status;
    fprintf(stderr, "[%s] %s: ", category, name);
    va_start(ap, message);
    vfprintf(stderr, message, ap);
    va_end(ap);
    fputc('\n', stderr);
}

int main(int argc, char **argv) {
    if (argc < 6) { fprintf(stderr, "usage: %s LIB URI STEPS H FORCE\n", argv[0]); return 1; }
    void *lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) { fprintf(stderr, "dlopen: %s\n", dlerror()); return 2; }
    LOAD(instantiate, fmi2Instantiate);
    LOAD(setup, fmi2SetupExperiment);
    LOAD(enter, fmi2EnterInitializationMode);
    LOAD(exit_, fmi2ExitInitializationMode);
    LOAD(set_real, fmi2SetReal);
    LOAD(get_real, fmi2GetReal);
    LOAD(get_integer, fmi2GetInteger);
    LOAD(do_step, fmi2DoStep);
    LOAD(free_instance, fmi2FreeInstance);
    fmi2CallbackFunctions cb = {logger, NULL, NULL, NULL, NULL};
    int steps = atoi(argv[3]);
    double h = atof(argv[4]), force = atof(argv[5]);
    const fmi2ValueReference vr_in = TIP_VR_NODE_121_FY, vr_out = TIP_VR_NODE_121_Y;
    const fmi2ValueReference vr_method = TIP_VR_METHOD;
    fmi2Component c = instantiate("header", fmi2CoSimulation, TIP_GUID, argv[2], &cb, fmi2False, fmi2False);
    if (!c) { fprintf(stderr, "instantiate failed\n"); return 3; }
    CHECK(setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0));
    CHECK(enter(c));
    CHECK(exit_(c));
    fmi2Integer method = 0;
    CHECK(get_integer(c, &vr_method, 1, &method));
    double y = 0.0;
    for (int k = 0; k < steps; k++) {
        CHECK(set_real(c, &vr_in, 1, &force));
        CHECK(do_step(c, k * h, h, fmi2True));
    }
    CHECK(get_real(c, &vr_out, 1, &y));
    free_instance(c);
    printf("%.17g %d %u\n", y, (int)method, (unsigned)TIP_NUMBER_OF_VARIABLES);
    dlclose(lib);
    return 0;
}
