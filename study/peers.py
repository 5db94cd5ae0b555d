"""Peers of the study (issue 8), on the same body, scene and steps as `fxbody-study`.

(a) numpy: what a Python user would write for the reduced blocked cantilever read from
    the same .fxb file: the exact discrete state space (zero-order hold, scipy expm of
    the augmented modal state matrix), stepped one communication step at a time in a
    numpy loop. Same load model as the study (a pulse holds the step's mean load), same
    error measure (max |uy - uy_FE| over the FE reference samples, over the peak).
(b) Exudyn: optional; see exudyn_peer() for what is and is not done.

usage: peers.py FIXTURES_DIR OUT_CSV [--quick]
Writes OUT_CSV: peer,scene,h_s,error_rel_peak,ns_per_step,cpu_s_per_sim_s,note
"""

import json
import os
import sys
import time

# One BLAS thread: the loop does 40x40 products, where threads only add overhead (and the
# study machine is shared).
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy  # noqa: E402,F401
import numpy as np
from scipy.linalg import expm  # noqa: E402


def load_fixture(fixtures, name):
    sys.path.insert(0, fixtures)
    import fxbread  # the fixtures' own reader, independent of the Rust reader

    body = fxbread.read_fxb(open(os.path.join(fixtures, name + ".fxb")).read())
    ref = json.load(open(os.path.join(fixtures, name + ".ref.json")))
    return body, ref


def mean_load(shape, amp, duration, t, h):
    if shape == "step":
        return amp
    overlap = max(0.0, min(t + h, duration) - max(t, 0.0))
    return amp * overlap / h


def numpy_peer(body, ref, scene, resp, h, reps):
    ids = list(body["node_ids"])
    tip = ids.index(ref["tip_node"])
    phi = body["local"][6 * tip:6 * tip + 3, :]  # translational rows, local frame
    p0 = body["p0"]
    k, m = body["k_l"], body["m_l"]
    n = len(m)
    fy = np.array([0.0, 1.0, 0.0])
    b_in = phi.T @ (p0.T @ fy)  # generalised load of a unit global fy
    c_out = (p0 @ phi)[1, :]  # global uy from alpha
    a = np.zeros((2 * n, 2 * n))
    a[:n, n:] = np.eye(n)
    a[n:, :n] = -k / m[:, None]
    if body["damping"] is not None:
        ra, rb = body["damping"]
        a[n:, n:] = -(ra * np.eye(n) + rb * k / m[:, None])
    aug = np.zeros((2 * n + 1, 2 * n + 1))
    aug[:2 * n, :2 * n] = a
    aug[:2 * n, 2 * n] = np.concatenate([np.zeros(n), b_in / m])
    e = expm(aug * h)
    ad, bd = e[:2 * n, :2 * n], e[:2 * n, 2 * n]
    c = np.concatenate([c_out, np.zeros(n)])
    t_ref = np.array(resp["t"])
    uy_ref = np.array(resp["nodes"][str(ref["tip_node"])]["uy"])
    dt_ref = t_ref[1] - t_ref[0]
    steps = int(round(t_ref[-1] / h))
    loads = [mean_load(resp["shape"], resp["amplitude"], resp["duration"] or 0.0, i * h, h)
             for i in range(steps)]
    # The user's loop; the error is computed afterwards from the stored outputs.
    best = np.inf
    for _ in range(reps):
        x = np.zeros(2 * n)
        out = np.empty(steps)
        t0 = time.perf_counter()
        for i in range(steps):
            x = ad @ x + bd * loads[i]
            out[i] = c @ x
        best = min(best, time.perf_counter() - t0)
    err = 0.0
    for i in range(steps):
        t = (i + 1) * h
        kk = round(t / dt_ref)
        if abs(kk * dt_ref - t) < 1e-6 * dt_ref and kk < len(uy_ref):
            err = max(err, abs(out[i] - uy_ref[kk]))
    err /= np.max(np.abs(uy_ref))
    return err, best / steps * 1e9, best / (steps * h)


def exudyn_peer(fixtures, quick):
    """Exudyn on the free truss (see study/exudyn_peer.py for why the truss and not the
    free-free beam). Returns (rows, note); no rows when exudyn is not importable."""
    try:
        import exudyn  # noqa: F401
    except Exception as e:  # not installed or broken: say so, no numbers
        return [], f"exudyn not importable: {type(e).__name__}"
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import exudyn_peer

    hs = [2e-5] if quick else [1e-5, 2e-5, 4e-5]
    return exudyn_peer.rows(fixtures, hs, 1 if quick else 2), "exudyn " + exudyn.__version__


def main():
    fixtures, out = sys.argv[1], sys.argv[2]
    quick = "--quick" in sys.argv
    body, ref = load_fixture(fixtures, "cantilever")
    steps = [2e-4 * 2.0 ** k for k in ((-1, 0, 1) if quick else range(-2, 6))]
    rows = []
    for resp in ref["responses"]:
        scene = "cantilever " + resp["name"]
        for h in steps:
            err, ns, cpu = numpy_peer(body, ref, scene, resp, h, 1 if quick else 3)
            print(f"numpy {scene:<18} h = {h:.3e}  error {err:.3e}  {ns:8.0f} ns/step",
                  file=sys.stderr)
            rows.append(("numpy exact state space", scene, h, err, ns, cpu, "scipy expm ZOH"))
    ex_rows, note = exudyn_peer(fixtures, quick)
    rows += ex_rows
    print("exudyn:", note, file=sys.stderr)
    with open(out, "w") as f:
        f.write("peer,scene,h_s,error_rel_peak,ns_per_step,cpu_s_per_sim_s,note\n")
        for r in rows:
            f.write("%s,%s,%.6e,%.6e,%.1f,%.6e,%s\n" % r)
        f.write("# exudyn: %s\n" % note.replace(",", ";"))


if __name__ == "__main__":
    main()
