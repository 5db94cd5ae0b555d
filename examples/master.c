/* A C master for the cantilever packed with its tip node 121 exposed (README, "C"):
 * a 1 N step load on the tip along y, explicit method, 0.4 s at 0.2 ms; prints the peak
 * tip deflection. Built against include/fxbody.h and the header `pack --header` wrote. */
#include <limits.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

#include "fxbody.h"     /* the FMI 2.0 types and functions (include/) */
#include "cantilever.h" /* this FMU's GUID and value references (pack --header) */

static void logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status,
                   fmi2String category, fmi2String message, ...) {
    va_list ap;
    (void)env;
    (void)status;
    fprintf(stderr, "[%s] %s: ", category, instance);
    va_start(ap, message);
    vfprintf(stderr, message, ap);
    va_end(ap);
    fputc('\n', stderr);
}

int main(void) {
    char dir[PATH_MAX], uri[PATH_MAX + 8];
    if (!realpath("out/cantilever/resources", dir)) return 1;
    snprintf(uri, sizeof uri, "file://%s", dir);
    fmi2CallbackFunctions cb = {logger, NULL, NULL, NULL, NULL};
    fmi2Component c = fmi2Instantiate("body", fmi2CoSimulation, CANTILEVER_GUID, uri, &cb, fmi2False, fmi2False);
    if (!c) return 1;
    const fmi2ValueReference method = CANTILEVER_VR_METHOD, fy = CANTILEVER_VR_NODE_121_FY,
                             y = CANTILEVER_VR_NODE_121_Y;
    const fmi2Integer explicit_method = CANTILEVER_METHOD_EXPLICIT;
    const double h = 2e-4, load = 1.0;
    double tip, peak = 0.0;
    if (fmi2SetInteger(c, &method, 1, &explicit_method) != fmi2OK ||
        fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) != fmi2OK ||
        fmi2EnterInitializationMode(c) != fmi2OK || fmi2ExitInitializationMode(c) != fmi2OK ||
        fmi2SetReal(c, &fy, 1, &load) != fmi2OK)
        return 1;
    for (int k = 0; k < 2000; k++) { /* 0.4 s */
        if (fmi2DoStep(c, k * h, h, fmi2True) != fmi2OK || fmi2GetReal(c, &y, 1, &tip) != fmi2OK)
            return 1;
        peak = tip > peak ? tip : -tip > peak ? -tip : peak;
    }
    fmi2FreeInstance(c);
    printf("peak tip deflection %.4e m\n", peak);
    return 0;
}
