"""Independent inputs for `fxbody import` (tests/python/test_import.py): a 3D frame
bracket built with the fixture generator's FE elements (fixtures/fe.py), reduced in
numpy by Guyan and by Craig-Bampton, free and clamped, and three writers of the
matrices: the real Nastran punch layout, pyNastran, and Abaqus MATRIX INPUT lines.
Nothing here uses the tool's code: it is the second implementation the tests compare
with."""

import pathlib
import sys

import numpy as np
import scipy.linalg as la

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "fixtures"))
import fe  # noqa: E402,F401  (also used by the tests as im.fe)
from modes import fix_sign  # noqa: E402

E, G, RHO = 210e9, 81e9, 7850.0
SPOINT0 = 900001


def bracket(refine=1):
    """A 3D frame bracket: members along x (1.0 m, 4 elements), then y (0.6 m, 3), then
    z (0.4 m, 2), solid 40 x 30 mm; `refine` divides every element into that many. Node
    IDs from 101 along the members (refine 1: 101..110, corners 105 and 108, ends 101 and
    110), coordinates (m), full K and M (6 DOFs a node, global frame, node-major), 60 DOFs
    at refine 1. Its principal axes are not the global ones."""
    sec = fe.rect_section(0.04, 0.03)
    axes = {
        "x": np.eye(3),
        "y": np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]),
        "z": np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]),
    }
    legs = [("x", 1.0, 4 * refine), ("y", 0.6, 3 * refine), ("z", 0.4, 2 * refine)]
    xyz = [np.zeros(3)]
    els = []
    for ax, length, nel in legs:
        d = axes[ax][0] * length / nel
        ke, me = fe.frame_element_oriented(length / nel, E, G, RHO, sec, axes[ax])
        for _ in range(nel):
            a = len(xyz) - 1
            xyz.append(xyz[-1] + d)
            els.append((np.r_[6 * a : 6 * a + 6, 6 * a + 6 : 6 * a + 12], ke, me))
    xyz = np.array(xyz)
    k, m = fe.assemble(6 * len(xyz), els)
    ids = list(range(101, 101 + len(xyz)))
    return ids, xyz, k, m


def dof_index(ids, nodes):
    """Full-model rows of all six DOFs of the nodes `nodes` (IDs)."""
    return np.array([6 * ids.index(n) + c for n in nodes for c in range(6)])


def guyan(k, m, b):
    """Guyan reduction to the rows b: (K_bb - K_bi K_ii^-1 K_ib, T^T M T, T)."""
    n = k.shape[0]
    i = np.setdiff1d(np.arange(n), b)
    t = np.zeros((n, len(b)))
    t[b, np.arange(len(b))] = 1.0
    t[i] = -la.solve(k[np.ix_(i, i)], k[np.ix_(i, b)])
    return t.T @ k @ t, t.T @ m @ t, t


def fixed_interface(k, m, b):
    """The interior rows i (all but b), the fixed-interface modes (omega^2 ascending, mass-
    normalised shapes over i, signed by the fixtures' rule: the first component within
    1e-6 of the largest is positive, so that another LAPACK kernel, which may return
    -psi, writes the same matrices) and the constraint modes T_c (identity on b,
    -K_ii^-1 K_ib on i: Guyan's T)."""
    n = k.shape[0]
    i = np.setdiff1d(np.arange(n), b)
    w2, psi = la.eigh(k[np.ix_(i, i)], m[np.ix_(i, i)])
    return i, w2, fix_sign(psi), guyan(k, m, b)[2]


def craig_bampton(k, m, b, nmodes, fixed=None):
    """Craig-Bampton: interface rows b plus nmodes fixed-interface modes (mass-normalised).
    Returns (K_cb, M_cb, T, cut-off Hz = frequency of the last kept fixed-interface mode).
    `fixed`: fixed_interface(k, m, b) if already computed."""
    i, w2, psi, tg = fixed if fixed is not None else fixed_interface(k, m, b)
    t = np.zeros((k.shape[0], len(b) + nmodes))
    t[:, : len(b)] = tg
    t[i, len(b):] = psi[:, :nmodes]
    kc, mc = t.T @ k @ t, t.T @ m @ t
    kc = 0.5 * (kc + kc.T)
    mc = 0.5 * (mc + mc.T)
    return kc, mc, t, float(np.sqrt(w2[nmodes - 1]) / (2 * np.pi))


def craig_bampton_upto(k, m, b, cutoff, fixed=None):
    """Craig-Bampton as a user runs it: every fixed-interface mode up to `cutoff` Hz.
    Returns (K_cb, M_cb, modes kept, dropped), dropped = (omega^2 of the fixed-interface
    modes left out, their inertial coupling to the interface DOFs psi_j^T (M_ii T_ci +
    M_ib), one row a mode): all that the reduction leaves out of the full model."""
    fixed = fixed if fixed is not None else fixed_interface(k, m, b)
    i, w2, psi, tg = fixed
    nm = int((np.sqrt(w2) / (2 * np.pi) <= cutoff).sum())
    kc, mc, _, _ = craig_bampton(k, m, b, nm, fixed)
    coupling = psi[:, nm:].T @ (m[np.ix_(i, i)] @ tg[i] + m[np.ix_(i, b)])
    return kc, mc, nm, (w2[nm:], coupling)


def truncation_estimate(lam, x_b, dropped):
    """Second-order estimate of the relative frequency error of Craig-Bampton modes
    (eigenvalues lam, interface part x_b of the M_cb-normalised vectors, one column a
    mode) from the dropped fixed-interface modes alone: the full model's equations give
    each dropped mode the amplitude q_j = lam c_j x_b / (w_j^2 - lam), which lowers lam by
    lam^2 sum_j (c_j x_b)^2 / (w_j^2 - lam); half of that relative to lam for the
    frequency."""
    w2, c = dropped
    cx = c @ x_b
    return 0.5 * np.sum(lam * cx**2 / (w2[:, None] - lam), axis=0)


def bar(nel):
    """A uniform bar in axial motion, one DOF a node from one end (node 0) to the other:
    length 1, EA 1, rho A 1, nel linear elements, consistent mass. Returns (K, M)."""
    k, m = np.zeros((nel + 1, nel + 1)), np.zeros((nel + 1, nel + 1))
    h = 1.0 / nel
    for a in range(nel):
        k[a : a + 2, a : a + 2] += np.array([[1.0, -1.0], [-1.0, 1.0]]) / h
        m[a : a + 2, a : a + 2] += np.array([[2.0, 1.0], [1.0, 2.0]]) * h / 6
    return k, m


def bar_craig_bampton_exact(kept, nroots):
    """The first nroots Craig-Bampton frequencies, in units of the first free-free one f1,
    of a uniform free bar coupled at one end, with its first `kept` fixed-interface modes,
    in closed form. The constraint mode is the rigid translation; the fixed-interface
    (clamped-free) modes are at (j - 1/2) f1, with effective masses eps_j = 2 / (pi^2
    (j - 1/2)^2) of the bar's (summing to 1). So lambda = (f / f1)^2 solves
    1 + sum_j eps_j lambda / (lambda_j - lambda) = 0, one root between consecutive poles
    (with every mode: exactly n f1). nroots < kept."""
    from scipy.optimize import brentq

    lj = (np.arange(1, kept + 1) - 0.5) ** 2
    eps = 2.0 / (np.pi**2 * lj)

    def secular(lam):
        return 1.0 + np.sum(eps * lam / (lj - lam))

    assert nroots < kept, "only the roots between two poles"
    roots = []
    for a, b in zip(lj[:nroots], lj[1 : nroots + 1]):
        d = 1e-12 * (b - a)
        roots.append(brentq(secular, a + d, b - d, xtol=1e-15, rtol=1e-15))
    return np.sqrt(roots)


def reduced_dofs(ids, nodes, nmodes=0):
    """(grid, comp) of a reduction to the nodes (all six DOFs) plus nmodes scalar points."""
    return [(n, c) for n in nodes for c in range(1, 7)] + [(SPOINT0 + j, 0) for j in range(nmodes)]


def rigid_props(xyz, k_unused, m):
    """Mass, centre of mass and inertia about it of a full 6-DOF-a-node model, and the
    rigid 6x6 R^T M R about the centre of mass."""
    n = len(xyz)
    r = np.zeros((6 * n, 6))
    for a in range(n):
        for c in range(3):
            r[6 * a + c, c] = 1.0
            r[6 * a + 3 + c, 3 + c] = 1.0
    mass = (r[:, :3].T @ m @ r[:, :3]).trace() / 3
    # centre of mass: first moments, translations against positions
    pos = np.zeros((6 * n, 3))
    for a in range(n):
        for c in range(3):
            pos[6 * a + c, c] = xyz[a, c]
    s = np.array([r[:, c] @ m @ pos[:, c] for c in range(3)])
    com = s / mass
    for a in range(n):
        x = xyz[a] - com
        for c in range(3):
            e = np.zeros(3)
            e[c] = 1.0
            r[6 * a : 6 * a + 3, 3 + c] = np.cross(e, x)
    rb = r.T @ m @ r
    return mass, com, rb[3:, 3:], rb


# An entry below this fraction of its row and column scale sqrt(a_ii a_jj) is round-off
# of an exact zero (Cauchy-Schwarz bounds a positive semi-definite matrix's entries by it).
ROUND_OFF = 1e-12


def zero_round_off(a):
    """`a` with the entries below ROUND_OFF sqrt(|a_ii a_jj|) set to exact zeros: the
    structure of a computed matrix, the same whatever BLAS kernel computed it."""
    d = np.sqrt(np.abs(np.diag(a)))
    out = np.array(a, dtype=float)
    out[np.abs(out) < ROUND_OFF * np.outer(d, d)] = 0.0
    return out + 0.0


def read_punch(path):
    """The entries of a punch written by write_punch: {name: {((gi, ci), (gj, cj)): value}}
    (columns by position: GI 9-24, CI 25-40, value 41-56)."""
    out, name, col = {}, None, None
    for line in pathlib.Path(path).read_text().splitlines():
        if line.startswith("DMIG*"):
            name, col = line[8:24].strip(), (int(line[24:40]), int(line[40:56]))
        elif line.startswith("DMIG"):
            out.setdefault(line[8:16].strip(), {})
        elif line.startswith("*"):
            out[name][((int(line[8:24]), int(line[24:40])), col)] = float(line[40:56])
    return out


def triangle(dofs, a):
    """Upper-triangle terms ((gi, ci), (gj, cj), value), i <= j, zeros left out."""
    out = []
    for j in range(len(dofs)):
        for i in range(j + 1):
            if a[i, j] != 0.0:
                out.append((dofs[i], dofs[j], float(a[i, j])))
    return out


def write_punch(path, mats, dofs):
    """The real punch layout: small-field header, large-field DMIG* column cards, one `*`
    line per entry with the value touching the component field (%16.9E)."""
    lines = []
    for name, a in mats.items():
        lines.append(f"{'DMIG':<8}{name:<8}{0:>8}{6:>8}{2:>8}{0:>8}{'':8}{len(dofs):>16}")
        for j, (gj, cj) in enumerate(dofs):
            rows = [(dofs[i], a[i, j]) for i in range(j + 1) if a[i, j] != 0.0]
            if not rows:
                continue
            lines.append(f"{'DMIG*':<8}{name:<16}{gj:>16}{cj:>16}")
            for (gi, ci), v in rows:
                lines.append(f"{'*':<8}{gi:>16}{ci:>16}{v:16.9E}")
    pathlib.Path(path).write_text("\n".join(lines) + "\n")


def write_pynastran(path, mats, dofs, ids, xyz):
    """The same matrices and the GRID cards written by pyNastran (large field, double)."""
    from pyNastran.bdf.bdf import BDF

    model = BDF(debug=False)
    for nid, x in zip(ids, xyz):
        model.add_grid(nid, list(map(float, x)))
    spoints = [g for g, c in dofs if c == 0]
    if spoints:
        model.add_spoint(spoints)
    for name, a in mats.items():
        terms = triangle(dofs, a)
        model.add_dmig(name, 6, 2, 0, 0, None,
                       [list(t[1]) for t in terms], [list(t[0]) for t in terms],
                       [t[2] for t in terms])
    model.write_bdf(str(path), size=16, is_double=True)


def write_abaqus(path, dofs, a):
    """Abaqus MATRIX INPUT lines `row node, row dof, col node, col dof, value` (%.17e),
    lower triangle as Abaqus writes it."""
    lines = [f"{gi},{ci}, {gj},{cj}, {v:.17e}" for (gj, cj), (gi, ci), v in triangle(dofs, a)]
    pathlib.Path(path).write_text("\n".join(lines) + "\n")


def write_csv(path, ids, xyz):
    rows = ["id,x,y,z"] + [f"{n},{float(x[0])!r},{float(x[1])!r},{float(x[2])!r}" for n, x in zip(ids, xyz)]
    pathlib.Path(path).write_text("\n".join(rows) + "\n")
