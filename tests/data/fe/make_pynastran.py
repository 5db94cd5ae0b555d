#!/usr/bin/env python3
"""Writes pyn_written.bdf with pyNastran itself (a second, independent DMIG writer).

pyNastran 1.4.1 pins numpy 1.x, so it lives in a venv of its own, not in the test venv:

    .venv-nastran/bin/python tests/data/fe/make_pynastran.py [OUT_DIR]

(scripts/test.sh makes .venv-nastran from requirements-nastran.txt). The file is
committed, so the Rust test (crates/import/tests/all/readers.rs) needs no Python; the Python test
tests/python/test_fe_fixtures.py writes it again with pyNastran during the run and
checks that the committed copy is byte for byte what pyNastran writes. It holds
GRID (large field), SPOINT and the KAAX and MAAX matrices of make_fixtures.py (the same
values as expected_punch_kaax.csv and expected_punch_maax.csv), one upper triangle each,
written large-field double precision as pyNastran does (size=16, is_double=True).
"""
import os
import sys

from pyNastran.bdf.bdf import BDF

import make_fixtures as fx

HERE = os.path.dirname(os.path.abspath(__file__))


def main(out_dir=HERE):
    model = BDF(debug=False)
    for nid, xyz in sorted(fx.NODES.items()):
        model.add_grid(nid, list(xyz))
    model.add_spoint([d[0] for d in fx.DOFS if d[1] == 0])
    for name, a in (("KAAX", fx.matrix(17, 2.0e8)), ("MAAX", fx.matrix(18, 1.0))):
        gcj, gci, real = [], [], []
        for (i, j), v in sorted(a.items()):
            gcj.append(fx.DOFS[j])
            gci.append(fx.DOFS[i])
            real.append(v)
        model.add_dmig(name, 6, 2, 0, 0, None, gcj, gci, real)
    path = os.path.join(out_dir, "pyn_written.bdf")
    model.write_bdf(path, size=16, is_double=True)

    # Cross-check with pyNastran's own reader: its matrix equals the one meant.
    check = BDF(debug=False)
    check.read_bdf(path, punch=True, xref=False)
    dense, rows, cols = check.dmig["KAAX"].get_matrix(is_sparse=False, apply_symmetry=True)
    k = fx.matrix(17, 2.0e8)
    # rows, cols: index -> (grid, comp), in order of first appearance.
    row_of = {key: n for n, key in rows.items()}
    col_of = {key: n for n, key in cols.items()}
    worst = 0.0
    for (i, j), v in k.items():
        r = row_of[fx.DOFS[i]]
        c = col_of[fx.DOFS[j]]
        worst = max(worst, abs(dense[r, c] - v) / abs(v))
    print(f"pyNastran reads back its own KAAX to {worst:.1e} relative")


if __name__ == "__main__":
    main(*sys.argv[1:2])
