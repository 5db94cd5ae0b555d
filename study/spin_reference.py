"""A reference integration of a free flexible body's exact floating-frame equations, in numpy.

Independent of the Rust crate (it shares no code with it): the body's finite-element
model (its mass matrix M, node coordinates X in the local frame, from fixtures/bodies.py)
and its local modes and local stiffness (Phi_L, K_L, read from the shipped `.fxb` with
fixtures/fxbread.py).

Kinematics (docs/FORMULATION.md section 3, "The exact kinetic energy"): a node at local
position `X_n` sits, deformed, at `x_n = x_L0 + P (X_n + Phi_t(n) alpha)`; its rotational
DOFs turn at `omega + P Phi_r(n) alpha_dot`. In the frame's own components, with the
body velocities `nu = (v, w, alpha_dot)` (`v = P^T x_L0_dot`, `w = P^T omega`), every
FE DOF velocity is `u = Psi(alpha) nu`,

    Psi(alpha) = [ T | W0 + sum_j alpha_j W_j | Phi_L ],

T the unit translations, W0 the rotation about L0 (`w x X_n` on translations, `w` on
rotations), W_j the rotation of mode j's displacement (`w x Phi_t,j(n)`, nothing on
rotations). The kinetic energy is exactly `T = 1/2 nu^T M(alpha) nu` with
`M(alpha) = Psi^T M Psi`, quadratic in alpha, and the equations are the
Lagrange (Hamel) equations on the frame's group with the momenta `p = M(alpha) nu`:

    p_v' = p_v x w,   p_w' = p_w x w + p_v x v,
    p_a' = dT/dalpha - K_L alpha,   dT/dalpha_j = (w x Phi_t,j)^T (M u)_t,
    alpha' = alpha_dot,   P' = P [w],   x_L0' = P v.

Torque-free, they conserve the energy `T + 1/2 alpha^T K_L alpha` and the angular
momentum `x_L0 x P p_v + P p_w` exactly.

Integrators: `midpoint` (default) the implicit midpoint rule on (p, alpha) with the frame
turned by the Cayley map of the mid-step rate, solved by a simplified Newton iteration
(numerical Jacobian, refreshed when the iteration slows): it keeps the angular momentum
to round-off by construction and the energy within a bounded O(h^2) oscillation; `rk`
scipy's DOP853 at tight tolerances (slow: the truss's highest local modes are stiff).

`--check` compares the kinetic energy the withdrawn first-order attempt used
(`T_form + v_R^T M_C(P_dot) alpha`, built from the file's M_R and M_C,kl) with the exact
one on random states: the difference must be second order in alpha for the attempt to be
consistent.

    .venv/bin/python study/spin_reference.py truss --rad 400 --dt 1e-3
    .venv/bin/python study/spin_reference.py freefree --rad 400 --dt 1e-3
    .venv/bin/python study/spin_reference.py truss --check

Measured (spin at 0.018 of the first frequency about P0 (1, -2, 3), 1 ms steps): the
free-free beam keeps its energy to 2.0e-14 and its angular momentum to 3.1e-14 over
400 rad (5.2 iterations per step, 20 min), its attitude 2.1e-3 rad off the rigid Euler
path of its undeformed inertia; the truss keeps them to 5.9e-10 and 3.6e-14 over 400 rad
(11.4 iterations per step, 63 min on a loaded 2-core machine). `--check`: on the truss the
withdrawn first-order T equals the exact T to first order in alpha (6e-10 of T); on the
free-free beam it is off at first order (2.5e-5 of T at 1 mm of deflection, 2.6e-7 at
0.01 mm), 20 to 40 times less without the rotational rows' `P_dot Phi_r alpha`
(docs/FORMULATION.md section 3).
"""

import argparse
import os
import sys
import time

import numpy as np
import scipy.linalg as sl

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "fixtures"))
import bodies  # noqa: E402
from build import rot_blocks  # noqa: E402
from fxbread import read_fxb  # noqa: E402


def skew(x):
    return np.array([[0.0, -x[2], x[1]], [x[2], 0.0, -x[0]], [-x[1], x[0], 0.0]])


def cayley(x):
    s = skew(x)
    return np.linalg.solve(np.eye(3) - 0.5 * s, np.eye(3) + 0.5 * s)


class Body:
    """The exact floating-frame model of one fixture."""

    def __init__(self, name):
        spec = getattr(bodies, name)()
        fxb = read_fxb(open(os.path.join(HERE, "..", "fixtures", name + ".fxb")).read())
        self.dpn = spec["dpn"]
        self.m = np.asarray(spec["M"], float)  # local-frame FE mass (build.py rotates it by P0)
        self.x = np.asarray(spec["X"], float)
        n = self.x.shape[0]
        self.n = n
        self.p0 = fxb["p0"]
        self.nl = fxb["nbmod"]
        self.k_l = fxb["k_l"]
        local = fxb["local"].reshape(n, 6, self.nl)
        self.phi_t = local[:, :3, :]
        self.phi_r = local[:, 3:, :]
        self.fxb = fxb
        # The file's rigid modes 1, 4, 7 are the local coordinates: the same nodes?
        rig = fxb["rigid"].reshape(n, 6, -1)
        xr = np.stack([rig[:, 0, 0], rig[:, 0, 3], rig[:, 0, 6]], axis=1)
        self.coord_err = float(np.abs(xr - self.x).max())
        ndof = self.m.shape[0]
        self.ndof = ndof
        self.tr = np.array([self.dpn * k + c for k in range(n) for c in range(3)])
        # Psi pieces.
        t = np.zeros((ndof, 3))
        w0 = np.zeros((ndof, 3))
        phi = np.zeros((ndof, self.nl))
        for k in range(n):
            b = self.dpn * k
            t[b : b + 3] = np.eye(3)
            w0[b : b + 3] = -skew(self.x[k])
            phi[b : b + 3] = self.phi_t[k]
            if self.dpn == 6:
                w0[b + 3 : b + 6] = np.eye(3)
                phi[b + 3 : b + 6] = self.phi_r[k]
        self.t, self.w0, self.phi = t, w0, phi
        # Independent checks of the model against the file: m_L and M_R's mass.
        self.m_l_err = float(np.abs(np.diag(phi.T @ self.m @ phi) / fxb["m_l"] - 1).max())
        self.w1 = 2 * np.pi * fxb["freq"]  # replaced below by the first stored frequency
        w2 = sl.eigh(self.k_l, np.diag(fxb["m_l"]), eigvals_only=True)
        self.w_top = float(np.sqrt(w2.max()))

    def psi(self, a):
        ps = np.empty((self.ndof, 6 + self.nl))
        ps[:, :3] = self.t
        w = self.w0.copy()
        disp = self.phi_t @ a  # (n, 3)
        for k in range(self.n):
            b = self.dpn * k
            w[b : b + 3] -= skew(disp[k])
        ps[:, 3:6] = w
        ps[:, 6:] = self.phi
        return ps

    def mass(self, a):
        ps = self.psi(a)
        return ps.T @ self.m @ ps, ps

    def rates(self, y):
        """(p, alpha) -> (p', alpha') and the body velocities nu."""
        nl = self.nl
        p, a = y[: 6 + nl], y[6 + nl :]
        mm, ps = self.mass(a)
        nu = np.linalg.solve(mm, p)
        v, w = nu[:3], nu[3:6]
        mu = (self.m @ (ps @ nu))[self.tr].reshape(self.n, 3)
        # dT/dalpha_j = sum_n (w x Phi_t,j(n)) . (M u)_n = w . sum_n Phi_t,j(n) x (M u)_n
        cr = np.cross(self.phi_t, mu[:, :, None], axisa=1, axisb=1, axisc=1)  # (n, 3, nl)
        dtda = w @ cr.sum(axis=0)
        dp = np.empty_like(p)
        dp[:3] = np.cross(p[:3], w)
        dp[3:6] = np.cross(p[3:6], w) + np.cross(p[:3], v)
        dp[6:] = dtda - self.k_l @ a
        return np.concatenate([dp, nu[6:]]), nu

    def energy(self, y):
        nl = self.nl
        p, a = y[: 6 + nl], y[6 + nl :]
        mm, _ = self.mass(a)
        return 0.5 * p @ np.linalg.solve(mm, p) + 0.5 * a @ self.k_l @ a

    def start(self, w_global):
        """Torque-free spin, modes at rest: p = M(0) (0, P0^T w, 0)."""
        nu = np.zeros(6 + self.nl)
        nu[3:6] = self.p0.T @ w_global
        mm, _ = self.mass(np.zeros(self.nl))
        return np.concatenate([mm @ nu, np.zeros(self.nl)])


def jacobian(body, y, f0):
    n = y.size
    jac = np.empty((n, n))
    scale = np.maximum(np.abs(y), 1e-8 * np.abs(y).max())
    for i in range(n):
        e = 1e-7 * scale[i]
        yy = y.copy()
        yy[i] += e
        jac[:, i] = (body.rates(yy)[0] - f0) / e
    return jac


def midpoint(body, y0, p_frame, dt, steps, every, report):
    """Implicit midpoint on (p, alpha), Cayley on the frame (module text)."""
    n = y0.size
    f0, _ = body.rates(y0)
    lu = sl.lu_factor(np.eye(n) - 0.5 * dt * jacobian(body, y0, f0))
    y, p = y0.copy(), p_frame.copy()
    iters_total = 0
    for k in range(1, steps + 1):
        y1 = y + dt * body.rates(y)[0]
        prev = np.inf
        np_ = 6 + body.nl
        for it in range(30):
            ym = 0.5 * (y + y1)
            fm, nu = body.rates(ym)
            g = y1 - y - dt * fm
            d = sl.lu_solve(lu, g)
            y1 = y1 - d
            # change relative to each block's size; stop at round-off (it stops falling)
            r = max(np.abs(d[:np_]).max() / np.abs(y1[:np_]).max(),
                    np.abs(d[np_:]).max() / max(np.abs(y1[np_:]).max(), 1e-300))
            if r < 1e-15 or (r < 1e-12 and r > 0.3 * prev):
                break
            prev = r
        iters_total += it + 1
        if it > 10:  # refresh the Jacobian when the iteration slows
            fm, _ = body.rates(y1)
            lu = sl.lu_factor(np.eye(n) - 0.5 * dt * jacobian(body, y1, fm))
        _, nu = body.rates(0.5 * (y + y1))
        p = p @ cayley(dt * nu[3:6])
        y = y1
        if k % every == 0 or k == steps:
            report(k, y, p)
    return y, p, iters_total / steps


def euler_rigid(inertia, w_body0, p0, t_end, dt):
    """The rigid body (inertia about L0, body frame), the same midpoint/Cayley scheme at a
    small step: the rigid Euler path."""
    l = inertia @ w_body0
    p = p0.copy()
    steps = int(np.ceil(t_end / dt))
    h = t_end / steps
    inv = np.linalg.inv(inertia)
    for _ in range(steps):
        l1 = l.copy()
        for _ in range(50):
            lm = 0.5 * (l + l1)
            wm = inv @ lm
            new = l + h * np.cross(lm, wm)
            if np.abs(new - l1).max() <= 1e-16 * np.abs(l).max():
                l1 = new
                break
            l1 = new
        p = p @ cayley(h * inv @ (0.5 * (l + l1)))
        l = l1
    return p


def check_first_order(body, rng):
    """T of the withdrawn first-order attempt against the exact T (module text)."""
    fxb = body.fxb
    nl = body.nl
    m_r, m_c = fxb["m_r"], fxb["m_c"]  # m_c[k, l] (nr x nl)
    nr = m_r.shape[0]
    out = []
    for s in [1e-3, 1e-4, 1e-5]:
        rows = []
        for _ in range(5):
            a = rng.normal(size=nl)
            a *= s / np.abs(body.phi_t @ a).max()  # largest displacement s (m)
            ad = rng.normal(size=nl) * 0.0
            w = rng.normal(size=3)
            v = rng.normal(size=3) * 0.0
            rot = sl.expm(skew(rng.normal(size=3)))
            p = body.p0 @ rot
            nu = np.concatenate([v, w, ad])
            mm, _ = body.mass(a)
            t_exact = 0.5 * nu @ mm @ nu
            # The same motion in the file's coordinates: frame-point velocities.
            omega = p @ w
            vr = np.zeros(nr)
            vr[9:12] = p @ v
            for j in range(3):
                vr[3 * j : 3 * j + 3] = p @ v + np.cross(omega, p[:, j])
            if nr == 15:
                vr[12:15] = omega
            pdot = skew(omega) @ p
            mc = np.einsum("kl,klrj->rj", p, m_c)
            mcd = np.einsum("kl,klrj->rj", pdot, m_c)
            t_form = 0.5 * vr @ m_r @ vr + vr @ mc @ ad + 0.5 * np.sum(fxb["m_l"] * ad**2)
            t_first = t_form + vr @ mcd @ a
            # the exact T to first order in alpha:
            mm0, _ = body.mass(np.zeros(nl))
            eps = 1e-6
            d1 = (0.5 * nu @ body.mass(a * eps)[0] @ nu - 0.5 * nu @ mm0 @ nu) / eps
            t_lin = 0.5 * nu @ mm0 @ nu + d1
            # what the attempt adds that no motion has: the rotational DOFs' part of
            # P_dot Phi_L alpha (a node's rotation rate is omega + P Phi_r alpha_dot: the
            # frame turning carries the local rotation along, it adds no rate)
            spur = np.zeros(body.ndof)
            if body.dpn == 6:
                for k in range(body.n):
                    spur[6 * k + 3 : 6 * k + 6] = np.cross(w, body.phi_r[k] @ a)
            t_spur = (body.psi(np.zeros(nl)) @ nu) @ body.m @ spur
            rows.append((abs(t_first - t_exact) / t_exact, abs(t_lin - t_exact) / t_exact,
                         abs(t_first - t_lin) / t_exact,
                         abs(t_first - t_lin - t_spur) / t_exact))
        out.append((s, np.max(rows, axis=0)))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("body", choices=["truss", "freefree"])
    ap.add_argument("--rate", type=float, default=0.018, help="spin / first frequency")
    ap.add_argument("--rad", type=float, default=400.0, help="rotation to integrate (rad)")
    ap.add_argument("--dt", type=float, default=1e-3, help="step (s)")
    ap.add_argument("--samples", type=int, default=10)
    ap.add_argument("--check", action="store_true", help="first-order T against the exact T")
    args = ap.parse_args()
    body = Body(args.body)
    print(f"{args.body}: {body.n} nodes, {body.nl} local modes; model against file: "
          f"local coordinates {body.coord_err:.1e} m, m_L {body.m_l_err:.1e}")
    if args.check:
        for s, (first, lin, diff, rest) in check_first_order(body, np.random.default_rng(1)):
            print(f"  displacement {s:.0e} m: |T_first - T|/T {first:.2e}, "
                  f"|T_lin - T|/T {lin:.2e}, |T_first - T_lin|/T {diff:.2e}, "
                  f"without the rotational rows' P_dot Phi_r alpha {rest:.2e}")
        return
    # first elastic frequency of the body as the Rust tests take it (the file's first stored
    # frequency is not read by fxbread: use (K_L, m_L)'s lowest, as the tests' w_1)
    w2 = sl.eigh(body.k_l, np.diag(body.fxb["m_l"]), eigvals_only=True)
    w1 = float(np.sqrt(w2[w2 > 0][0]))
    axis = body.p0 @ np.array([1.0, -2.0, 3.0])
    w = axis / np.linalg.norm(axis) * args.rate * w1
    y = body.start(w)
    e0 = body.energy(y)
    l0 = body.p0 @ y[3:6]
    t_end = args.rad / np.linalg.norm(w)
    steps = int(np.ceil(t_end / args.dt))
    dt = t_end / steps
    print(f"  w_1 {w1:.2f} rad/s, |w| {np.linalg.norm(w):.4f} rad/s, highest local "
          f"{body.w_top:.0f} rad/s, midpoint dt {dt:.3e} s, {steps} steps")
    worst = {"e": 0.0, "l": 0.0}
    t0 = time.time()

    def report(k, yk, pk):
        de = body.energy(yk) / e0 - 1
        dl = np.linalg.norm(pk @ yk[3:6] - l0) / np.linalg.norm(l0)
        worst["e"] = max(worst["e"], abs(de))
        worst["l"] = max(worst["l"], dl)
        print(f"  {np.linalg.norm(w) * k * dt:8.1f} rad  dE/E {de:+.3e}  |dL|/|L| {dl:.3e}  "
              f"|p_v| {np.linalg.norm(yk[:3]):.1e}  ({time.time() - t0:.0f} s)", flush=True)

    y, p, iters = midpoint(body, y, body.p0.copy(), dt, steps, max(steps // args.samples, 1),
                           report)
    print(f"  max |dE/E| {worst['e']:.2e}, max |dL|/|L| {worst['l']:.2e}, "
          f"{iters:.1f} iterations per step")
    inertia = body.w0.T @ body.m @ body.w0
    p_rigid = euler_rigid(inertia, body.p0.T @ w, body.p0, t_end, min(dt, 1e-3) / 4)
    dev = np.linalg.norm(sl.logm(p_rigid.T @ p).real)
    dev = np.sqrt(0.5) * dev
    print(f"  attitude off the rigid Euler path after {args.rad:.0f} rad: {dev:.2e} rad")


if __name__ == "__main__":
    main()
