#!/bin/sh
# cross_compile.sh <compiler> <core folder> <sources...>: compiles each source to an object with the
# library's flags (no -m options: the target's baseline), header-only dependencies (GLM) from the host's
# /usr/include after the compiler's own. Exits 77 (skipped) when the compiler is not installed.
cxx=$1
core=$2
shift 2
if ! command -v "$cxx" >/dev/null 2>&1; then
    echo "$cxx not found: skipped (scripts/setup.sh installs it)"
    exit 77
fi
out=$(mktemp -d) || exit 1
trap 'rm -rf "$out"' EXIT
status=0
for source in "$@"; do
    if "$cxx" -std=c++20 -O1 -fopenmp -ffp-contract=off -fno-math-errno -fno-trapping-math \
        -Wall -Wextra -Wpedantic -I"$core/include" -I"$core/src" -idirafter /usr/include \
        -c "$source" -o "$out/object.o"; then
        echo "ok: $source"
    else
        echo "FAILED: $source"
        status=1
    fi
done
exit $status
