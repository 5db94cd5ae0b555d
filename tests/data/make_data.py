#!/usr/bin/env python3
"""Write the small .fxb test files of tests/data (pure Python, no numpy).

Two families (the hand-written format variants fmt_*.fxb are not generated):

* labels_*.fxb: every value encodes its own position, so a test can check where each
  value lands in the matrices against the storage orders of FORMULATION.md section 1.
  Not a physical body (only Body::assemble is used on them).
* body_b{iblo}_r{irot}_d{idamp}.fxb: a body of point masses for each flag combination,
  its rigid part built as `fxbody import` builds it (docs/FORMULATION.md section 1): M_R
  from the exact rigid mass properties (W (x) I3 on the affine modes, d I3 on modes
  13..15) and M_C,kl(i,j) = (T_lk Phi_R,i)^T M Phi_L,j, the rotation on the rigid mode.
  For point masses, the same in every direction, these equal Phi_R^T M Phi_R and the
  rotation on the local mode to round-off, and the load-time invariance check passes.
  m_L = diag(Phi_L^T M Phi_L) from the masses below, K_L chosen with eigenvalues known
  in closed form. Not a physical body in two respects, on purpose (format and flag
  tests): the made-up local modes are neither M-orthogonal nor free of rigid motion,
  and K_C holds plain numbers (no stiffness model behind it).
  Total mass = sum of MASSES (tests check this against `info`).

Run from the repository root: python3 tests/data/make_data.py [OUT_DIR] (default: this
folder; tests/python/test_data_bodies.py writes elsewhere and compares).
"""

import math
import os

OUT = os.path.dirname(os.path.abspath(__file__))


def e16(v):
    """Fortran 1PE16.9."""
    if v == 0:
        return " 0.000000000E+00"
    s = "%.9E" % v
    mant, exp = s.split("E")
    return ("%16s" % (mant + "E" + exp[0] + exp[1:].rjust(2, "0")))


def reals(values, style):
    lines = []
    for k in range(0, len(values), 5):
        chunk = values[k:k + 5]
        if style == "fixed":
            lines.append("".join(e16(v) for v in chunk))
        else:
            # 13 significant digits, separated by a blank or a tab: the tokens are longer
            # than 16 columns, so the fixed-column reading fails and is not ambiguous.
            seps = [" ", "\t", "  ", " \t"]
            text = ""
            for i, v in enumerate(chunk):
                text += ("" if i == 0 else seps[i % 4]) + "%.12e" % v
            lines.append(text)
    return lines


def modes_lines(modes, nnodes, style):
    lines = []
    for mode in modes:
        for n in range(nnodes):
            six = mode[6 * n:6 * n + 6]
            lines += reals(six[:5], style)
            lines += reals(six[5:], style)
    return lines


def write_file(name, f, style):
    L = ["# %s: written by tests/data/make_data.py (%s layout)" % (name, style)]
    L.append("# block 1")
    hdr = [f["nbmod"], f["nbstat"], len(f["ids"]), f["irot"], f["idamp"], f["iblo"], f["ifile"]]
    L.append("".join("%8d" % v for v in hdr))
    L.append("# block 2")
    for k in range(0, len(f["ids"]), 10):
        L.append("".join("%8d" % v for v in f["ids"][k:k + 10]))
    L.append("# block 3")
    L += reals(f["p0"] + [f["freq"]], style)
    if f["idamp"]:
        L.append("# block 4")
        L += reals(list(f["damping"]), style)
    n = len(f["ids"])
    if not f["iblo"]:
        L.append("# blocks 5+6")
        L += modes_lines(f["rigid"], n, style)
    L.append("# block 7")
    L += modes_lines(f["local"], n, style)
    for b, key in [(8, "m_l"), (9, "k_full"), (10, "k_diag")]:
        L.append("# block %d" % b)
        L += reals(f[key], style)
    if not f["iblo"]:
        L.append("# block 11")
        L += reals(f["m_r"], style)
        if f["nbmod"] > 0:
            for b, key in [(12, "m_c"), (13, "k_c")]:
                for m in range(9):
                    L.append("# block %d sub-block %d" % (b, m + 1))
                    L += reals(f[key][m], style)
    with open(os.path.join(OUT, name), "w") as fh:
        fh.write("\n".join(L) + "\n")


# ---------------------------------------------------------------- labelled files
def labelled(name, irot, idamp, nl, ns, ids, style):
    n = len(ids)
    nr = 15 if irot else 12
    f = dict(nbmod=nl, nbstat=ns, irot=irot, idamp=idamp, iblo=0, ifile=1, ids=ids)
    f["p0"] = [31.0 + k for k in range(9)]
    f["freq"] = 40.0
    f["damping"] = (4.5, 0.25)
    # mode i (1-based), node position p (1-based), component c (1-based)
    f["rigid"] = [[1e6 + 1000 * i + 10 * p + c for p in range(1, n + 1) for c in range(1, 7)]
                  for i in range(1, nr + 1)]
    f["local"] = [[2e6 + 1000 * j + 10 * p + c for p in range(1, n + 1) for c in range(1, 7)]
                  for j in range(1, nl + 1)]
    f["m_l"] = [30.0 + j for j in range(1, nl + 1)]
    f["k_full"] = [900.0 + k for k in range(1, ns * (2 * nl - ns + 1) // 2 + 1)]
    f["k_diag"] = [800.0 + k for k in range(1, nl - ns + 1)]
    f["m_r"] = [1100.0 + k for k in range(1, nr * (nr + 1) // 2 + 1)]
    f["m_c"] = [[12e6 + 10000 * m + 100 * i + j for i in range(1, nr + 1) for j in range(1, nl + 1)]
                for m in range(1, 10)]
    f["k_c"] = [[13e6 + 10000 * m + 100 * i + j for i in range(1, nr + 1) for j in range(1, nl + 1)]
                for m in range(1, 10)]
    write_file(name, f, style)


# ---------------------------------------------------------------- physical bodies
COORDS = [(0.0, 0.0, 0.0), (2.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.5, 0.5, 1.5)]
MASSES = [1.0, 2.0, 1.5, 0.5]          # translational mass per node (kg)
ROT_INERTIA = [0.01, 0.02, 0.0, 0.0]   # rotary inertia per node; nodes 3, 4 have no rotation
IDS = [11, 12, 13, 14]


def rotation(axis, angle):
    x, y, z = axis
    s = math.sqrt(x * x + y * y + z * z)
    x, y, z = x / s, y / s, z / s
    c, d = math.cos(angle), math.sin(angle)
    C = 1 - c
    return [[c + x * x * C, x * y * C - z * d, x * z * C + y * d],
            [y * x * C + z * d, c + y * y * C, y * z * C - x * d],
            [z * x * C - y * d, z * y * C + x * d, c + z * z * C]]


def exact_m_r(loc, irot):
    """M_R (upper triangle, row by row) from the exact rigid mass properties: with the
    weights (X, Y, Z, 1-X-Y-Z) of the rigid modes, W = [[J, s - J 1], [., m - 2 sum(s) +
    1^T J 1]] (s, J the first and second moments about L0) and M_R = W (x) I3; with
    rotations, d I3 on modes 13..15 (d the nodes' rotary inertia per direction) and J
    from the inertia less d, as fxbody import forms it."""
    mtot = sum(MASSES)
    s = [sum(m * x[a] for m, x in zip(MASSES, loc)) for a in range(3)]
    second = [[sum(m * x[a] * x[b] for m, x in zip(MASSES, loc)) for b in range(3)]
              for a in range(3)]
    d = sum(ROT_INERTIA) if irot else 0.0
    # the inertia about L0, then J = tr(I - d)/2 1 - (I - d): the second moment again
    tr = sum(second[a][a] for a in range(3))
    inertia = [[(tr if a == b else 0.0) - second[a][b] + (d if a == b else 0.0)
                for b in range(3)] for a in range(3)]
    ip = [[inertia[a][b] - (d if a == b else 0.0) for b in range(3)] for a in range(3)]
    half = sum(ip[a][a] for a in range(3)) / 2.0
    j = [[(half if a == b else 0.0) - ip[a][b] for b in range(3)] for a in range(3)]
    w = [[0.0] * 4 for _ in range(4)]
    for a in range(3):
        for b in range(3):
            w[a][b] = j[a][b]
        w[a][3] = w[3][a] = s[a] - sum(j[a])
    w[3][3] = mtot - 2.0 * sum(s) + sum(sum(r) for r in j)
    nr = 15 if irot else 12
    full = [[0.0] * nr for _ in range(nr)]
    for a in range(4):
        for b in range(4):
            for c in range(3):
                full[3 * a + c][3 * b + c] = w[a][b]
    if irot:
        for c in range(3):
            full[12 + c][12 + c] = d
    return [full[i][q] for i in range(nr) for q in range(i, nr)]


def body(iblo, irot, idamp, ns, angle):
    n = len(IDS)
    mtot = sum(MASSES)
    cog = [sum(m * x[k] for m, x in zip(MASSES, COORDS)) / mtot for k in range(3)]
    P = rotation((1.0, 2.0, 3.0), angle)   # columns = local axes
    loc = []
    for x in COORDS:
        d = [x[k] - cog[k] for k in range(3)]
        loc.append([sum(P[r][j] * d[r] for r in range(3)) for j in range(3)])
    nr = 0 if iblo else (15 if irot else 12)
    rigid = []
    for i in range(nr):
        v = [0.0] * (6 * n)
        for p in range(n):
            if i < 12:
                j, c = divmod(i, 3)
                w = loc[p][j] if j < 3 else 1.0 - sum(loc[p])
                v[6 * p + c] = w
            elif ROT_INERTIA[p] > 0:
                v[6 * p + 3 + (i - 12)] = 1.0
        rigid.append(v)
    # Local modes: smooth made-up shapes (rotations only where the node has them).
    nl = 3
    local = []
    for j in range(nl):
        v = [0.0] * (6 * n)
        for p in range(n):
            for c in range(6):
                if c >= 3 and not (irot and ROT_INERTIA[p] > 0):
                    continue
                v[6 * p + c] = math.sin(1.0 + j + 0.7 * p + 0.3 * c) * (0.5 if c >= 3 else 1.0)
        local.append(v)
    diag_m = []
    for p in range(n):
        diag_m += [MASSES[p]] * 3 + [ROT_INERTIA[p]] * 3

    def mdot(a, b):
        return sum(x * y * m for x, y, m in zip(a, b, diag_m))

    m_l = [mdot(v, v) for v in local]
    # K_L = S^T diag(k) S scaled: rows/cols 1..ns coupled, rest diagonal. Chosen as
    # K = diag(m_l)^(1/2) A diag(m_l)^(1/2) with A having the known eigenvalues below.
    lam = [(2 * math.pi * 3.0) ** 2, (2 * math.pi * 7.0) ** 2, (2 * math.pi * 12.5) ** 2]
    if ns == 0:
        A = [[lam[0], 0, 0], [0, lam[1], 0], [0, 0, lam[2]]]
    else:  # ns = 2: rotate the first two eigenvalues by 30 degrees
        c, s = math.cos(math.pi / 6), math.sin(math.pi / 6)
        A = [[c * c * lam[0] + s * s * lam[1], c * s * (lam[1] - lam[0]), 0],
             [c * s * (lam[1] - lam[0]), s * s * lam[0] + c * c * lam[1], 0],
             [0, 0, lam[2]]]
    sq = [math.sqrt(m) for m in m_l]
    K = [[sq[r] * A[r][q] * sq[q] for q in range(nl)] for r in range(nl)]
    k_full = [K[r][q] for r in range(ns) for q in range(r, nl)]
    k_diag = [K[r][r] for r in range(ns, nl)]
    m_r = exact_m_r(loc, irot) if nr else []

    def t_apply(v, k, l):  # T_kl: component l -> component k, per translation/rotation triplet
        out = [0.0] * len(v)
        for p in range(n):
            for base in (0, 3):
                out[6 * p + base + k] = v[6 * p + base + l]
        return out

    m_c, k_c = [], []
    for m in range(9):
        k, l = divmod(m, 3)
        # The rotation on the rigid mode: M_C,kl(i,j) = (T_lk Phi_R,i)^T M Phi_L,j, so
        # that the engine's sum_kl P_kl M_C,kl is the turned body's coupling.
        m_c.append([mdot(t_apply(rigid[i], l, k), local[j]) for i in range(nr) for j in range(nl)])
        k_c.append([0.001 * (m + 1) * (i + 1) - 0.002 * j for i in range(nr) for j in range(nl)])
    freq = math.sqrt(lam[2]) / (2 * math.pi)
    return dict(nbmod=nl, nbstat=ns, irot=irot, idamp=idamp, iblo=iblo, ifile=(iblo ^ irot),
                ids=IDS, p0=[P[r][c] for r in range(3) for c in range(3)], freq=freq,
                damping=(0.8, 2.0e-4), rigid=rigid if nr else [], local=local, m_l=m_l,
                k_full=k_full, k_diag=k_diag, m_r=m_r, m_c=m_c, k_c=k_c)


def main():
    labelled("labels_r1_d1_ns2.fxb", 1, 1, 3, 2, [101, 102], "fixed")
    labelled("labels_r0_d0_ns1.fxb", 0, 0, 2, 1, [5, 6, 7], "free")
    k = 0
    for iblo in (0, 1):
        for irot in (0, 1):
            for idamp in (0, 1):
                ns = 2 if (iblo + irot + idamp) % 2 else 0
                style = "fixed" if k % 2 == 0 else "free"
                angle = 0.0 if k < 2 else 0.4 * k
                f = body(iblo, irot, idamp, ns, angle)
                write_file("body_b%d_r%d_d%d.fxb" % (iblo, irot, idamp), f, style)
                k += 1


if __name__ == "__main__":
    import sys

    if len(sys.argv) > 1:
        OUT = sys.argv[1]
    main()
