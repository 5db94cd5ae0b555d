"""Co-simulation coupling stability (issue 8): the packed cantilever (tip node exposed) run
through fmpy's FMU2Slave, its tip tied to ground by a spring-damper that lives in the
master. Explicit force-position exchange every macro step H:

- held:      F(t) = F_n = -k y_n - c v_n over [t_n, t_n + H];
- linear:    F_n plus the slope (F_n - F_{n-1}) / H passed by fmi2SetRealInputDerivatives
             (linear extrapolation of the coupling force);
- rollback:  the held step is a predictor; the master reads y, v at t_n + H, rolls the FMU
             back (fmi2GetFMUstate / fmi2SetFMUstate) and redoes the step with F varying
             linearly from F_n to F_{n+1} (one corrector pass of an implicit coupling).

A trial: a constant external tip load of 1 N is switched on at t = 0; the run lasts 20
periods of the coupled mode (at least 200 macro steps). It is unstable when the
largest deviation from the static solution in the last quarter exceeds twice that of the
first quarter, or anything is non-finite. Bisection in log H gives the largest stable H.

The damper is sized for a damping ratio zeta of the coupled first mode (the beam itself
is undamped); results are given as H_max, and as H_max * omega_c with omega_c the circular
frequency of the lowest mode that moves the spring, next to BENCHMARKS.md's two-oscillator thresholds (held 0.053 /
linear 0.43 at 1 %, 0.53 / 0.99 at 10 %).

usage: cosim.py FMU FIXTURES_DIR OUT_CSV [--quick]
"""

import os
import shutil
import sys
import tempfile

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402
import scipy.linalg as la  # noqa: E402
from fmpy import extract, read_model_description  # noqa: E402
from fmpy.fmi2 import FMU2Slave  # noqa: E402

K_SPRING = 5000.0  # N/m, about 7 times the tip stiffness 3EI/L^3 = 726 N/m
F_EXT = 1.0


def coupled_mode(fixtures, tip_id):
    """omega_c and the modal participation b.v of the spring DOF, from the .fxb data."""
    sys.path.insert(0, fixtures)
    import fxbread

    d = fxbread.read_fxb(open(os.path.join(fixtures, "cantilever.fxb")).read())
    tip = list(d["node_ids"]).index(tip_id)
    b = (d["p0"] @ d["local"][6 * tip:6 * tip + 3, :])[1, :]
    kc = d["k_l"] + K_SPRING * np.outer(b, b)
    w2, v = la.eigh(kc, np.diag(d["m_l"]))
    k_static = 1.0 / (b @ np.linalg.solve(d["k_l"], b))
    # The coupled mode: the lowest one that moves the spring's DOF (the lowest mode of
    # the body bends in the other plane and does not feel the spring).
    p2 = (b @ v) ** 2
    i = int(np.argmax(p2 > 1e-8 * p2.max()))
    return np.sqrt(w2[i]), float(b @ v[:, i]), k_static


class Tip:
    def __init__(self, fmu, unzip, tip_id):
        md = read_model_description(fmu)
        vr = {v.name: v.valueReference for v in md.modelVariables}
        self.fy = vr[f"node_{tip_id}.fy"]
        self.out = [vr[f"node_{tip_id}.y"], vr[f"node_{tip_id}.vy"]]
        self.s = FMU2Slave(guid=md.guid, unzipDirectory=unzip,
                           modelIdentifier=md.coSimulation.modelIdentifier,
                           instanceName="cosim")
        self.s.instantiate()

    def reset(self):
        self.s.reset()
        self.s.setupExperiment(startTime=0.0)
        self.s.enterInitializationMode()
        self.s.exitInitializationMode()

    def free(self):
        self.s.terminate()
        self.s.freeInstance()


def trial(tip, scheme, h, c, steps, y_static):
    tip.reset()
    s = tip.s
    y, v = s.getReal(tip.out)
    f_prev = None
    t = 0.0
    ys = np.empty(steps)
    for n in range(steps):
        f = F_EXT - K_SPRING * y - c * v
        s.setReal([tip.fy], [f])
        if scheme == "linear" and f_prev is not None:
            s.setRealInputDerivatives([tip.fy], [1], [(f - f_prev) / h])
        if scheme == "rollback":
            saved = s.getFMUstate()
            s.setRealInputDerivatives([tip.fy], [1], [0.0])
            s.doStep(t, h)
            y1, v1 = s.getReal(tip.out)
            f1 = F_EXT - K_SPRING * y1 - c * v1
            s.setFMUstate(saved)
            s.freeFMUstate(saved)
            s.setReal([tip.fy], [f])
            s.setRealInputDerivatives([tip.fy], [1], [(f1 - f) / h])
        s.doStep(t, h)
        t += h
        f_prev = f
        y, v = s.getReal(tip.out)
        if not (np.isfinite(y) and abs(y) < 1e3):
            return False
        ys[n] = y
    dev = np.abs(ys - y_static)
    q = max(steps // 4, 1)
    return dev[-q:].max() <= 2.0 * dev[:q].max()


def largest_stable(tip, scheme, c, omega, y_static, iters):
    period = 2.0 * np.pi / omega

    def ok(h):
        steps = int(max(200, 20 * period / h))
        try:
            return trial(tip, scheme, h, c, steps, y_static)
        except Exception:  # fmpy raises on an Error status: the step failed
            return False

    lo, hi = period / 2000.0, 0.2
    if ok(hi):
        return hi
    if not ok(lo):
        return 0.0
    for _ in range(iters):
        mid = np.sqrt(lo * hi)
        if ok(mid):
            lo = mid
        else:
            hi = mid
    return lo


def main():
    fmu, fixtures, out = sys.argv[1], sys.argv[2], sys.argv[3]
    quick = "--quick" in sys.argv
    import json

    tip_id = json.load(open(os.path.join(fixtures, "cantilever.ref.json")))["tip_node"]
    omega, part, k_tip = coupled_mode(fixtures, tip_id)
    y_static = F_EXT / (k_tip + K_SPRING)
    unzip = tempfile.mkdtemp(prefix="fxbody_cosim_")
    try:
        extract(fmu, unzip)
        tip = Tip(fmu, unzip, tip_id)
        rows = []
        bench = {(0.01, "held"): 0.053, (0.01, "linear"): 0.43,
                 (0.1, "held"): 0.53, (0.1, "linear"): 0.99}
        for zeta in (0.01, 0.1):
            c = 2.0 * zeta * omega / part**2
            for scheme in ("held", "linear", "rollback"):
                h = largest_stable(tip, scheme, c, omega, y_static, 6 if quick else 14)
                b = bench.get((zeta, scheme))
                rows.append((zeta, scheme, h, h * omega, b))
                print(f"cosim zeta {zeta:4.2f} {scheme:<8} H_max {h:.3e} s  "
                      f"H*omega_c {h * omega:.3f}  (two oscillators: {b})", file=sys.stderr)
        tip.free()
    finally:
        shutil.rmtree(unzip, ignore_errors=True)
    with open(out, "w") as f:
        f.write("# k_spring=%g N/m, k_tip=%.6g N/m, omega_c=%.6g rad/s (f_c=%.4g Hz)\n"
                % (K_SPRING, k_tip, omega, omega / (2 * np.pi)))
        f.write("zeta,scheme,h_max_s,h_max_times_omega_c,two_oscillator_benchmark\n")
        for z, sch, h, hw, b in rows:
            f.write("%g,%s,%.6e,%.6g,%s\n" % (z, sch, h, hw, "" if b is None else b))


if __name__ == "__main__":
    main()
