#!/usr/bin/env bash
# Runs every DeformKit test. On a fresh machine it first installs and builds (scripts/setup.sh).
#
#   ./scripts/test.sh              sanitized unit tests (ASan + UBSan, ./build-asan), then the whole
#                                  suite on the Release build (./build); the summary line comes last
#   ./scripts/test.sh --sanitize   only the sanitized unit tests
#   ./scripts/test.sh --quick      only the Release suite
#   extra arguments after -- go to ctest (e.g. -- -L unit)
#
# The last line has ctest's form and counts test cases: every Catch2 case and pytest case, and every other
# CTest entry (CLI scripts, the Blender and Slurm tests) as one. The wall time of each phase is printed
# before it.
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
phases=()
phase_start=$SECONDS
phase_done() {  # phase_done NAME: records the wall time since the previous phase ended
    phases+=("$(printf '%-34s %4d s' "$1" $((SECONDS - phase_start)))")
    phase_start=$SECONDS
}

# ctest's verdicts with test cases counted: a CTest entry that ran Catch2 or pytest counts its cases (from
# ctest's full log), any other entry counts as one case.
case_summary() {  # case_summary BUILD_DIR
    python3 scripts/test_summary.py "$1/Testing/Temporary/LastTest.log"
}

status=0
run_ctest() {  # run_ctest BUILD_DIR ARGS...; sets `summary`
    local dir=$1; shift
    set +e
    ctest --test-dir "$dir" --output-on-failure -j "$jobs" "$@"
    local rc=$?
    set -e
    summary=$(case_summary "$dir")
    [ "$rc" -eq 0 ] || status=1
}

./scripts/setup.sh --deps
phase_done "dependencies"

# ctest runs two tests at a time on a 2-core machine. OpenMP threads that spin at barriers would then
# steal each other's cores (the UV-warp solver's many short parallel loops slow down ~15x); passive
# waiting yields the core instead. Results are the same bytes either way.
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}

generator=()
if [ ! -f build-asan/CMakeCache.txt ] && command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi

if [ "$mode" != quick ]; then
    # The library and its unit tests only (no CLI, Python module, Maya layer or benchmarks), at -O1 with
    # line tables: what the sanitizers check, compiled in about half the time of an optimised build.
    cmake -S . -B build-asan "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
        -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" -DDEFORMKIT_SANITIZE=address,undefined \
        -DDEFORMKIT_BUILD_HARNESS=OFF -DDEFORMKIT_BUILD_PYTHON=OFF -DDEFORMKIT_BUILD_MAYA=OFF \
        -DDEFORMKIT_BUILD_BENCH=OFF >/dev/null
    cmake --build build-asan -j "$jobs" --target deformkit_unit_tests
    phase_done "sanitized build"
    ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 run_ctest build-asan -L unit
    sanitize_summary="sanitized unit tests: $summary"
    phase_done "sanitized unit tests"
fi
if [ "$mode" != sanitize ]; then
    ./scripts/setup.sh
    phase_done "release build (scripts/setup.sh)"
    run_ctest build "${ctest_args[@]}"
    phase_done "release suite"
fi

echo
echo "wall time per phase:"
printf '  %s\n' "${phases[@]}"
[ -n "${sanitize_summary:-}" ] && [ "$mode" != sanitize ] && echo "$sanitize_summary"
echo "$summary"
exit $status
