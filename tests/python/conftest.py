"""Shared fixtures for the FMU tests: pack the shipped bodies with target/release/fxbody
(scripts/test.sh builds it first) into a temporary folder, and read their references."""

import json
import os
import pathlib
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]
# Set by scripts/test.sh when CI=true: every master, tool and package the suite uses must
# be there, and a test that would be skipped for want of one fails instead (a broken
# LD_LIBRARY_PATH for ecos's libtbb, a missing valgrind, a venv without Dask).
REQUIRE_ALL = os.environ.get("FXBODY_REQUIRE_ALL") == "1"


def missing(what, why):
    """A dependency `what` is not usable (`why`): the calling test fails under
    FXBODY_REQUIRE_ALL=1 (CI), and is skipped with the reason otherwise (a run by hand
    on a machine without it)."""
    if REQUIRE_ALL:
        pytest.fail(f"{what} is required (FXBODY_REQUIRE_ALL=1, set by scripts/test.sh in CI) "
                    f"but not usable: {why}", pytrace=False)
    pytest.skip(f"{what}: {why}")


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    """Under FXBODY_REQUIRE_ALL=1 no test may pass by being skipped, whatever skipped it
    (a `skipif` on a missing tool included): the skip is reported as a failure."""
    outcome = yield
    report = outcome.get_result()
    if REQUIRE_ALL and report.skipped and not hasattr(report, "wasxfail"):
        report.outcome = "failed"
        reason = report.longrepr[2] if isinstance(report.longrepr, tuple) else report.longrepr
        report.longrepr = f"skipped under FXBODY_REQUIRE_ALL=1 (CI), which allows no skip: {reason}"
FIXTURES = REPO / "fixtures"
EXE = REPO / "target" / "release" / "fxbody"
BODIES = ["cantilever", "cantilever_damped", "freefree", "truss"]


def nastran_python():
    """The Python of the pyNastran venv (pyNastran pins numpy < 2, so it is not in the test
    venv): FXBODY_NASTRAN_PYTHON, which scripts/test.sh sets after making .venv-nastran
    from requirements-nastran.txt. Unset (pytest run by hand): the test is skipped, saying
    so (it fails under FXBODY_REQUIRE_ALL=1, see `missing`); set but unusable: the test
    fails."""
    exe = os.environ.get("FXBODY_NASTRAN_PYTHON")
    if not exe:
        missing("pyNastran", "it is not in the test venv (it needs numpy < 2): run scripts/test.sh, "
                "which makes .venv-nastran and sets FXBODY_NASTRAN_PYTHON")
    run = subprocess.run([exe, "-c", "import pyNastran; print(pyNastran.__version__)"],
                         capture_output=True, text=True)
    assert run.returncode == 0, f"FXBODY_NASTRAN_PYTHON={exe} has no pyNastran: {run.stderr}"
    return exe


def pack_fmu(out_dir, body, *extra, name=None):
    """Pack fixtures/<body>.fxb with its /NODE deck into a folder of its own,
    out_dir/<name>/<name>.fmu (the model name stays the body's: fxbody refuses a second
    FMU of one model name in a folder, whose OSP description it would overwrite);
    returns the .fmu path."""
    if not EXE.is_file():
        pytest.fail(f"{EXE} is missing: run `cargo build --release` first (scripts/test.sh does)")
    folder = pathlib.Path(out_dir) / (name or body)
    folder.mkdir(parents=True, exist_ok=True)
    out = folder / f"{name or body}.fmu"
    cmd = [str(EXE), "pack", str(FIXTURES / f"{body}.fxb"), "--coords",
           str(FIXTURES / f"{body}.nodes.rad"), "-o", str(out), *extra]
    run = subprocess.run(cmd, capture_output=True, text=True)
    assert run.returncode == 0, f"{' '.join(cmd)} failed: {run.stderr}"
    return out


def reference(body):
    """The fixture's full-FE reference (fixtures/<body>.ref.json)."""
    return json.loads((FIXTURES / f"{body}.ref.json").read_text())


@pytest.fixture(scope="session")
def fmu_dir(tmp_path_factory):
    return tmp_path_factory.mktemp("fmus")


@pytest.fixture(scope="session")
def packed(fmu_dir):
    """Every shipped body packed with default options (all nodes exposed)."""
    return {b: pack_fmu(fmu_dir, b) for b in BODIES if (FIXTURES / f"{b}.fxb").is_file()}


@pytest.fixture(scope="session")
def cantilever_tip(fmu_dir):
    """The cantilever with only its tip node exposed, and the reference."""
    ref = reference("cantilever")
    tip = ref["tip_node"]
    return pack_fmu(fmu_dir, "cantilever", "--nodes", str(tip), name="cantilever_tip"), ref
