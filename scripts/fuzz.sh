#!/usr/bin/env bash
# Runs one libFuzzer target for a while on a copy of its seed corpus.
#
#   ./scripts/fuzz.sh NAME SECONDS      e.g. ./scripts/fuzz.sh obj_reader 60
#
# Builds ./build-fuzz with clang (core instrumented for coverage, ASan and UBSan; JOBS parallel jobs,
# default nproc), copies the seeds of tests/fuzz/corpus/<format> (<format>: NAME up to its first '_') to
# build-fuzz/corpus/NAME, fuzzes for SECONDS and prints one result line. Exits non-zero when the fuzzer
# finds a crash; the crashing input is left in build-fuzz/artifacts/NAME/ (add it to the seed corpus
# once fixed, as a regression test). tests/fuzz/<format>.dict, if present, is the fuzzer dictionary.
# FUZZ_BUILD names another build folder (default build-fuzz), e.g. to fuzz beside another engineer's build.
set -euo pipefail
cd "$(dirname "$0")/.."

if [ $# -ne 2 ] || ! [[ "$2" =~ ^[0-9]+$ ]]; then
    echo "usage: fuzz.sh NAME SECONDS (e.g. fuzz.sh obj_reader 60)" >&2
    exit 2
fi
name=$1
seconds=$2
format=${name%%_*}
seeds=tests/fuzz/corpus/$format
if [ ! -f "tests/fuzz/${name}_fuzz.cpp" ]; then
    echo "fuzz.sh: no target '$name' (expected tests/fuzz/${name}_fuzz.cpp)" >&2
    exit 2
fi
if ! command -v clang++ >/dev/null; then
    echo "fuzz.sh: clang++ not found (libFuzzer needs clang)" >&2
    exit 2
fi

build=${FUZZ_BUILD:-build-fuzz}
jobs=${JOBS:-$(nproc 2>/dev/null || echo 2)}  # JOBS=1 on a shared machine
mkdir -p "$build"
# Several fuzz.sh may run at once on one build folder (one per core): configure and build one at a time.
exec 9>"$build/.configure.lock"
flock 9
build_log=$build/build.log
CC=clang CXX=clang++ cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DDEFORMKIT_BUILD_FUZZ=ON -DDEFORMKIT_BUILD_PYTHON=OFF -DDEFORMKIT_BUILD_BENCH=OFF \
    -DDEFORMKIT_SANITIZE=address,undefined -DCMAKE_CXX_FLAGS=-fsanitize=fuzzer-no-link >"$build_log" 2>&1 ||
    { cat "$build_log" >&2; echo "fuzz.sh: configure failed" >&2; exit 2; }
cmake --build "$build" -j "$jobs" --target "fuzz_$name" >>"$build_log" 2>&1 ||
    { tail -n 40 "$build_log" >&2; echo "fuzz.sh: build failed (log: $build_log)" >&2; exit 2; }

flock -u 9

corpus=$build/corpus/$name
artifacts=$build/artifacts/$name
mkdir -p "$corpus" "$artifacts"
[ -d "$seeds" ] && cp -n "$seeds"/* "$corpus"/ 2>/dev/null || true
log=$build/fuzz-$name.log

dict=()
[ -f "tests/fuzz/$format.dict" ] && dict=(-dict="tests/fuzz/$format.dict")

set +e
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
    "$build/bin/fuzz_$name" "$corpus" -max_total_time="$seconds" -print_final_stats=1 \
    -artifact_prefix="$artifacts/" "${dict[@]}" >"$log" 2>&1
rc=$?
set -e

runs=$(grep -Eo 'stat::number_of_executed_units: *[0-9]+' "$log" | grep -Eo '[0-9]+$' || echo "?")
cov=$(grep -Eo 'cov: [0-9]+' "$log" | tail -n 1 | grep -Eo '[0-9]+' || echo "?")
inputs=$(find "$corpus" -type f | wc -l)
if [ $rc -eq 0 ]; then
    echo "fuzz $name: OK, ${seconds}s, $runs runs, coverage $cov, corpus $inputs inputs ($corpus)"
else
    crash=$(grep -Eo "Test unit written to [^ ]+" "$log" | tail -n 1 | sed 's/Test unit written to //')
    grep -E "ERROR:|runtime error|==[0-9]+==|deadly signal|Abort" "$log" | head -n 5 >&2 || true
    echo "fuzz $name: FAILED (exit $rc) after $runs runs; input: ${crash:-none}; log: $log"
    exit 1
fi
