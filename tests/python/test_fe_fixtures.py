"""The committed FE-reader fixtures (tests/data/fe) are what their writer produces: running
make_fixtures.py into an empty folder gives every committed file byte for byte, so the
Rust tests read files whose intended matrices the writer states (expected_*.csv)."""

import pathlib
import subprocess
import sys

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
