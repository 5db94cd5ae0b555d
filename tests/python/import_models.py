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

E, G, RHO = 210e9, 81e9, 7850.0
SPOINT0 = 900001


def bracket():
    """A 3D frame bracket: members along x (1.0 m, 4 elements), then y (0.6 m, 3), then
    z (0.4 m, 2), solid 40 x 30 mm. Node IDs 101..110, coordinates (m), full K and M
    (6 DOFs a node, global frame, node-major), 60 DOFs. Its principal axes are not the
    global ones."""
    sec = fe.rect_section(0.04, 0.03)
    axes = {
        "x": np.eye(3),
        "y": np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]),
        "z": np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]),
    }
    legs = [("x", 1.0, 4), ("y", 0.6, 3), ("z", 0.4, 2)]
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


def craig_bampton(k, m, b, nmodes):
    """Craig-Bampton: interface rows b plus nmodes fixed-interface modes (mass-normalised).
    Returns (K_cb, M_cb, T, cut-off Hz = frequency of the last kept fixed-interface mode)."""
    n = k.shape[0]
    i = np.setdiff1d(np.arange(n), b)
    w2, psi = la.eigh(k[np.ix_(i, i)], m[np.ix_(i, i)])
    psi = psi[:, :nmodes]
    _, _, tg = guyan(k, m, b)
    t = np.zeros((n, len(b) + nmodes))
    t[:, : len(b)] = tg
    t[i, len(b):] = psi
    kc, mc = t.T @ k @ t, t.T @ m @ t
    kc = 0.5 * (kc + kc.T)
    mc = 0.5 * (mc + mc.T)
    return kc, mc, t, float(np.sqrt(w2[nmodes - 1]) / (2 * np.pi))


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
