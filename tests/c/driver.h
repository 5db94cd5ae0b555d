/* What the C drivers of the tests share (fmu_driver.c, fmu3_driver.c, header_driver.c).
 *
 * LOAD(var, fn): take `fn` from the library handle `lib` (dlopen) into `var`, typed
 * from the header's own declaration of `fn`, so that a driver checks the header against
 * the library; return 2 from main when the library lacks it.
 * CHECK(call): return 3 from main, saying which call, unless it returns OK (0 in both
 * FMI versions: fmi2OK, fmi3OK). */
#ifndef FXBODY_TEST_DRIVER_H
#define FXBODY_TEST_DRIVER_H

#define LOAD(var, fn)                                                      \
    __typeof__(fn) *var = (__typeof__(fn) *)dlsym(lib, #fn);               \
    if (!var) { fprintf(stderr, "missing %s\n", #fn); return 2; }

#define CHECK(call)                                                        \
    do { int s_ = (call); if (s_ != 0) {                                   \
        fprintf(stderr, "%s failed with %d\n", #call, s_); return 3; } } while (0)

#endif
