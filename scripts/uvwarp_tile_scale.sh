#!/usr/bin/env bash
# A fully covered UV tile from 1024^2 to 16384^2 (tests/bench/uvwarp_tile_bench.cpp), each size in a process
# of its own so that its peak memory is its own, and one Markdown table: bind, cold solve, redirect map and
# figures in seconds, bind / solve, peak bytes per cell, and the delivered map's rigid stretch removed.
#
#   ./scripts/uvwarp_tile_scale.sh                  1024 2048 4096 8192 16384
#   ./scripts/uvwarp_tile_scale.sh 1024 2048        the sizes given
#   DEFORMKIT_BUILD_DIR=build-perf ./scripts/uvwarp_tile_scale.sh
#
# 16384^2 needs about 11 GB of memory and several minutes on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${DEFORMKIT_BUILD_DIR:-build}
exe="$build/bin/bench_uvwarp_tile"
if [ ! -f "$build/CMakeCache.txt" ]; then
    echo "uvwarp_tile_scale.sh: $build is not configured: run scripts/setup.sh first" >&2
    exit 2
fi
cmake --build "$build" --target bench_uvwarp_tile >/dev/null  # not part of the default build
sizes=("$@")
[ ${#sizes[@]} -gt 0 ] || sizes=(1024 2048 4096 8192 16384)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for t in "${sizes[@]}"; do
    echo "running ${t}^2 ..." >&2
    DEFORMKIT_TILE_SIZES="$t" "$exe" --benchmark_out="$out/$t.json" \
        --benchmark_out_format=json >"$out/$t.log" 2>&1 || {
        cat "$out/$t.log" >&2
        exit 1
    }
done
python3 - "$out" "${sizes[@]}" <<'EOF'
import json
import sys

folder, sizes = sys.argv[1], sys.argv[2:]
print("| tile | bind s | cold solve s | map s | figures s | bind / solve | peak bytes a cell | removed | inverted, off-chart |")
print("|---|---|---|---|---|---|---|---|---|")
for t in sizes:
    with open(f"{folder}/{t}.json") as f:
        b = json.load(f)["benchmarks"][0]
    print(f"| {t}² | {b['bind_s']:.2f} | {b['solve_s']:.2f} | {b['redirect_s']:.2f} | {b['measure_s']:.2f} "
          f"| {b['bind_ratio']:.2f} | {b.get('peak_bytes_per_cell', float('nan')):.1f} "
          f"| {b['reduction_pct']:.1f}% | {int(b['inverted'])}, {int(b['off_chart'])} |")
EOF
