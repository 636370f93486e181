#!/usr/bin/env bash
# Runs every benchmark (build/bin/bench_*) and prints one table: median throughput of each benchmark
# and its ratio against the reference measured in the same run (see scripts/bench_table.py).
#
#   ./scripts/bench.sh                 all benchmarks, 5 repetitions each
#   ./scripts/bench.sh --quick         1 repetition (a smoke run)
set -euo pipefail
cd "$(dirname "$0")/.."

reps=5
if [ "${1:-}" = "--quick" ]; then reps=1; fi

if ! ls build/bin/bench_* >/dev/null 2>&1; then
    ./scripts/setup.sh >/dev/null
fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for exe in build/bin/bench_*; do
    name=$(basename "$exe")
    echo "running $name ..." >&2
    if ! "$exe" --benchmark_repetitions="$reps" --benchmark_report_aggregates_only=true \
        --benchmark_out="$out/$name.json" --benchmark_out_format=json >"$out/$name.log" 2>&1; then
        cat "$out/$name.log" >&2
        exit 1
    fi
done
python3 scripts/bench_table.py "$out"/*.json
