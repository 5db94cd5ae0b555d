"""The install story: `scripts/install.sh --no-build PREFIX` puts `fxbody` and the FMU
library where the installed command finds it, so that `pack` works from any folder with
a clean environment (no --lib, no FXBODY_LIB, not run from the repository), and the FMU
it writes runs in fmpy and follows the full-FE reference."""

import os
import shutil
import subprocess

import numpy as np
from fmpy import simulate_fmu

from conftest import FIXTURES, REPO, reference


def test_installed_fxbody_packs_without_flags_from_anywhere(tmp_path):
    prefix = tmp_path / "prefix"
    r = subprocess.run(["bash", str(REPO / "scripts" / "install.sh"), "--no-build", str(prefix)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    exe = prefix / "bin" / "fxbody"
    assert exe.is_file() and (prefix / "lib" / "fxbody" / "libfxbody.so").is_file()
    assert (prefix / "include" / "fxbody" / "fxbody.h").is_file()
    work = tmp_path / "elsewhere"
    work.mkdir()
    shutil.copy(FIXTURES / "cantilever.fxb", work)
    shutil.copy(FIXTURES / "cantilever.nodes.rad", work)
    clean = {"PATH": f"{prefix / 'bin'}:/usr/bin:/bin", "HOME": str(tmp_path)}
    r = subprocess.run(["fxbody", "pack", "cantilever.fxb", "--coords", "cantilever.nodes.rad",
                        "--nodes", "121", "-o", "cantilever.fmu"], cwd=work, env=clean,
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    help_text = subprocess.run(["fxbody", "pack", "--help"], cwd=work, env=clean,
                               capture_output=True, text=True).stdout
    assert "PREFIX/lib/fxbody/libfxbody.so" in help_text and "FXBODY_LIB" in help_text, help_text

    # Moved elsewhere, the library goes with the prefix: the copy packs too.
    moved = tmp_path / "moved"
    shutil.copytree(prefix, moved)
    shutil.rmtree(prefix)
    r = subprocess.run([str(moved / "bin" / "fxbody"), "pack", "cantilever.fxb", "--coords",
                        "cantilever.nodes.rad", "--nodes", "121", "--name", "moved", "-o", "moved.fmu"],
                       cwd=work, env=clean, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    # Without its library, the message names every place looked at.
    os.remove(moved / "lib" / "fxbody" / "libfxbody.so")
    r = subprocess.run([str(moved / "bin" / "fxbody"), "pack", "cantilever.fxb", "--coords",
                        "cantilever.nodes.rad", "-o", "none.fmu"], cwd=work, env=clean,
                       capture_output=True, text=True)
    assert r.returncode == 2 and str(moved / "lib" / "fxbody" / "libfxbody.so") in r.stderr, r.stderr

    # The installed pack's FMU: a 1 N tip step for 0.4 s, exact method, against the
    # full-FE response's peak (0.5%, the exact method's floor in test_fmu.py).
    res = simulate_fmu(str(work / "cantilever.fmu"), stop_time=0.4, output_interval=2e-4,
                       start_values={"node_121.fy": 1.0}, output=["node_121.y"])
    y = res["node_121.y"] - res["node_121.y"][0]
    resp = next(x for x in reference("cantilever")["responses"] if x["name"] == "step")
    t, uy = np.array(resp["t"]), np.array(resp["nodes"]["121"]["uy"])
    want = np.abs(uy[t <= 0.4 + 1e-12]).max()
    assert abs(np.abs(y).max() - want) <= 5e-3 * want, (np.abs(y).max(), want)
