#!/usr/bin/env bash
# The whole test suite: Rust (unit, integration, doc tests) and Python (fixture
# generator checks, fmpy tests). Creates ./.venv with requirements-test.txt on first use.
set -euo pipefail
cd "$(dirname "$0")/.."

if [ ! -x .venv/bin/python ] || ! cmp -s requirements-test.txt .venv/.requirements; then
    python3 -m venv .venv
    .venv/bin/pip install --quiet --disable-pip-version-check -r requirements-test.txt
    cp requirements-test.txt .venv/.requirements
fi
export FXBODY_PYTHON="$PWD/.venv/bin/python"

cargo build --release
cargo test --release
.venv/bin/python -m pytest -q tests/python fixtures
