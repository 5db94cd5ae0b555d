"""Model Exchange + CVode in the study (issue 26.3): the fixture bodies packed as FMI 2.0
Model Exchange FMUs (`fxbody pack --interface me`, the tip node exposed) and run by
fmpy's Model Exchange master with CVode (BDF, dense Newton, fmpy's defaults: absolute
tolerance rtol x the state nominals, largest step 1/50 of the run) over a range of
relative tolerances, on the study's scenes that have a full-FE reference: the
cantilever's step and pulse, the free-free pulse and the truss pulse (the fixtures'
ref.json, the same load on the tip's fy: a step held from t = 0, a pulse ending in an
input event at its duration).

Error as `fxbody-study` measures it: the largest |uy - uy_ref| over the reference samples
the run lands on (uy: the tip's global y position less its initial one), divided by the
reference's largest |uy|. The run's output grid is the reference's (2,245 to 2,822
samples; fmpy's CVode takes at most 500 steps between two output points, which the
tight tolerances need). CPU time: process CPU seconds of the whole simulate_fmu call on the extracted FMU
(model description parsed once beforehand), the fastest of REPS runs, per simulated
second: what a Python user of fmpy pays, including fmpy's own loop; the study's own
points time the solver's stepping loop only.

usage: me.py FIXTURES_DIR FXBODY_EXE OUT_CSV [--quick]
Writes OUT_CSV: scene,rtol,error_rel_peak,cpu_s_per_sim_s,outputs,compared_samples,note
(a run CVode gives up on has NaN error and time and says why in `note`).
"""

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402
from fmpy import extract, read_model_description, simulate_fmu  # noqa: E402

# (study scene, fixture, response name): the scenes of crates/study with a full-FE
# reference, named as the study names them.
SCENES = [
    ("cantilever step", "cantilever", "step"),
    ("cantilever pulse", "cantilever", "pulse"),
    ("free-free pulse", "freefree", "pulse"),
    ("truss pulse", "truss", "pulse"),
]


def pack(exe, fixtures, body, tip, out_dir):
    """The body packed for Model Exchange with its tip exposed, extracted: (dir, md)."""
    fmu = os.path.join(out_dir, f"{body}_me.fmu")
    cmd = [exe, "pack", os.path.join(fixtures, f"{body}.fxb"), "--coords",
           os.path.join(fixtures, f"{body}.nodes.rad"), "--nodes", str(tip),
           "--interface", "me", "-o", fmu]
    subprocess.run(cmd, check=True, capture_output=True)
    unzip = extract(fmu, os.path.join(out_dir, f"{body}_me"))
    return unzip, read_model_description(unzip)


def point(unzip, md, resp, tip, rtol, reps):
    """One rtol: (error relative to the peak, CPU s per simulated s, outputs, samples
    compared)."""
    t_ref = np.array(resp["t"])
    uy_ref = np.array(resp["nodes"][str(tip)]["uy"])
    dt = t_ref[1] - t_ref[0]
    stop = t_ref[-1]
    amp, dur = resp["amplitude"], resp.get("duration")
    fy, y = f"node_{tip}.fy", f"node_{tip}.y"
    if dur:
        rows = [(0.0, amp), (dur, amp), (dur, 0.0), (stop, 0.0)]
    else:
        rows = [(0.0, amp), (stop, amp)]
    signal = np.array(rows, dtype=[("time", float), (fy, float)])
    best, r = np.inf, None
    for _ in range(reps):
        c0 = time.process_time()
        r = simulate_fmu(unzip, validate=False, model_description=md, fmi_type="ModelExchange",
                         solver="CVode", relative_tolerance=rtol, start_time=0.0,
                         stop_time=stop, output_interval=dt, input=signal,
                         output=[y], record_events=False)
        best = min(best, time.process_time() - c0)
    u = r[y] - r[y][0]
    err, compared = 0.0, 0
    for ti, ui in zip(r["time"], u):
        k = round(ti / dt)
        if abs(k * dt - ti) < 1e-6 * dt and k < len(uy_ref):
            err = max(err, abs(ui - uy_ref[k]))
            compared += 1
    return err / np.max(np.abs(uy_ref)), best / stop, len(r), compared


def main():
    fixtures, exe, out = sys.argv[1], sys.argv[2], sys.argv[3]
    quick = "--quick" in sys.argv
    rtols = [1e-4, 1e-7, 1e-10] if quick else [10.0 ** -k for k in range(3, 12)]
    reps = 1 if quick else 3
    work = tempfile.mkdtemp(prefix="fxbody_me_study_")
    rows = []
    try:
        packed = {}
        for scene, body, name in SCENES:
            ref = json.load(open(os.path.join(fixtures, f"{body}.ref.json")))
            tip = ref["tip_node"]
            if body not in packed:
                packed[body] = pack(exe, fixtures, body, tip, work)
            unzip, md = packed[body]
            resp = next(r for r in ref["responses"] if r["name"] == name)
            for rtol in rtols:
                try:
                    err, cpu, n, compared = point(unzip, md, resp, tip, rtol, reps)
                    note = ""
                except RuntimeError as e:  # CVode gave up (mxstep, convergence)
                    err, cpu, n, compared = np.nan, np.nan, 0, 0
                    note = str(e).replace(",", ";").replace("\n", " ")[:200]
                print(f"ME + CVode {scene:<18} rtol {rtol:.0e}  error {err:.3e}  "
                      f"cpu/s {cpu:.3e}  ({n} outputs) {note}", file=sys.stderr)
                rows.append((scene, rtol, err, cpu, n, compared, note))
    finally:
        shutil.rmtree(work, ignore_errors=True)
    with open(out, "w") as f:
        f.write("scene,rtol,error_rel_peak,cpu_s_per_sim_s,outputs,compared_samples,note\n")
        for r in rows:
            f.write("%s,%.0e,%.6e,%.6e,%d,%d,%s\n" % r)


if __name__ == "__main__":
    main()
