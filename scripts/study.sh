#!/usr/bin/env bash
# Speed against accuracy (issue 8), from scratch: the Python peers (numpy exact state
# space; Exudyn when importable), the Model Exchange FMU through fmpy's CVode over a range
# of tolerances (study/me.py, issue 26.3), then `fxbody-study` (every method over a range of
# communication steps, mode-count sweep, stability map, dense-product bound), which also draws
# docs/study.svg and writes docs/study_results.md. Usage: scripts/study.sh [--quick]
# (--quick: about half a minute, written to out/study_quick/ so docs/ keeps the full run).
set -euo pipefail
cd "$(dirname "$0")/.."
QUICK="${1:-}"
OUT=docs
if [ "$QUICK" = "--quick" ]; then OUT=out/study_quick; fi
PY="${PYTHON:-.venv/bin/python}"
if [ ! -x "$PY" ]; then
    python3 -m venv .venv
    .venv/bin/pip install -q -r requirements-test.txt
fi
mkdir -p "$OUT" out/study
# Build first (binary and FMU library) so that no compilation runs during the timings.
cargo build --release -q
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
echo "== peers (numpy, exudyn) =="
"$PY" study/peers.py fixtures "$OUT/peers.csv" $QUICK
echo "== full-FE chirp reference =="
F1=$("$PY" -c "import json; d = json.load(open('fixtures/cantilever.ref.json')); print(repr(5 * d['frequencies_hz']['euler_bernoulli_planes']['xy'][0]))")
"$PY" study/chirp_ref.py fixtures "$OUT/chirp_ref.csv" "$F1" 1.0 5e-5
echo "== Model Exchange + CVode (fmpy) =="
"$PY" study/me.py fixtures ./target/release/fxbody "$OUT/me.csv" $QUICK
echo "== fxbody-study =="
./target/release/fxbody-study --fixtures fixtures --out "$OUT" $QUICK
echo "== co-simulation coupling stability (fmpy) =="
./target/release/fxbody pack fixtures/cantilever.fxb --coords fixtures/cantilever.nodes.rad \
    --nodes "$("$PY" -c "import json; print(json.load(open('fixtures/cantilever.ref.json'))['tip_node'])")" \
    -o out/study/cantilever_tip.fmu
"$PY" study/cosim.py out/study/cantilever_tip.fmu fixtures "$OUT/cosim.csv" $QUICK
