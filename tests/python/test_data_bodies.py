"""The hand-made bodies of tests/data are what their writers produce.

make_data.py is standard-library Python (no BLAS, no numpy): its output is the same bytes
on every machine, so the committed files are compared byte for byte. The naive-construction
free-free beam (tests/data/freefree_naive.fxb) and the truss reduced on a 3-2-1 support
(tests/data/truss_supported.fxb and .nodes.rad) come from the fixture generator and go
through LAPACK: fixtures/test_generate.py compares them value by value with a tolerance."""

import pathlib
import subprocess
import sys

DATA = pathlib.Path(__file__).resolve().parents[1] / "data"


def test_make_data_writes_the_committed_bodies(tmp_path):
    run = subprocess.run([sys.executable, str(DATA / "make_data.py"), str(tmp_path)],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    written = sorted(p.name for p in tmp_path.iterdir())
    assert len(written) == 10, written  # 2 labelled files, 8 flag combinations
    for name in written:
        assert (DATA / name).read_bytes() == (tmp_path / name).read_bytes(), name
