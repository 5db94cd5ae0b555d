"""Exudyn peer (issue 8): ObjectFFRFreducedOrder built from the fixture generator's own
finite-element matrices and the same local modes as the shipped `truss.fxb` (a free
pin-jointed tower, translational DOFs only, which is what Exudyn's reduced FFRF body
takes: a mode basis of node translations and a matching 3n x 3n mass matrix). The
free-free beam could not be used: its 6-DOF frame elements lie on one line, so a
translational mass has no inertia about the axis (docs/STUDY.md).

Scene: the fixture's pulse (0.1 N on the tip's global fy for 1 ms), Exudyn's default
implicit integrator (generalised-alpha) at each communication step h; the tip
displacement compared with the fixture's full-FE response like the study does (max over
the reference samples, relative to the peak). Timed: exu.SolveDynamic (wall clock, the
fastest of `reps` runs), per step.

usage: exudyn_peer.py FIXTURES_DIR STEP [STEP ...]  -> CSV rows on stdout:
       exudyn,truss pulse,h,error,ns_per_step,cpu_per_sim_s,note
(study/peers.py calls rows() directly.)
"""

import json
import os
import sys
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

# Modified Newton (Jacobian kept while it converges): 10 times faster here than Exudyn's
# default full Newton at the same results, so the fairer choice for the peer.
MODIFIED = os.environ.get("EXUDYN_MODIFIED_NEWTON", "1") == "1"


class _Fem:
    """The few members ObjectFFRFreducedOrderInterface reads from a FEMinterface."""

    def __init__(self, x, m, k, modes):
        self._x, self._m, self._k = x, m, k
        self.modeBasis = {"matrix": modes}
        self.postProcessingModes = {}

    def GetNodePositionsAsArray(self):  # noqa: N802 (Exudyn's name)
        return self._x

    def GetSurfaceTriangles6(self):  # noqa: N802
        return []

    def GetSurfaceTriangles(self):  # noqa: N802
        return []

    def GetMassMatrix(self, sparse=True):  # noqa: N802
        return self._m

    def GetStiffnessMatrix(self, sparse=True):  # noqa: N802
        return self._k


def build(fixtures):
    sys.path.insert(0, fixtures)
    import bodies

    spec = bodies.truss()
    ref = json.load(open(os.path.join(fixtures, "truss.ref.json")))
    modes = spec["phi_l"]  # the .fxb's local modes, 3 per node, local frame
    return spec, ref, modes


def run(spec, ref, modes, h, reps):
    import exudyn as exu
    import exudyn.itemInterface as ii
    from exudyn.FEM import ObjectFFRFreducedOrderInterface

    resp = next(r for r in ref["responses"] if r["name"] == "pulse")
    tip_id = ref["tip_node"]
    tip = spec["ids"].index(tip_id)
    amp, dur = resp["amplitude"], resp["duration"]
    t_ref = np.array(resp["t"])
    uy_ref = np.array(resp["nodes"][str(tip_id)]["uy"])
    t_end = float(t_ref[-1])
    steps = int(round(t_end / h))

    best, out = np.inf, None
    for _ in range(reps):
        sc = exu.SystemContainer()
        mbs = sc.AddSystem()
        cms = ObjectFFRFreducedOrderInterface(_Fem(spec["X"], spec["M"], spec["K"], modes))
        obj = cms.AddObjectFFRFreducedOrder(
            mbs, positionRef=list(spec["x_l0"]), rotationMatrixRef=spec["p0"])
        body = obj["oFFRFreducedOrder"]
        marker = mbs.AddMarker(ii.MarkerSuperElementPosition(
            bodyNumber=body, meshNodeNumbers=[tip], weightingFactors=[1.0]))

        lo = mbs.AddLoad(ii.LoadForceVector(markerNumber=marker, loadVector=[0, 0, 0]))

        # The step's mean load, as the study feeds ours (exact impulse at every step),
        # set once per step before the step (not inside the Newton iterations). Exudyn
        # calls this with t = the END of the step about to be computed.
        def pre_step(mbs_, t):
            t0 = h * (np.round(t / h) - 1.0)
            overlap = max(0.0, min(t0 + h, dur) - max(t0, 0.0))
            mbs_.SetLoadParameter(lo, "loadVector", [0.0, amp * overlap / h, 0.0])
            return True

        mbs.SetPreStepUserFunction(pre_step)
        sensor = mbs.AddSensor(ii.SensorSuperElement(
            bodyNumber=body, meshNodeNumber=tip, storeInternal=True, writeToFile=False,
            outputVariableType=exu.OutputVariableType.Displacement))
        mbs.Assemble()
        s = exu.SimulationSettings()
        s.timeIntegration.numberOfSteps = steps
        s.timeIntegration.endTime = steps * h
        s.timeIntegration.verboseMode = 0
        s.solution.file.write = False
        s.solution.sensors.writePeriod = h
        s.timeIntegration.newton.useModifiedNewton = MODIFIED
        s.timeIntegration.generalizedAlpha.spectralRadius = 0.9
        t0 = time.perf_counter()
        mbs.SolveDynamic(s)
        best = min(best, time.perf_counter() - t0)
        out = mbs.GetSensorStoredData(sensor)
    # The superelement's Displacement output is global (checked: read in the body frame
    # it misses the reference by 30 %).
    dt_ref = t_ref[1] - t_ref[0]
    e = 0.0
    for ti, ui in zip(out[:, 0], out[:, 2]):
        k = round(ti / dt_ref)
        if abs(k * dt_ref - ti) < 1e-6 * h and 0 < k < len(uy_ref):
            e = max(e, abs(ui - uy_ref[k]))
    err = e / np.abs(uy_ref).max()
    return err, best / steps * 1e9, best / (steps * h)


def rows(fixtures, hs, reps=2):
    """(peer, scene, h, error, ns per step, cpu s per simulated s, note) per step."""
    spec, ref, modes = build(fixtures)
    out = []
    for h in hs:
        err, ns, cpu = run(spec, ref, modes, h, reps)
        print(f"exudyn truss pulse h = {h:.3e}  error {err:.3e}  {ns:9.0f} ns/step",
              file=sys.stderr)
        out.append(("exudyn", "truss pulse", h, err, ns, cpu,
                    "ObjectFFRFreducedOrder; genalpha 0.9; modified Newton"))
    return out


def main():
    for r in rows(sys.argv[1], [float(x) for x in sys.argv[2:]]):
        print("%s,%s,%.6e,%.6e,%.1f,%.6e,%s" % r)


if __name__ == "__main__":
    main()
