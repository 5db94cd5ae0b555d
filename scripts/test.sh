#!/usr/bin/env bash
# The whole test suite: formatting and lints (the workspace's [lints]: unsafe only at the
# FMI boundary and in the host, every unsafe block with a SAFETY comment, every public
# item documented), Rust (unit, integration, doc tests of every package) and Python
# (fixture generator checks, the FMUs in fmpy, libcosim and ecos, the Dask sweep, the
# README's snippets, the import from pyNastran-written files). Creates ./.venv with
# requirements-test.txt and ./.venv-nastran with requirements-nastran.txt on first use.
set -euo pipefail
cd "$(dirname "$0")/.."

if [ ! -x .venv/bin/python ] || ! cmp -s requirements-test.txt .venv/.requirements; then
    # Resolved, so that a .venv symlink to a shared venv is updated in place.
    python3 -m venv "$(readlink -f .venv)"
    .venv/bin/pip install --quiet --disable-pip-version-check -r requirements-test.txt
    cp requirements-test.txt .venv/.requirements
fi
export FXBODY_PYTHON="$PWD/.venv/bin/python"
# pyNastran needs numpy < 2: a second venv, used only to write the pyNastran fixtures
# during the run (tests/python/test_import.py, test_fe_fixtures.py).
if [ ! -x .venv-nastran/bin/python ] || ! cmp -s requirements-nastran.txt .venv-nastran/.requirements; then
    python3 -m venv .venv-nastran
    .venv-nastran/bin/pip install --quiet --disable-pip-version-check -r requirements-nastran.txt
    cp requirements-nastran.txt .venv-nastran/.requirements
fi
export FXBODY_NASTRAN_PYTHON="$PWD/.venv-nastran/bin/python"

# CalculiX, the FE solver the whole-model tests check against (crates/sparse/tests/ccx.rs).
bash scripts/setup-fe.sh

cargo fmt --all --check
# --release shares the dependencies' build with the tests below.
cargo clippy --release --workspace --all-targets -- -D warnings
cargo build --release --workspace
cargo test --release --workspace
# ecos (ecospy) needs libtbb.so.12, which PyPI's tbb installs into the venv's lib/.
# One BLAS thread: the tests' small eigen-solves run 10x slower when OpenBLAS spreads
# them over cores that cargo and the FMUs are already using (measured 0.04 s vs 0.52 s).
LD_LIBRARY_PATH="$PWD/.venv/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" \
    OPENBLAS_NUM_THREADS=1 .venv/bin/python -m pytest -q tests/python fixtures
