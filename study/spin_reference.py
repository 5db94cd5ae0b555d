"""A reference integration of a free flexible body's equations of motion, in numpy.

Independent of the Rust crate (it shares no code with it): it reads a `.fxb` file with
fixtures/fxbread.py, forms the kinetic energy of docs/FORMULATION.md section 3,

    T = 1/2 v_R^T M_R v_R + v_R^T M_C(P) v_L + 1/2 sum_j m_L,j v_L,j^2,
    M_C(P) = sum_kl P_kl M_C,kl,   P = P0 + [q_Lj - q_L0]_j,

and integrates the constrained Lagrange equations of T with the potential
1/2 alpha^T K_L alpha and the force -K_C(P) alpha on the rigid coordinates,

    M(q) a + h(q, v) = Q(q) + C(q)^T lambda,   C(q) a = -C_dot v,

with the six distance constraints of the frame points (section 3). The quadratic-velocity
vector `h = M_dot v - dT/dq` is not written out by hand: M is affine in q (through P),
so both parts are formed from the 9 x nq Jacobian of vec(P) by q, read off `frame_of`
numerically (exact for an affine map), and checked at the start against central
differences of T itself. `--eq` chooses the equations: `first` (default) adds to T the
part `v_R^T M_C(P_dot) alpha` of the node velocities' `P_dot Phi_L alpha`, first order in
alpha, whose Lagrange equations fxbody's split and implicit methods solve
(src/solver/free/drag.rs); `form` the Lagrange equations of T as written; `radioss` the
equations without h, as Radioss solves them.

Classical Runge-Kutta 4 at a small step, then the positions and velocities projected
back onto the constraints (Newton on q, the M-orthogonal projection on v). Printed: the
energy `T + 1/2 alpha^T K_L alpha` and the angular momentum about the origin
(`sum_a x_a x p_a` over the frame points, `p = dT/dv_R`) relative to their start, at
intervals of rotation. A body spun torque-free at `--rate` of its first frequency about
`P0 (1, -2, 3)`, the set-up of tests/all/free/spin.rs.

    .venv/bin/python study/spin_reference.py fixtures/truss.fxb --rad 5 --dt 2e-5
    .venv/bin/python study/spin_reference.py fixtures/truss.fxb --rad 5 --dt 2e-5 --eq radioss
    .venv/bin/python study/spin_reference.py fixtures/truss.fxb --json out.json --rad 2

Measured (fixtures/truss.fxb, 5 rad at dt 2e-5 s): `first` keeps the angular momentum to
1.4e-11 and the energy to 3.7e-8; `radioss` drifts (see docs/FORMULATION.md section 3).
"""

import argparse
import json
import os
import sys
import time

import numpy as np
import scipy.linalg as sl

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "fixtures"))
from fxbread import read_fxb  # noqa: E402

PAIRS = [(1, 0, 1.0), (2, 0, 1.0), (3, 0, 1.0), (2, 1, 2.0), (3, 1, 2.0), (3, 2, 2.0)]


def offset(point):
    """Offset of frame point `point` (0 = L0, j = Lj) in q_R."""
    return 9 if point == 0 else 3 * (point - 1)


class Body:
    def __init__(self, path):
        b = read_fxb(open(path).read())
        if b["iblo"] or b["irot"]:
            raise SystemExit("this reference handles free bodies with Irot = 0")
        self.nr, self.nl = 12, b["nbmod"]
        self.nq = self.nr + self.nl
        self.p0 = b["p0"]
        self.m_r, self.m_c, self.k_c = b["m_r"], b["m_c"], b["k_c"]
        self.m_l, self.k_l = np.asarray(b["m_l"]), b["k_l"]
        self.m_c9 = self.m_c.reshape(9, self.nr, -1)
        self.k_c9 = self.k_c.reshape(9, self.nr, -1)
        w2 = sl.eigh(self.k_l, np.diag(self.m_l), eigvals_only=True)
        self.w1 = np.sqrt(w2[w2 > 0][0])
        # Jacobian of vec(P) (row-major, index 3 k + l) by q: affine, so exact.
        self.jp = np.zeros((9, self.nq))
        for i in range(self.nq):
            e = np.zeros(self.nq)
            e[i] = 1.0
            self.jp[:, i] = (self.frame_of(e) - self.frame_of(0 * e)).ravel()

    def frame_of(self, q):
        p = self.p0.copy()
        for j in range(3):
            p[:, j] += q[3 * j : 3 * j + 3] - q[9:12]
        return p

    def mc(self, p):
        return np.tensordot(p.ravel(), self.m_c9, axes=1)

    def kc(self, p):
        return np.tensordot(p.T.ravel(), self.k_c9, axes=1)

    def mass(self, q):
        """M(q) of the chosen kinetic energy T = 1/2 v^T M(q) v."""
        nr = self.nr
        m = np.zeros((self.nq, self.nq))
        m[:nr, :nr] = self.m_r
        mc = self.mc(self.frame_of(q))
        m[:nr, nr:] = mc
        m[nr:, :nr] = mc.T
        m[nr:, nr:] = np.diag(self.m_l)
        if self.first_order:
            # v_R^T M_C(P_dot) alpha = v_R^T J_Y v_R, J_Y[:, i] = M_C(dP/dq_i) alpha.
            alpha = q[nr:]
            jy = (self.m_c9 @ alpha).T @ self.jp[:, :nr]
            m[:nr, :nr] += jy + jy.T
        return m

    def prepare(self, first_order):
        """Choose T and tabulate dM/dq_i (M is affine in q: exact differences)."""
        self.first_order = first_order
        zero = np.zeros(self.nq)
        m0 = self.mass(zero)
        dm = np.stack([self.mass(e) - m0 for e in np.eye(self.nq)])
        # M depends on alpha only through its rigid block (first-order T): keep the
        # nonzero parts, for speed.
        nr = self.nr
        rest = dm[nr:].copy()
        rest[:, :nr, :nr] = 0
        assert not rest.any()
        self.dm_q, self.dm_a = dm[:nr], dm[nr:, :nr, :nr]

    def kinetic(self, q, v):
        return 0.5 * v @ self.mass(q) @ v

    def quadratic(self, q, v):
        """h = M_dot v - dT/dq, with M_dot = sum_i v_i dM/dq_i and
        dT/dq_i = 1/2 v^T dM/dq_i v (exact: M is affine in q)."""
        nr = self.nr
        mdot = np.tensordot(v[:nr], self.dm_q, axes=1)
        mdot[:nr, :nr] += np.tensordot(v[nr:], self.dm_a, axes=1)
        dtdq = np.concatenate([(self.dm_q @ v) @ v, (self.dm_a @ v[:nr]) @ v[:nr]]) / 2
        return mdot @ v - dtdq

    def constraints(self, q):
        p = self.frame_of(q)
        edge = lambda a: np.zeros(3) if a == 0 else p[:, a - 1]
        phi = np.zeros(6)
        jac = np.zeros((6, self.nq))
        for r, (a, b, c) in enumerate(PAIRS):
            d = edge(a) - edge(b)
            phi[r] = d @ d - c
            jac[r, offset(a) : offset(a) + 3] += 2 * d
            jac[r, offset(b) : offset(b) + 3] -= 2 * d
        return phi, jac

    def accel(self, q, v, drop):
        """The accelerations from the saddle-point system of M(q), the forces, h and the
        constraints' second derivative."""
        nr, nq = self.nr, self.nq
        p = self.frame_of(q)
        alpha = q[nr:]
        f = np.zeros(nq)
        f[:nr] = -self.kc(p) @ alpha
        f[nr:] = -self.k_l @ alpha
        if not drop:
            f -= self.quadratic(q, v)
        _, jac = self.constraints(q)
        rhs_c = np.zeros(6)
        for r, (a, b, _) in enumerate(PAIRS):
            w = v[offset(a) : offset(a) + 3] - v[offset(b) : offset(b) + 3]
            rhs_c[r] = -2 * w @ w
        kkt = np.block([[self.mass(q), -jac.T], [-jac, np.zeros((6, 6))]])
        return np.linalg.solve(kkt, np.concatenate([f, -rhs_c]))[:nq]

    def project(self, q, v):
        """Positions onto the constraints (Newton, least change), velocities by the
        M-orthogonal projection (the kinetic energy's own metric)."""
        for _ in range(5):
            phi, jac = self.constraints(q)
            if np.abs(phi).max() < 1e-15:
                break
            q = q - jac.T @ np.linalg.solve(jac @ jac.T, phi)
        _, jac = self.constraints(q)
        mi_jt = np.linalg.solve(self.mass(q), jac.T)
        v = v - mi_jt @ np.linalg.solve(jac @ mi_jt, jac @ v)
        return q, v

    def energy(self, q, v):
        a = q[self.nr :]
        return self.kinetic(q, v) + 0.5 * a @ self.k_l @ a

    def angular_momentum(self, q, v):
        nr = self.nr
        p = self.frame_of(q)
        mom = (self.mass(q) @ v)[:nr]
        x0 = q[9:12]  # L0 from the origin (L0 starts at the origin here)
        total = np.zeros(3)
        for j, o in enumerate([0, 3, 6, 9]):
            x = x0 + (p[:, j] if j < 3 else 0)
            total += np.cross(x, mom[o : o + 3])
        return total


def self_check(body, rng):
    """h against central differences of T itself; for the first-order T also against
    the closed form the Rust crate uses, h = [2 M_C(P_dot) v_L; 0]."""
    q = rng.normal(size=body.nq) * 1e-2
    v = rng.normal(size=body.nq)
    eps = 1e-3
    dtdq = np.array(
        [
            (body.kinetic(q + eps * e, v) - body.kinetic(q - eps * e, v)) / (2 * eps)
            for e in np.eye(body.nq)
        ]
    )
    mdot = (body.mass(q + eps * v) - body.mass(q - eps * v)) / (2 * eps)
    h_fd = mdot @ v - dtdq
    h = body.quadratic(q, v)
    scale = max(np.abs(h).max(), 1e-300)
    err = np.abs(h - h_fd).max() / scale
    assert err < 1e-8, f"quadratic-velocity vector off central differences by {err:.2e}"
    closed = None
    if body.first_order:
        nr = body.nr
        pdot = (body.jp @ v).reshape(3, 3)
        form = np.concatenate([2 * body.mc(pdot) @ v[nr:], np.zeros(body.nl)])
        closed = np.abs(h - form).max() / scale
    return err, closed


EQUATIONS = {
    # name: (first-order kinetic energy, quadratic-velocity terms), description
    "radioss": (False, False, "M(q) a = Q: Radioss' equations, no quadratic-velocity terms"),
    "form": (False, True, "the Lagrange equations of T = 1/2 v^T M v (section 3's T)"),
    "first": (True, True, "the Lagrange equations of T + v_R^T M_C(P_dot) alpha (first order in alpha)"),
}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("fxb")
    ap.add_argument("--rate", type=float, default=0.018, help="spin / first frequency")
    ap.add_argument("--rad", type=float, default=20.0, help="rotation to integrate (rad)")
    ap.add_argument("--dt", type=float, default=2e-5, help="RK4 step (s)")
    ap.add_argument("--eq", choices=sorted(EQUATIONS), default="first", help="the equations integrated")
    ap.add_argument("--samples", type=int, default=20)
    ap.add_argument("--json", help="write the samples (t, P, L0 position, alpha) here")
    args = ap.parse_args()
    body = Body(args.fxb)
    first_order, with_h, label = EQUATIONS[args.eq]
    body.prepare(first_order)
    err, closed = self_check(body, np.random.default_rng(1))
    print(f"h against central differences of T: {err:.1e}" + ("" if closed is None else f"; against [2 M_C(P_dot) v_L; 0]: {closed:.1e}"))
    axis = body.p0 @ np.array([1.0, -2.0, 3.0])
    w = axis / np.linalg.norm(axis) * args.rate * body.w1
    q = np.zeros(body.nq)
    v = np.zeros(body.nq)
    for j in range(1, 4):
        v[offset(j) : offset(j) + 3] = np.cross(w, body.p0[:, j - 1])
    e0, l0 = body.energy(q, v), body.angular_momentum(q, v)
    t_end = args.rad / np.linalg.norm(w)
    n = int(np.ceil(t_end / args.dt))
    dt = t_end / n
    every = max(n // args.samples, 1)
    samples = []
    t0 = time.time()
    print(f"{args.fxb}: {label}, |w| {np.linalg.norm(w):.4f} rad/s, RK4 dt {dt:.3e} s, {n} steps")
    f = lambda q, v: (v, body.accel(q, v, not with_h))
    for k in range(1, n + 1):
        k1 = f(q, v)
        k2 = f(q + dt / 2 * k1[0], v + dt / 2 * k1[1])
        k3 = f(q + dt / 2 * k2[0], v + dt / 2 * k2[1])
        k4 = f(q + dt * k3[0], v + dt * k3[1])
        q = q + dt / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        v = v + dt / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
        q, v = body.project(q, v)
        if k % every == 0 or k == n:
            de = body.energy(q, v) / e0 - 1
            dl = np.linalg.norm(body.angular_momentum(q, v) - l0) / np.linalg.norm(l0)
            rad = np.linalg.norm(w) * k * dt
            print(f"  {rad:8.2f} rad  dE/E {de:+.3e}  |dL|/|L| {dl:.3e}  ({time.time() - t0:.0f} s)", flush=True)
            samples.append(
                {
                    "t": k * dt,
                    "p": body.frame_of(q).ravel().tolist(),
                    "origin": q[9:12].tolist(),
                    "alpha": q[body.nr :].tolist(),
                    "energy": de,
                    "momentum": dl,
                }
            )
    if args.json:
        with open(args.json, "w") as out:
            json.dump({"fxb": args.fxb, "rate": args.rate, "w0": w.tolist(), "dt": dt, "eq": args.eq, "samples": samples}, out)


if __name__ == "__main__":
    main()
