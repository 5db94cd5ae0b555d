#!/usr/bin/env bash
# The whole test suite: formatting and lints (the workspace's [lints]: unsafe only at the
# FMI boundary and in the host, every unsafe block with a SAFETY comment, every public
# item documented), Rust (unit, integration, doc tests of every package) and Python
# (fixture generator checks, the FMUs in fmpy, libcosim and ecos, the Dask sweep, the
# README's snippets, the import from pyNastran-written files). Creates ./.venv with
# requirements-test.txt and ./.venv-nastran with requirements-nastran.txt on first use.
# With CI=true nothing may be skipped for want of a dependency (see below).
set -euo pipefail
cd "$(dirname "$0")/.."

# FXBODY_BLESS makes the golden-file tests rewrite their files and pass: never in a run
# of the suite (bless by hand, then review the diff).
unset FXBODY_BLESS

# In CI (CI=true) every master, tool and package the suite uses must be there: the tests
# fail, instead of skipping a part, when one is missing (FXBODY_REQUIRE_ALL=1, read by
# tests/python/conftest.py and tests/common/mod.rs), and the system tools the suite runs
# are installed here when apt-get can do it, else the run stops naming them.
if [ "${CI:-}" = true ]; then
    export FXBODY_REQUIRE_ALL=1
    missing=()
    for tool in valgrind cc mkfifo; do
        command -v "$tool" >/dev/null || missing+=("$tool")
    done
    if [ ${#missing[@]} -gt 0 ]; then
        packages=()
        for tool in "${missing[@]}"; do
            case "$tool" in
                cc) packages+=(gcc) ;;
                mkfifo) packages+=(coreutils) ;;
                *) packages+=("$tool") ;;
            esac
        done
        if [ "$(id -u)" = 0 ]; then
            apt-get install -y --no-install-recommends "${packages[@]}"
        elif sudo -n true 2>/dev/null; then
            sudo apt-get install -y --no-install-recommends "${packages[@]}"
        else
            echo "scripts/test.sh: CI needs ${missing[*]} (apt-get install ${packages[*]}), and cannot install it here" >&2
            exit 1
        fi
    fi
fi

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

# CalculiX, the FE solver the whole-model tests check against (crates/import/tests/all/ccx.rs).
bash scripts/setup-fe.sh

cargo fmt --all --check
# --release shares the dependencies' build with the tests below.
cargo clippy --release --workspace --all-targets -- -D warnings
# The API documentation of every package builds, every intra-doc link resolved.
RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps
cargo build --release --workspace
cargo test --release --workspace
# ecos (ecospy) needs libtbb.so.12, which PyPI's tbb installs into the venv's lib/.
# One BLAS thread: the tests' small eigen-solves run 10x slower when OpenBLAS spreads
# them over cores that cargo and the FMUs are already using (measured 0.04 s vs 0.52 s).
LD_LIBRARY_PATH="$PWD/.venv/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" \
    OPENBLAS_NUM_THREADS=1 .venv/bin/python -m pytest -q tests/python fixtures

# The tests that regenerate committed files (fixtures, the README's example punch, bodies
# imported against committed ones, the golden model descriptions, the import's
# thread-pool independence) again under other floating-point kernels (issue 28): none of
# them compares bytes that went through BLAS/LAPACK or faer, each compares values with a
# stated tolerance. The run above used OpenBLAS's default kernel for this CPU at one
# thread and faer (the import) at two; OpenBLAS's Prescott kernel (SSE3, no AVX), two
# BLAS threads and faer at one thread each change the rounding (other bits in the eigen-
# vectors of a 400 x 400 matrix, checked when this was written). About 30 s in all.
REGENERATION=(fixtures/test_generate.py tests/python/test_free_hand_step.py
    tests/python/test_import.py::test_example_files_are_what_the_script_writes
    tests/python/test_import.py::test_same_bodies_as_the_previous_solver)
for variant in "OPENBLAS_CORETYPE=Prescott OPENBLAS_NUM_THREADS=1 FXBODY_IMPORT_THREADS=1" \
    "OPENBLAS_NUM_THREADS=2 FXBODY_IMPORT_THREADS=1" \
    "OPENBLAS_CORETYPE=Prescott OPENBLAS_NUM_THREADS=2 FXBODY_IMPORT_THREADS=2"; do
    echo "regeneration tests with $variant"
    # shellcheck disable=SC2086 # the variant is a list of assignments for env
    env $variant .venv/bin/python -m pytest -q -p no:cacheprovider "${REGENERATION[@]}"
    # shellcheck disable=SC2086
    env $variant cargo test --release -q -p fxbody-import --lib dense
    # shellcheck disable=SC2086
    env $variant cargo test --release -q -p fxbody --test all fmi::model_description
done
