"""The committed FE-reader fixtures (tests/data/fe) are what their writer produces: running
make_fixtures.py into an empty folder gives every committed file byte for byte, so the
Rust tests read files whose intended matrices the writer states (expected_*.csv)."""

import pathlib
import subprocess
import sys

from conftest import nastran_python

FE = pathlib.Path(__file__).resolve().parents[1] / "data" / "fe"


def test_fixtures_are_reproduced_by_their_writer(tmp_path):
    run = subprocess.run([sys.executable, str(FE / "make_fixtures.py"), str(tmp_path)],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    written = sorted(p.name for p in tmp_path.iterdir())
    assert len(written) >= 30
    for name in written:
        assert (FE / name).read_bytes() == (tmp_path / name).read_bytes(), name
    # Every committed fixture but pyNastran's own file comes from this writer.
    committed = {p.name for p in FE.iterdir() if p.is_file()}
    assert committed - set(written) == {"make_fixtures.py", "make_pynastran.py",
                                         "pyn_written.bdf"}


def test_pynastran_fixture_is_what_pynastran_writes(tmp_path):
    """pyn_written.bdf, read by the Rust DMIG tests, written again by pyNastran itself in
    its own venv (make_pynastran.py): the committed copy is byte for byte its output."""
    run = subprocess.run([nastran_python(), str(FE / "make_pynastran.py"), str(tmp_path)],
                         capture_output=True, text=True, cwd=FE)
    assert run.returncode == 0, run.stderr
    assert "reads back its own KAAX to" in run.stdout, run.stdout
    got = (tmp_path / "pyn_written.bdf").read_bytes()
    assert got == (FE / "pyn_written.bdf").read_bytes()
