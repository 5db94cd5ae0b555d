#!/usr/bin/env bash
# Install the `fxbody` command and the FMU library it packs into every .fmu:
#
#     bash scripts/install.sh [--no-build] [PREFIX]        (default PREFIX: ~/.local)
#
# writes PREFIX/bin/fxbody, PREFIX/lib/fxbody/libfxbody.so (where an installed fxbody
# looks for it, relative to itself: `fxbody pack` needs no --lib or FXBODY_LIB) and
# PREFIX/include/fxbody/fxbody.h (the C header of the FMI functions). Put PREFIX/bin on
# PATH. `cargo install` alone cannot do this: it installs binaries, never a library.
# --no-build installs what the last `cargo build --release` built (the tests use it).
set -euo pipefail
cd "$(dirname "$0")/.."
build=1
if [ "${1:-}" = --no-build ]; then
    build=0
    shift
fi
prefix="${1:-$HOME/.local}"
if [ "$build" = 1 ]; then
    cargo build --release -p fxbody -p fxbody-cli
fi
install -D -m 755 target/release/fxbody "$prefix/bin/fxbody"
install -D -m 755 target/release/libfxbody.so "$prefix/lib/fxbody/libfxbody.so"
install -D -m 644 include/fxbody.h "$prefix/include/fxbody/fxbody.h"
echo "installed $prefix/bin/fxbody, $prefix/lib/fxbody/libfxbody.so, $prefix/include/fxbody/fxbody.h"
case ":$PATH:" in
    *":$prefix/bin:"*) ;;
    *) echo "add $prefix/bin to PATH (e.g. export PATH=\"$prefix/bin:\$PATH\")" ;;
esac
