#!/usr/bin/env bash
# Runs every DeformKit test. On a fresh machine it first installs and builds (scripts/setup.sh).
#
#   ./scripts/test.sh              build the Release tree (./build) with the sanitized unit tests (the core
#                                  and Ptex libraries under ASan + UBSan, the same test objects), then run
#                                  every test; the summary line comes last
#   ./scripts/test.sh --sanitize   only the sanitized unit tests
#   ./scripts/test.sh --quick      everything but the sanitized unit tests
#   extra arguments after -- go to ctest (e.g. -- -L unit)
#
# The last line has ctest's form and counts test cases: every Catch2 case and pytest case, and every other
# CTest entry (CLI scripts, the Blender and Slurm tests) as one; the sanitized unit tests' own line comes
# before it. The wall time of each phase is printed before them.
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
    phases+=("$(printf '%-38s %4d s' "$1" $((SECONDS - phase_start)))")
    phase_start=$SECONDS
}

./scripts/setup.sh --deps
phase_done "dependencies"

# ctest runs two tests at a time on a 2-core machine. OpenMP threads that spin at barriers would then
# steal each other's cores (the UV-warp solver's many short parallel loops slow down ~15x); passive
# waiting yields the core instead. Results are the same bytes either way.
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}

# One build of everything the tests need, so both cores stay busy from the first source to the last.
case "$mode" in
    all)
        ./scripts/setup.sh --with-sanitized-tests
        phase_done "build (Release and sanitized tests)" ;;
    quick)
        ./scripts/setup.sh
        phase_done "build (Release)"
        ctest_args=(-LE sanitized "${ctest_args[@]}") ;;
    sanitize)
        ./scripts/setup.sh --sanitized-tests-only
        phase_done "build (sanitized tests)"
        ctest_args=(-L sanitized "${ctest_args[@]}") ;;
esac

status=0
set +e
ctest --test-dir build --output-on-failure -j "$jobs" "${ctest_args[@]}"
status=$?
set -e
phase_done "tests"

echo
echo "wall time per phase:"
printf '  %s\n' "${phases[@]}"
python3 scripts/test_summary.py build/Testing/Temporary/LastTest.log
exit $status
