#!/usr/bin/env bash
# Usage: storage_faults.sh DEFORMKIT FAULT_LIBRARY SCRATCH_DIR
# Storage that fails after the bytes were written (an fsync that reports a quota or an I/O error, a rename
# that fails with EIO) is exit 1, names the output and leaves the file that was there and no temporary; a
# rename refused for another reason is the destination's fault (exit 2). Faults come from FAULT_LIBRARY
# (storage_faults.cpp) preloaded into the CLI.
set -u
dk=$1
faults=$2
work=$3
rm -rf "$work" && mkdir -p "$work/out"
failures=0
passed=0

fail() { echo "FAIL $1"; [ -f "$work/err" ] && cat "$work/err"; failures=$((failures + 1)); }
slide() {  # slide [ENV...]: slides the grid into $work/out/slid.obj with the given environment
    env LD_PRELOAD="$faults" "$@" "$dk" slide "$work/grid.obj" --handle 12 --from 0,0,0 --to 0.1,0,0 \
        --radius 0.3 --out "$work/out/slid.obj" >"$work/stdout" 2>"$work/err"
}
check() {  # check NAME EXPECTED_RC TEXT: exit code, one line on stderr holding TEXT, the old file, no temporary
    local name=$1 want=$2 text=$3 rc=$4
    [ "$rc" -eq "$want" ] || { fail "$name: exit $rc, expected $want"; return; }
    [ "$(wc -l <"$work/err")" -eq 1 ] || { fail "$name: expected one line on stderr"; return; }
    grep -qF -- "$text" "$work/err" || { fail "$name: '$text' not on stderr"; return; }
    cmp -s "$work/out/slid.obj" "$work/kept.obj" || { fail "$name: the existing output changed"; return; }
    [ -z "$(ls -A "$work/out" | grep -v '^slid\.obj$')" ] || { fail "$name: left $(ls -A "$work/out")"; return; }
    passed=$((passed + 1))
}

# A 5 x 5 grid of quads on z = 0.
awk 'BEGIN { for (j = 0; j < 6; j++) for (i = 0; i < 6; i++) printf "v %g %g 0\n", i / 5, j / 5
             for (j = 0; j < 5; j++) for (i = 0; i < 5; i++) { a = j * 6 + i + 1
                 printf "f %d %d %d %d\n", a, a + 1, a + 7, a + 6 } }' >"$work/grid.obj"

# The library passes every call through when no fault is asked for.
slide
rc=$?
if [ "$rc" -eq 0 ] && [ -s "$work/out/slid.obj" ]; then passed=$((passed + 1)); else fail "no-fault: exit $rc"; fi
# The output a failed write must leave as it was.
echo "the last good output" >"$work/kept.obj"
cp "$work/kept.obj" "$work/out/slid.obj"

out="$work/out/slid.obj"
slide DEFORMKIT_FAULT=fsync
check fsync-eio 1 "$out: the storage did not keep the written file: Input/output error" $?
slide DEFORMKIT_FAULT=fsync DEFORMKIT_FAULT_ERRNO=122
check fsync-quota 1 "$out: the storage did not keep the written file: Disk quota exceeded" $?
slide DEFORMKIT_FAULT=rename
check rename-eio 1 "$out: cannot replace the file: Input/output error" $?
slide DEFORMKIT_FAULT=rename DEFORMKIT_FAULT_ERRNO=13
check rename-denied 2 "$out: cannot replace the file: Permission denied" $?

# EINVAL from fsync: a file system that cannot sync (nothing was lost); the file is written.
slide DEFORMKIT_FAULT=fsync DEFORMKIT_FAULT_ERRNO=22
rc=$?
if [ "$rc" -eq 0 ] && ! cmp -s "$out" "$work/kept.obj"; then passed=$((passed + 1)); else fail "fsync-einval: exit $rc"; fi

echo "storage_faults: $passed passed, $failures failed"
[ "$failures" -eq 0 ]
