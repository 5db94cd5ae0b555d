"""Realistic full FE models for `fxbody import` (tests/python/test_import_frames.py): 3D
frames of 20 to 500 consistent-mass elements, held at one end or free, whose lowest
eigenvalue reaches 4e-14 of the largest. Built with the fixture generator's elements
(fixtures/fe.py), independently of the tool.

The frame runs along three legs, x, then y, then z (lengths 1.23, 0.71 and 0.47 m, so
that no coordinate is a round number), its elements shared out 4:3:2, a solid 40 x 30 mm
steel section turned with each leg: its principal axes are not the global ones. Node IDs
from 1001 along the frame."""

import pathlib
import sys

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "fixtures"))
import fe  # noqa: E402

E, G, RHO = 210e9, 81e9, 7850.0
FIRST_ID = 1001
LEGS = [("x", 1.23), ("y", 0.71), ("z", 0.47)]
AXES = {
    "x": np.eye(3),
    "y": np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]),
    "z": np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]),
}


def frame(n_el, clamped):
    """(ids, xyz, K, M) of the frame with n_el elements (6 DOFs a node, global frame,
    node-major); `clamped`: the first node's DOFs removed (ids and xyz keep every node,
    so that coordinates can be written for all of them)."""
    sec = fe.rect_section(0.04, 0.03)
    share = [4, 3, 2]
    counts = [n_el * s // 9 for s in share]
    counts[0] += n_el - sum(counts)
    xyz = [np.zeros(3)]
    els = []
    for (ax, length), nel in zip(LEGS, counts):
        d = AXES[ax][0] * length / nel
        ke, me = fe.frame_element_oriented(length / nel, E, G, RHO, sec, AXES[ax])
        for _ in range(nel):
            a = len(xyz) - 1
            xyz.append(xyz[-1] + d)
            els.append((np.r_[6 * a : 6 * a + 12], ke, me))
    xyz = np.array(xyz)
    k, m = fe.assemble(6 * len(xyz), els)
    ids = list(range(FIRST_ID, FIRST_ID + len(xyz)))
    if clamped:
        keep = np.arange(6, k.shape[0])
        k, m = k[np.ix_(keep, keep)], m[np.ix_(keep, keep)]
    return ids, xyz, k, m


def dofs(ids, clamped):
    """(grid, comp) of the matrices' rows."""
    nodes = ids[1:] if clamped else ids
    return [(n, c) for n in nodes for c in range(1, 7)]


def rigid_motions(ids, xyz, nodes):
    """The six rigid motions about the centre of the coordinates (translations, small
    rotations), on the rows of `nodes` (6 DOFs each)."""
    c = xyz.mean(axis=0)
    r = np.zeros((6 * len(nodes), 6))
    for row, n in enumerate(nodes):
        x = xyz[ids.index(n)] - c
        for q in range(3):
            r[6 * row + q, q] = 1.0
            e = np.zeros(3)
            e[q] = 1.0
            r[6 * row : 6 * row + 3, 3 + q] = np.cross(e, x)
            r[6 * row + 3 + q, 3 + q] = 1.0
    return r
