"""tests/data/free_hand_step.json (loaded by the Rust test free::explicit::hand_*) is what
tests/reference/free_hand_step.py writes: rerun the hand computation and compare every
number of the committed file, as fixtures/test_generate.py does for the fixtures:
|a - b| <= REL |b| + FLOOR max|array|.

The fixtures need 1e-6 because their FE eigenproblem amplifies round-off by about 1e8.
Nothing here amplifies it that much (three springs, eigenvalue gaps of 30 % and more,
two steps): the table first committed, computed with another numpy and BLAS, differs
from this machine's run by at most 1.2e-14 of an array's largest value. 1e-9 leaves five
orders of magnitude for other machines; editing the script or the file by hand moves
the numbers by far more (a changed load or step: 1e-3 and up).
"""

import json
import pathlib
import sys

import numpy as np

REPO = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tests" / "reference"))

import free_hand_step  # noqa: E402

REL = 1e-9
FLOOR = 1e-9


def test_committed_file_is_what_the_script_writes():
    committed = json.loads((REPO / "tests" / "data" / "free_hand_step.json").read_text())
    fresh = json.loads(json.dumps(free_hand_step.compute()))
    assert set(committed) - {"source"} == set(fresh)
    for body, case in fresh.items():
        assert set(committed[body]) == set(case), f"{body}: keys differ"
        for key, want in case.items():
            got = np.asarray(committed[body][key], float)
            want = np.asarray(want, float)
            assert got.shape == want.shape, f"{body}.{key}: shape {got.shape} != {want.shape}"
            scale = np.abs(want).max()
            bad = np.abs(got - want) > REL * np.abs(want) + FLOOR * scale
            assert not bad.any(), (
                f"{body}.{key}: {bad.sum()} values differ, first at {np.argwhere(bad)[0]}: "
                f"{got[bad][0]!r} vs {want[bad][0]!r}; rerun tests/reference/free_hand_step.py"
            )


def test_written_file_reads_back_exactly(tmp_path):
    # The writer's format (one key per line) loses nothing: Python's float repr round-trips.
    data = free_hand_step.compute()
    out = tmp_path / "hand.json"
    free_hand_step.write(data, str(out))
    back = json.loads(out.read_text())
    assert back["source"].startswith("written by tests/reference/free_hand_step.py")
    for body, case in data.items():
        for key, value in case.items():
            assert back[body][key] == value, f"{body}.{key}"
