#!/usr/bin/env bash
# Runs every benchmark (build/bin/bench_*) and prints one table: median throughput of each benchmark
# and its ratio against the reference measured in the same run (see scripts/bench_table.py).
#
#   ./scripts/bench.sh                 all benchmarks, 5 repetitions each
#   ./scripts/bench.sh --quick         1 repetition (a smoke run)
#   DEFORMKIT_BUILD_DIR=build-perf ./scripts/bench.sh    benchmarks of another build folder
#
# With chromium, tests/bench/shot_report_load.py times the shot report of a 240-frame x 10-tile shot against an
# empty page. Then scripts/bench_python.py prints what the Python module costs over the C++ benchmarks of the same work.
# When `blender` is on PATH, scripts/bench_blender.py also times Blender's Lattice and SimpleDeform modifiers
# on the same 1,001,000-vertex grid, and the table gets their shares and our / Blender ratios
# (target: ours at least 3x faster than Blender's modifier).
# With Blender and the staged add-on ($build/blender), tests/bench/blender_slide_frame_change.py also times
# frame changes of a 99,602-vertex mesh with and without the add-on's slide (about 500 active vertices) and
# prints their ratio after the table.
set -euo pipefail
cd "$(dirname "$0")/.."

reps=5
blender_reps=15
if [ "${1:-}" = "--quick" ]; then
    reps=1
    blender_reps=3
fi
build=${DEFORMKIT_BUILD_DIR:-build}

# The benchmarks are not part of the default build: configure (setup.sh) if needed, then build them.
if [ ! -f "$build/CMakeCache.txt" ]; then
    ./scripts/setup.sh >/dev/null
fi
cmake --build "$build" -j "$(nproc 2>/dev/null || echo 2)" --target deformkit_benchmarks >/dev/null
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for exe in "$build"/bin/bench_*; do
    name=$(basename "$exe")
    echo "running $name ..." >&2
    if ! "$exe" --benchmark_repetitions="$reps" --benchmark_report_aggregates_only=true \
        --benchmark_out="$out/$name.json" --benchmark_out_format=json >"$out/$name.log" 2>&1; then
        cat "$out/$name.log" >&2
        exit 1
    fi
done
blender_json=()
if command -v blender >/dev/null 2>&1; then
    echo "running Blender's modifiers (scripts/bench_blender.py) ..." >&2
    if ! blender -b --factory-startup --python-exit-code 1 --python scripts/bench_blender.py -- \
        --reps "$blender_reps" --out "$out/blender.json" >"$out/blender.log" 2>&1; then
        cat "$out/blender.log" >&2
        exit 1
    fi
    blender_json=(--blender "$out/blender.json")
fi
python3 scripts/bench_table.py "${blender_json[@]}" "$out"/bench_*.json
if [ ${#blender_json[@]} -eq 0 ]; then
    echo "Blender comparison skipped: blender is not on PATH"
fi
if command -v blender >/dev/null 2>&1 && [ -f "$build/blender/deformkit/__init__.py" ]; then
    echo "running the slide's frame change in Blender (tests/bench/blender_slide_frame_change.py) ..." >&2
    if ! blender -b --factory-startup --python-exit-code 1 \
        --python tests/bench/blender_slide_frame_change.py -- "$build/blender" --reps "$reps" \
        --table "$out/blender_slide.txt" >"$out/blender_slide.log" 2>&1; then
        cat "$out/blender_slide.log" >&2
        exit 1
    fi
    echo
    cat "$out/blender_slide.txt"
else
    echo "Blender slide frame change skipped: blender or the staged add-on ($build/blender) is missing"
fi
if [ -d "$build/python" ] && { command -v chromium >/dev/null 2>&1 || command -v chromium-browser >/dev/null 2>&1; }; then
    echo "running the shot report's load time (tests/bench/shot_report_load.py) ..." >&2
    echo
    PYTHONPATH="$build/python" /usr/bin/python3 tests/bench/shot_report_load.py --reps "$reps"
else
    echo "Shot report load time skipped: chromium or the Python module ($build/python) is missing"
fi
if [ -d "$build/python" ]; then
    echo "running the Python module against the C++ benchmarks (scripts/bench_python.py) ..." >&2
    echo
    /usr/bin/python3 scripts/bench_python.py --build "$build" --reps $((reps < 5 ? 5 : reps)) \
        ${blender_json[@]+"${blender_json[@]}"}
else
    echo "Python comparison skipped: no Python module in $build/python"
fi
