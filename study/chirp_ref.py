"""Independent reference for the study's chirp scene: the full finite-element cantilever
(the fixture generator's own frame-element model, all modes, not the reduced .fxb body)
under a tip load fy = F sin(2 pi f1 t^2 / (2 T)), 0 <= t <= T.

Each FE mode is advanced exactly over steps of H_FINE with the load interpolated
linearly inside a step (first-order hold). At H_FINE = 1e-5 s and f1 = 50 Hz the
interpolation error of the load is about (2 pi f1 H)^2 / 8 = 1e-6 of its amplitude.

usage: chirp_ref.py FIXTURES_DIR OUT_CSV F1_HZ T_END [GRID]
Writes OUT_CSV: a header line '# f1=..,t_end=..,grid=..', then 't,uy' rows every GRID s.
"""

import os
import sys

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402
import scipy.linalg as la  # noqa: E402

H_FINE = 1e-5


def main():
    fixtures, out = sys.argv[1], sys.argv[2]
    f1, t_end = float(sys.argv[3]), float(sys.argv[4])
    grid = float(sys.argv[5]) if len(sys.argv) > 5 else 5e-5
    sys.path.insert(0, fixtures)
    import bodies
    import fe

    _, k, m, _ = fe.beam_model(bodies.N_EL, bodies.LENGTH, bodies.E, bodies.G,
                               bodies.RHO, bodies.SECTION)
    free = np.arange(6, k.shape[0])  # node 0 clamped (all 6 DOFs), as the fixture
    w2, phi = la.eigh(k[np.ix_(free, free)], m[np.ix_(free, free)])
    w = np.sqrt(np.maximum(w2, 0.0))
    tip_uy = 6 * bodies.N_EL + 1 - 6  # tip node, fy row, in the free numbering
    p = phi[tip_uy, :]  # modal load of a unit fy and modal rows of uy alike
    h = H_FINE
    c, s = np.cos(w * h), np.sin(w * h)
    every = int(round(grid / h))
    n = int(round(t_end / h))

    def load(t):
        return np.sin(2.0 * np.pi * f1 * t * t / (2.0 * t_end))

    y = np.zeros_like(w)
    v = np.zeros_like(w)
    rows = [(0.0, 0.0)]
    f0 = load(0.0)
    for i in range(n):
        fe1 = load((i + 1) * h)
        a0, rate = p * f0, p * (fe1 - f0) / h
        y_new = y * c + v * s / w + a0 / w2 * (1.0 - c) + rate / w2 * (h - s / w)
        v = -y * w * s + v * c + a0 / w * s + rate / w2 * (1.0 - c)
        y = y_new
        f0 = fe1
        if (i + 1) % every == 0:
            rows.append(((i + 1) * h, float(p @ y)))
    with open(out, "w") as f:
        f.write("# f1=%.12g,t_end=%.12g,grid=%.12g,modes=%d\n" % (f1, t_end, grid, len(w)))
        for t, u in rows:
            f.write("%.9e,%.12e\n" % (t, u))
    print("chirp reference: %d FE modes, %d samples, peak %.4e m"
          % (len(w), len(rows), max(abs(u) for _, u in rows)), file=sys.stderr)


if __name__ == "__main__":
    main()
