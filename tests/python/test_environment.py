"""The environment the suite runs in (issue 29, point 2 and 8): every master, tool and
package a test needs is there, checked in one place, so that under FXBODY_REQUIRE_ALL=1
(scripts/test.sh sets it when CI=true) a broken environment fails here by name instead of
turning into skips; and the suite never runs with FXBODY_BLESS set (golden files would be
rewritten and pass: scripts/test.sh unsets it)."""

import importlib
import os
import shutil
import subprocess
import sys

import pytest

from conftest import REQUIRE_ALL, missing

# The masters and packages the Python tests import (tests/python/masters.py,
# test_dask_sweep.py), by the module the tests load.
MODULES = ["fmpy", "libcosimpy.CosimExecution", "ecospy", "dask.distributed", "scipy", "numpy"]
# The programs the tests run (memcheck under fmpy and the C masters, the C builds).
TOOLS = ["valgrind", "cc"]


def test_the_suite_never_runs_blessed():
    assert "FXBODY_BLESS" not in os.environ, (
        "FXBODY_BLESS is set: the golden-file tests would rewrite their files and pass; "
        "scripts/test.sh unsets it")


@pytest.mark.parametrize("module", MODULES)
def test_every_python_package_imports(module):
    try:
        importlib.import_module(module)
    except (ImportError, OSError) as e:
        missing(module, f"cannot be imported: {type(e).__name__}: {e}")


@pytest.mark.parametrize("tool", TOOLS)
def test_every_tool_runs(tool):
    path = shutil.which(tool)
    if path is None:
        missing(tool, "not on PATH (apt-get install " + {"cc": "gcc"}.get(tool, tool) + ")")
    run = subprocess.run([path, "--version"], capture_output=True, text=True)
    assert run.returncode == 0, f"{path} --version: {run.stderr}"


def test_pynastran_venv_is_there():
    exe = os.environ.get("FXBODY_NASTRAN_PYTHON")
    if not exe:
        missing("pyNastran", "FXBODY_NASTRAN_PYTHON is not set (scripts/test.sh makes .venv-nastran)")
    run = subprocess.run([exe, "-c", "import pyNastran"], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr


def test_require_all_fails_instead_of_skipping(tmp_path):
    """The mechanism itself: a test that calls `missing`, and one that skips by itself,
    are skipped without the flag and fail with it (run in a child pytest, this conftest
    in force as a plugin)."""
    test = tmp_path / "test_probe.py"
    test.write_text("import pytest\nfrom conftest import missing\n\n"
                    "def test_missing():\n    missing('a tool', 'absent on purpose')\n\n"
                    "def test_plain_skip():\n    pytest.skip('skipped on purpose')\n")
    here = os.path.dirname(os.path.abspath(__file__))
    for flag, want in [("0", "2 skipped"), ("1", "2 failed")]:
        env = dict(os.environ, FXBODY_REQUIRE_ALL=flag, PYTHONPATH=here)
        run = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "conftest", str(test)],
                             capture_output=True, text=True, env=env, cwd=here)
        assert want in run.stdout, (flag, run.stdout + run.stderr)
    assert REQUIRE_ALL == (os.environ.get("FXBODY_REQUIRE_ALL") == "1")
