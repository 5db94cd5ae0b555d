#!/usr/bin/env python3
"""Writes cb_pyn.bdf with pyNastran itself: the bracket of tests/python/import_models.py
clamped at node 101 and reduced by Craig-Bampton to nodes 105, 108, 110 and 12
fixed-interface modes (scalar points 900001-900012), as GRID, SPOINT and DMIG cards
(large field, double). pyNastran 1.4.1 pins numpy 1.x, so it runs in a venv of its own:

    python3 -m venv /tmp/pyn && /tmp/pyn/bin/pip install pyNastran==1.4.1
    /tmp/pyn/bin/python tests/data/import/make_pynastran.py

tests/python/test_import.py imports the file and checks it against the same reduction
computed there."""

import pathlib
import sys

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1] / "python"))
import import_models as im  # noqa: E402
import numpy as np  # noqa: E402

ids, xyz, k, m = im.bracket()
keep = np.arange(6, k.shape[0])
ids, xyz, k, m = ids[1:], xyz[1:], k[np.ix_(keep, keep)], m[np.ix_(keep, keep)]
nodes = [105, 108, 110]
kc, mc, _, _ = im.craig_bampton(k, m, im.dof_index(ids, nodes), 12)
im.write_pynastran(HERE / "cb_pyn.bdf", {"KAAX": kc, "MAAX": mc},
                   im.reduced_dofs(ids, nodes, 12), ids, xyz)
