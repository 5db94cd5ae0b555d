#!/usr/bin/env python3
"""Writes the bodies that `fxbody import` built with its previous dense solver (nalgebra's
symmetric eigen-solver, Cholesky and products; commit 564facc), kept as the reference
that the faer solver must equal to round-off (tests/python/test_import.py,
test_same_bodies_as_the_previous_solver):

    .venv/bin/python tests/data/import/make_prev_solver.py OLD_FXBODY_BINARY

Four cases: the README's free Craig-Bampton bracket (fixtures/import/bracket.pch) with all
modes and with --fmax 300 (static modes), and the bracket clamped at node 101, reduced by
Craig-Bampton to nodes 105, 108, 110 and 12 modes, with all modes and with --fmax 300."""

import pathlib
import subprocess
import sys

HERE = pathlib.Path(__file__).resolve().parent
REPO = HERE.parents[2]
sys.path.insert(0, str(REPO / "tests" / "python"))
import import_models as im  # noqa: E402
import numpy as np  # noqa: E402

IFACE = [105, 108, 110]


def inputs(out):
    """The input files of the four cases, written into `out`; returns name -> args."""
    out = pathlib.Path(out)
    ids, xyz, k, m = im.bracket()
    keep = np.arange(6, k.shape[0])
    ids, k, m = ids[1:], k[np.ix_(keep, keep)], m[np.ix_(keep, keep)]
    kc, mc, _, _ = im.craig_bampton(k, m, im.dof_index(ids, IFACE), 12)
    im.write_punch(out / "clamped_cb.pch", {"KAAX": kc, "MAAX": mc},
                   im.reduced_dofs(ids, IFACE, 12))
    ex = REPO / "fixtures" / "import"
    free = [ex / "bracket.pch", "--coords", ex / "bracket_grids.bdf"]
    clamped = [out / "clamped_cb.pch", "--blocked"]
    return {
        "free": free,
        "free_fmax": free + ["--fmax", "300"],
        "blocked": clamped,
        "blocked_fmax": clamped + ["--fmax", "300"],
    }


def write(exe, case_args, out, name):
    subprocess.run([str(exe), "import", *map(str, case_args), "-o", str(out / f"{name}.fxb")],
                   check=True, capture_output=True)


if __name__ == "__main__":
    for name, args in inputs(HERE).items():
        write(sys.argv[1], args, HERE, name)
    (HERE / "clamped_cb.pch").unlink()
    for p in HERE.glob("*.nodes.csv"):
        p.unlink()
