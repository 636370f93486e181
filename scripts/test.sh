#!/usr/bin/env bash
# Runs every DeformKit test. On a fresh machine it first installs and builds (scripts/setup.sh).
#
#   ./scripts/test.sh              sanitized unit tests (ASan + UBSan, ./build-asan), then the whole
#                                  suite on the Release build (./build); ctest's summary line comes last
#   ./scripts/test.sh --sanitize   only the sanitized unit tests
#   ./scripts/test.sh --quick      only the Release suite
#   extra arguments after -- go to ctest (e.g. -- -L unit)
set -euo pipefail
cd "$(dirname "$0")/.."

mode=all
ctest_args=()
while (($#)); do
    case "$1" in
        --sanitize) mode=sanitize ;;
        --quick) mode=quick ;;
        --) shift; ctest_args=("$@"); break ;;
        *) echo "test.sh: unknown argument '$1' (expected --sanitize, --quick or -- CTEST_ARGS)" >&2; exit 2 ;;
    esac
    shift
done

jobs=$(nproc 2>/dev/null || echo 2)
summary=""

run_ctest() {  # run_ctest BUILD_DIR ARGS... ; remembers ctest's summary line
    local dir=$1; shift
    local log
    log=$(mktemp)
    set +e
    ctest --test-dir "$dir" --output-on-failure -j "$jobs" "$@" 2>&1 | tee "$log"
    local rc=${PIPESTATUS[0]}
    set -e
    summary=$(grep -E "tests passed|tests failed" "$log" | tail -n 1)
    rm -f "$log"
    return "$rc"
}

./scripts/setup.sh --deps

# ctest runs two tests at a time on a 2-core machine. OpenMP threads that spin at barriers would then
# steal each other's cores (the UV-warp solver's many short parallel loops slow down ~15x); passive
# waiting yields the core instead. Results are the same bytes either way.
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}

status=0
if [ "$mode" != quick ]; then
    cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDEFORMKIT_SANITIZE=address,undefined \
        -DDEFORMKIT_BUILD_PYTHON=OFF -DDEFORMKIT_BUILD_BENCH=OFF >/dev/null
    cmake --build build-asan -j "$jobs"
    ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 run_ctest build-asan -L unit || status=1
    sanitize_summary="sanitized unit tests: $summary"
fi
if [ "$mode" != sanitize ]; then
    ./scripts/setup.sh
    run_ctest build "${ctest_args[@]}" || status=1
    [ -n "${sanitize_summary:-}" ] && echo "$sanitize_summary"
fi
echo "$summary"
exit $status
