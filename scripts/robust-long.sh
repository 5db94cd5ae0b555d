#!/usr/bin/env bash
# Long robustness modes of issue 9 (docs/ROBUSTNESS.md), on demand:
#   1. the reader's mutation test with many cases (default 1,000,000);
#   2. the C master tests/c/robust_driver.c under valgrind memcheck: every misuse, then a
#      long run; any invalid access or any definite/indirect leak fails;
#   3. the fmpy master tests/python/test_robust_fmpy.py under valgrind: errors and
#      definite/indirect leaks whose stack passes through the FMU's library fail
#      (CPython and glibc's loader have their own, unrelated reports);
#   4. the misuse matrix and the thread tests, repeated.
#
# usage: scripts/robust-long.sh [--cases N] [--steps N] [--repeat N] [--quick]
#   --cases N   mutation cases (default 1000000)
#   --steps N   steps of the C and fmpy runs under valgrind (default 20000 and 2000)
#   --repeat N  repetitions of the misuse and thread tests (default 20)
#   --quick     a short pass: 20000 cases, 500 steps, 2 repeats (a few minutes)
set -euo pipefail
cd "$(dirname "$0")/.."

CASES=1000000 STEPS=20000 PYSTEPS=2000 REPEAT=20
while [ $# -gt 0 ]; do
    case "$1" in
        --cases) CASES="$2"; shift 2 ;;
        --steps) STEPS="$2"; PYSTEPS="$2"; shift 2 ;;
        --repeat) REPEAT="$2"; shift 2 ;;
        --quick) CASES=20000 STEPS=500 PYSTEPS=500 REPEAT=2; shift ;;
        *) echo "unknown argument $1" >&2; exit 2 ;;
    esac
done
command -v valgrind >/dev/null || { echo "valgrind is needed (apt-get install valgrind)" >&2; exit 2; }
if [ ! -x .venv/bin/python ]; then
    python3 -m venv .venv
    .venv/bin/pip install --quiet --disable-pip-version-check -r requirements-test.txt
fi

cargo build --release
work=$(mktemp -d /tmp/fxbody_robust_long.XXXXXX)
trap 'rm -rf "$work"' EXIT
fail=0

echo "== 1. reader mutation: $CASES cases"
start=$SECONDS
FXBODY_MUTATION_CASES=$CASES cargo test --release --test alloc mutation -- --nocapture 2>&1 \
    | grep -E "mutation cases|test result|panicked|over the heap" || fail=1
echo "   $((SECONDS - start)) s"

echo "== 2. C master under valgrind: $STEPS steps"
./target/release/fxbody pack fixtures/cantilever.fxb --coords fixtures/cantilever.nodes.rad \
    --nodes 121 -o "$work/tip.fmu" >/dev/null
.venv/bin/python -c "import zipfile, sys; zipfile.ZipFile(sys.argv[1]).extractall(sys.argv[2])" \
    "$work/tip.fmu" "$work/unz"
guid=$(grep -o 'guid="[^"]*"' "$work/unz/modelDescription.xml" | head -1 | cut -d'"' -f2)
vr() { grep "name=\"$1\"" "$work/unz/modelDescription.xml" | grep -o 'valueReference="[0-9]*"' | cut -d'"' -f2; }
so="$work/unz/binaries/linux64/cantilever.so"
uri="file://$work/unz/resources"
cc -g -O1 -Wall -Werror -std=c99 -D_POSIX_C_SOURCE=200809L -I include \
    tests/c/robust_driver.c -o "$work/driver" -ldl -lm
start=$SECONDS
if valgrind -q --error-exitcode=99 --leak-check=full --show-leak-kinds=definite,indirect \
    --errors-for-leak-kinds=definite,indirect --log-file="$work/c.vg" \
    "$work/driver" "$so" "$uri" "$guid" "$(vr node_121.fy)" "$(vr node_121.y)" "$STEPS"; then
    echo "   memcheck clean ($((SECONDS - start)) s)"
else
    echo "   FAILED (exit $?):"; cat "$work/c.vg"; fail=1
fi

echo "== 3. fmpy master under valgrind: $PYSTEPS steps"
start=$SECONDS
PYTHONMALLOC=malloc valgrind --leak-check=full --show-leak-kinds=definite,indirect \
    --num-callers=40 --log-file="$work/py.%p.vg" \
    .venv/bin/python tests/python/test_robust_fmpy.py "$work/tip.fmu" --steps "$PYSTEPS" \
    2>/dev/null | tail -1 || fail=1
# Keep the reports whose stack passes through the FMU's library.
if .venv/bin/python - "$work"/py.*.vg <<'EOF'
import re, sys
ours = re.compile(r"cantilever\.so|fxbody|fmi2[A-Z]|/src/(fmi|fmu|solver|fxb)/")
kinds = ("Invalid", "Conditional jump", "Use of uninitialised", "Syscall param",
         "Mismatched", "Source and destination", "Argument")
total = mine = 0
for path in sys.argv[1:]:
    for block in re.split(r"\n==\d+== \n", open(path).read()):
        lines = block.splitlines()
        if not lines:
            continue
        head = re.sub(r"^==\d+== ", "", lines[0]).strip()
        if head.startswith(kinds) or "definitely lost" in head or "indirectly lost" in head:
            total += 1
            if ours.search(block):
                mine += 1
                print(block)
print(f"   valgrind reports: {total} in total, {mine} through the FMU's library")
sys.exit(1 if mine else 0)
EOF
then echo "   no report attributable to the library ($((SECONDS - start)) s)"; else fail=1; fi

echo "== 4. misuse matrix and threads, $REPEAT times"
start=$SECONDS
for _ in $(seq "$REPEAT"); do
    cargo test --release --test all -q -- fmi::call_sequence fmi::bad_args fmi::states \
        fmi::threads fmi::c_valgrind 2>&1 \
        | grep -E "test result|panicked" | grep -v " 0 failed" && fail=1
done
echo "   $((SECONDS - start)) s"

if [ "$fail" = 0 ]; then echo "robust-long: all passed"; else echo "robust-long: FAILURES above"; exit 1; fi
