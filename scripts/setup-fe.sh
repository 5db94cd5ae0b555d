#!/usr/bin/env bash
# CalculiX (ccx), the FE solver the whole-model tests and bench check against
# (crates/import/tests/all/ccx.rs, crates/import/benches/sparse.rs): Debian's calculix-ccx.
# Idempotent: does nothing when ccx is already on the PATH. Needs root (or sudo) for
# apt-get on a fresh machine.
set -euo pipefail
if command -v ccx >/dev/null 2>&1; then
    exit 0
fi
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
    SUDO="sudo"
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq calculix-ccx >/dev/null
command -v ccx >/dev/null
