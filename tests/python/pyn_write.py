#!/usr/bin/env python3
"""Writes a reduced model with pyNastran itself (GRID, SPOINT, DMIG large field, double),
run by the pyNastran venv's Python (it pins numpy < 2; tests/python/conftest.py,
nastran_python):

    python pyn_write.py MATRICES.npz OUT.bdf

MATRICES.npz holds KAAX, MAAX, dofs ((grid, comp) rows), ids and xyz (the GRID points),
written by the test from its numpy reduction (import_models.py)."""

import pathlib
import sys

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import import_models as im  # noqa: E402


def main(src, out):
    z = np.load(src)
    dofs = [(int(g), int(c)) for g, c in z["dofs"]]
    im.write_pynastran(out, {"KAAX": z["KAAX"], "MAAX": z["MAAX"]}, dofs,
                       [int(i) for i in z["ids"]], z["xyz"])


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
