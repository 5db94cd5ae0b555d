"""Hand computation of two steps of the reference explicit scheme for a tiny free body.

Independent of the Rust code: builds a three-node lumped-mass spring triangle, writes the
raw .fxb block values it implies (FORMULATION.md section 1 definitions), then runs two
cycles of the scheme of FORMULATION.md section 4 literally (unscaled 18x18 / 24x24
saddle-point system solved by numpy). Writes the raw blocks, the steps and the results
to tests/data/free_hand_step.json, which the Rust tests (free::explicit::hand_*) load;
tests/python/test_free_hand_step.py checks the committed file is what this script writes.

Run: python tests/reference/free_hand_step.py [--out FILE]  (numpy only)
"""

import argparse
import json
import os

import numpy as np

DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data", "free_hand_step.json")


def rot(ax, ay, az):
    cx, sx, cy, sy, cz, sz = np.cos(ax), np.sin(ax), np.cos(ay), np.sin(ay), np.cos(az), np.sin(az)
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rz @ ry @ rx


def build(irot):
    x = np.array([[0.3, -0.2, 0.1], [1.4, 0.5, -0.3], [0.2, 1.1, 0.6]])
    mass = np.array([1.0, 2.0, 1.5])
    jrot = np.array([0.01, 0.02, 0.015])
    springs = [(0, 1, 1000.0), (1, 2, 1500.0), (0, 2, 2000.0)]
    p0 = rot(0.3, -0.5, 0.8)
    n = 3
    ndof = 6 * n
    xl0 = (mass[:, None] * x).sum(0) / mass.sum()
    loc = (x - xl0) @ p0  # rows: P0^T (x - xL0)
    M = np.zeros((ndof, ndof))
    for i in range(n):
        for c in range(3):
            M[6 * i + c, 6 * i + c] = mass[i]
            if irot:
                M[6 * i + 3 + c, 6 * i + 3 + c] = jrot[i]
    K = np.zeros((ndof, ndof))
    for a, b, k in springs:
        d = x[b] - x[a]
        e = d / np.linalg.norm(d)
        kk = k * np.outer(e, e)
        for (i, si), (j, sj) in [((a, 1), (a, 1)), ((b, 1), (b, 1)), ((a, 1), (b, -1)), ((b, -1), (a, 1))]:
            K[6 * i:6 * i + 3, 6 * j:6 * j + 3] += si * sj * kk
    R = np.zeros((ndof, ndof))
    for i in range(n):
        R[6 * i:6 * i + 3, 6 * i:6 * i + 3] = p0
        R[6 * i + 3:6 * i + 6, 6 * i + 3:6 * i + 6] = p0
    Kloc = R.T @ K @ R
    # Deformation modes of the translational part, local frame.
    tr = [6 * i + c for i in range(n) for c in range(3)]
    Kt = Kloc[np.ix_(tr, tr)]
    Mt = np.diag(np.repeat(mass, 3))
    s = 1 / np.sqrt(np.diag(Mt))
    lam, vec = np.linalg.eigh(s[:, None] * Kt * s[None, :])
    phis = s[:, None] * vec[:, lam > 1e-6 * lam.max()]
    # Sign rule: each mode's local z at the first node (0.44, 0.17, ... of the mode's
    # scale) positive. LAPACK may return either sign; a fixed rule makes the output the
    # same on every machine (this one keeps the values first committed).
    phis = phis * np.sign(phis[2])
    phi1 = np.zeros(ndof)
    phi2 = np.zeros(ndof)
    th = 0.4
    phi1[tr] = 1.3 * (np.cos(th) * phis[:, 0] + np.sin(th) * phis[:, 1])
    phi2[tr] = 0.7 * (-np.sin(th) * phis[:, 0] + np.cos(th) * phis[:, 1])
    if irot:
        phi1[[3, 4, 5, 9, 10, 11, 15, 16, 17]] = [0.1, -0.2, 0.3, 0.05, 0.0, -0.1, 0.2, 0.1, 0.0]
    PhiL = np.stack([phi1, phi2], 1)
    nl, ns = 2, 1
    mL = np.diag(PhiL.T @ M @ PhiL).copy()
    off = PhiL.T @ M @ PhiL - np.diag(mL)
    assert np.abs(off).max() < 1e-12 * mL.max()
    KL = PhiL.T @ Kloc @ PhiL
    nr = 15 if irot else 12
    PhiR = np.zeros((ndof, nr))
    for i in range(n):
        X = loc[i]
        for j in range(3):
            for c in range(3):
                PhiR[6 * i + c, 3 * j + c] = X[j]
        for c in range(3):
            PhiR[6 * i + c, 9 + c] = 1 - X.sum()
            if irot:
                PhiR[6 * i + 3 + c, 12 + c] = 1.0
    MR = PhiR.T @ M @ PhiR

    def T(k, l, v):
        out = np.zeros_like(v)
        for i in range(n):
            out[6 * i + k] = v[6 * i + l]
            out[6 * i + 3 + k] = v[6 * i + 3 + l]
        return out

    MC = np.zeros((3, 3, nr, nl))
    KC = np.zeros((3, 3, nr, nl))
    for k in range(3):
        for l in range(3):
            for i in range(nr):
                for j in range(nl):
                    MC[k, l, i, j] = T(k, l, PhiL[:, j]) @ M @ PhiR[:, i]
                    KC[k, l, i, j] = PhiL[:, j] @ Kloc @ T(k, l, PhiR[:, i])
    sm = 1 / np.sqrt(mL)
    freq = np.sqrt(np.linalg.eigvalsh(sm[:, None] * KL * sm[None, :]).max()) / (2 * np.pi)
    damp = (0.5, 1e-4)
    raw = dict(
        nbmod=nl, nbstat=ns, nbnod=n, irot=irot, node_ids=[11, 12, 13], p0=p0.reshape(-1),
        freq=freq, damping=damp,
        rigid_modes=PhiR.T.reshape(-1), local_modes=PhiL.T.reshape(-1), m_l=mL,
        k_full=np.array([KL[0, 0], KL[0, 1]]), k_diag=np.array([KL[1, 1]]),
        m_r=np.array([MR[i, j] for i in range(nr) for j in range(i, nr)]),
        m_c=MC.reshape(-1), k_c=KC.reshape(-1),
    )
    body = dict(x=x, p0=p0, PhiR=PhiR, PhiL=PhiL, mL=mL, KL=KL, MR=MR, MC=MC, KC=KC,
                nr=nr, nl=nl, freq=freq, damp=damp, irot=irot)
    return raw, body


JUMP = [-4.0, 1.0, 2.0, 0.0, 0.5, -0.1, 2.0, 0.0, -1.5, 0.3, 0.0, 0.2]

PAIRS = [(1, 0, 1.0), (2, 0, 1.0), (3, 0, 1.0), (2, 1, 2.0), (3, 1, 2.0), (3, 2, 2.0)]


def off(p):
    return 9 if p == 0 else 3 * (p - 1)


def accelerations(body, scene, st, t, dt1, dt2):
    """Steps 2 to 6 of the scheme at the current positions; returns (a_R, a_L)."""
    nr, nl, irot = body["nr"], body["nl"], body["irot"]
    PhiR, PhiL, mL, KL, MR = body["PhiR"], body["PhiL"], body["mL"], body["KL"], body["MR"]
    aR, beta = body["damp"]
    P, vR, vL, alpha = st["P"], st["vR"], st["vL"], st["alpha"]
    g = np.array(scene["gravity"])
    s = np.zeros(nr)
    for c in range(3):
        for j in range(4):
            s[3 * j + c] = g[c]
    nodes = scene["nodes"]
    loads = np.array(st["load_values"]) + np.array(scene["rates"]) * (t - st["t_set"])
    # Step 2: loads with the current frame; M_C, K_C.
    FR, FL = np.zeros(nr), np.zeros(nl)
    for k, nd in enumerate(nodes):
        f, m = loads[6 * k:6 * k + 3], loads[6 * k + 3:6 * k + 6]
        for i in range(nr):
            if i < 12:
                FR[i] += f @ PhiR[6 * nd:6 * nd + 3, i]
            else:
                FR[i] += m @ PhiR[6 * nd + 3:6 * nd + 6, i]
        for j in range(nl):
            FL[j] += f @ (P @ PhiL[6 * nd:6 * nd + 3, j]) + m @ (P @ PhiL[6 * nd + 3:6 * nd + 6, j])
    MC = sum(P[k, l] * body["MC"][k, l] for k in range(3) for l in range(3))
    KC = sum(P[l, k] * body["KC"][k, l] for k in range(3) for l in range(3))
    GR, GL = MR @ s, MC.T @ s
    # Step 3.
    SL = FL + GL - KL @ alpha - (beta * KL + aR * np.diag(mL)) @ vL
    f1 = 1 + aR * dt1 / 2
    MVN = MC @ np.diag(1 / mL) / f1
    SR = FR + GR - KC @ alpha - MVN @ SL
    Mstar = MR - MVN @ MC.T
    # Step 4: constraint rows.
    nc = 9 if irot else 6
    C = np.zeros((nc, nr))
    rhs = np.zeros(nc)
    E = [np.zeros(3), P[:, 0], P[:, 1], P[:, 2]]
    for r, (a, b, c) in enumerate(PAIRS):
        d = E[a] - E[b]
        w = vR[off(a):off(a) + 3] - vR[off(b):off(b) + 3]
        C[r, off(a):off(a) + 3] += d + dt2 * w
        C[r, off(b):off(b) + 3] -= d + dt2 * w
        rhs[r] = (c - d @ d) / (dt2 * (dt1 + dt2)) - (2 * d + dt2 * w) @ w / (dt1 + dt2)
    if irot:
        # v_rot^(n+1/2) = omega(R, v^(n+1/2)), omega = R (-e2.de3, e1.de3, -e1.de2).
        # Frame: the mid-step frame predicted with the old half-step velocities.
        R = P + dt2 / 2 * np.stack([vR[3 * j:3 * j + 3] - vR[9:12] for j in range(3)], 1)

        def omega(vv):
            e1, e2, e3 = R[:, 0], R[:, 1], R[:, 2]
            de2 = vv[3:6] - vv[9:12]
            de3 = vv[6:9] - vv[9:12]
            return R @ np.array([-e2 @ de3, e1 @ de3, -e1 @ de2])
        B = np.stack([omega(np.eye(nr)[i]) for i in range(12)], 1)  # 3 x 12
        dt12 = (dt1 + dt2) / 2
        C[6:9, :12] = -B
        C[6:9, 12:15] = np.eye(3)
        rhs[6:9] = (B @ vR[:12] - vR[12:15]) / dt12
    # Step 5.
    A = np.block([[Mstar, -C.T], [-C, np.zeros((nc, nc))]])
    sol = np.linalg.solve(A, np.concatenate([SR, -rhs]))
    accR = sol[:nr]
    # Step 6.
    accL = SL / (mL * (1 + aR * dt2 / 2)) - MVN.T @ accR
    return accR, accL


def run(body, scene, comm, nsub, jump=None):
    """Communication steps `comm`, each split into `nsub` equal internal steps. Loads
    `scene["loads"]` set at t = 0 with rates `scene["rates"]`; with `jump`, the load
    values are set to `jump` at the start of the second communication step. After such a
    jump the scheme restarts: velocities synchronised with the old loads
    (v^n = v^(n-1/2) + dt/2 a^n) and dt1 = 0. Without a jump the internal steps continue
    across the communication point with dt1 = the previous step."""
    nr, nl, irot = body["nr"], body["nl"], body["irot"]
    p0 = body["p0"]
    V, W = np.array(scene["v0"]), np.array(scene["w0"])
    vR = np.zeros(nr)
    for j in range(3):
        vR[3 * j:3 * j + 3] = V + np.cross(W, p0[:, j])
    vR[9:12] = V
    if irot:
        vR[12:15] = W
    st = dict(qR=np.zeros(nr), vR=vR, vL=np.zeros(nl), alpha=np.zeros(nl), P=p0.copy(),
              load_values=np.array(scene["loads"], dtype=float), t_set=0.0)
    t, dt1 = 0.0, 0.0
    for k, h in enumerate(comm):
        if k == 1 and jump is not None:
            # Synchronised velocities with the old loads, then the new loads.
            aR_, aL_ = accelerations(body, scene, st, t, dt1, dt1)
            st["vR"] = st["vR"] + dt1 / 2 * aR_
            st["vL"] = st["vL"] + dt1 / 2 * aL_
            st["load_values"] = np.array(jump, dtype=float)
            st["t_set"] = t
            dt1 = 0.0
        dt2 = h / nsub
        for _ in range(nsub):
            accR, accL = accelerations(body, scene, st, t, dt1, dt2)
            # Step 7.
            dt12 = (dt1 + dt2) / 2
            st["vR"] = st["vR"] + dt12 * accR
            st["vL"] = st["vL"] + dt12 * accL
            # Step 1 of the next cycle: positions and frame columns.
            st["qR"] = st["qR"] + dt2 * st["vR"]
            st["alpha"] = st["alpha"] + dt2 * st["vL"]
            qR = st["qR"]
            st["P"] = p0 + np.stack([qR[3 * j:3 * j + 3] - qR[9:12] for j in range(3)], 1)
            t += dt2
            dt1 = dt2
    qR, alpha, P = st["qR"], st["alpha"], st["P"]
    pos = []
    for nd in scene["nodes"]:
        PhiR, PhiL = body["PhiR"], body["PhiL"]
        u = PhiR[6 * nd:6 * nd + 3, :12] @ qR[:12] + P @ (PhiL[6 * nd:6 * nd + 3] @ alpha)
        pos.append(body["x"][nd] + u)
    return dict(q=np.concatenate([qR, alpha]), v=np.concatenate([st["vR"], st["vL"]]), p=P,
                pos=np.concatenate(pos))


def flat(arr):
    return [float(v) for v in np.asarray(arr, dtype=float).reshape(-1)]


def compute():
    """Both bodies (Irot 0 and 1): the raw blocks, the steps and the three cases."""
    out = {}
    for irot in (False, True):
        raw, body = build(irot)
        dt_fx = 1 / (np.pi * body["freq"])  # undamped bound; the scheme's steps stay below
        # Case A: one communication step of two internal steps (h = 1.4 x 0.9 dt_fx).
        # Case B: two communication steps of one internal step each, loads unchanged
        # (variable steps dt1 != dt2 across the communication point).
        # Case C: as B with a load jump at the second communication step (restart).
        ha = 1.4 * 0.9 * dt_fx
        hb = [0.31 * dt_fx, 0.47 * dt_fx]
        scene = dict(nodes=[0, 2], gravity=[0.3, -0.2, -9.81], v0=[0.4, -0.3, 0.2],
                     w0=[0.7, -0.5, 1.1],
                     loads=[3.0, -2.0, 1.5, 0.4, -0.3, 0.2, -1.0, 2.5, 0.5, 0.1, 0.2, -0.3],
                     rates=[10.0, 0.0, -5.0, 1.0, 0.0, 0.0, 0.0, 3.0, 0.0, 0.0, -2.0, 0.0])
        out1 = run(body, scene, [ha], 2)
        out2 = run(body, scene, hb, 1)
        out3 = run(body, scene, hb, 1, jump=JUMP)
        case = {"p0": flat(raw["p0"]), "freq": float(raw["freq"]),
                "damping": [float(v) for v in raw["damping"]]}
        for key in ["rigid_modes", "local_modes", "m_l", "k_full", "k_diag", "m_r", "m_c", "k_c"]:
            case[key] = flat(raw[key])
        case.update(x0=flat(body["x"]), ha=float(ha), hb=flat(hb), jump=flat(JUMP),
                    qa=flat(out1["q"]), va=flat(out1["v"]), pa=flat(out1["p"]),
                    qb=flat(out2["q"]), vb=flat(out2["v"]), pb=flat(out2["p"]),
                    posb=flat(out2["pos"]),
                    qc=flat(out3["q"]), vc=flat(out3["v"]), pc=flat(out3["p"]))
        out["rot" if irot else "norot"] = case
    return out


def write(data, path):
    """One key per line: the file diffs by quantity."""
    lines = ['{"source": "written by tests/reference/free_hand_step.py; do not edit",']
    for i, (name, case) in enumerate(data.items()):
        lines.append(f' "{name}": {{')
        items = list(case.items())
        for j, (key, value) in enumerate(items):
            comma = "," if j + 1 < len(items) else ""
            lines.append(f'  "{key}": {json.dumps(value)}{comma}')
        lines.append(" }" + ("," if i + 1 < len(data) else ""))
    lines.append("}")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=DATA, help="output file (default: tests/data/free_hand_step.json)")
    write(compute(), ap.parse_args().out)


if __name__ == "__main__":
    main()
