"""What the Python path costs over the work: the deformkit module's one-off functions and bound evaluates
against the C++ benchmarks of the same work, measured in the same run, on the benchmarks' 1,001,000-vertex
grids (tests/bench/barr_bench.cpp, ffd_bench.cpp; the grids, lattice and targets are rebuilt here).

    python3 scripts/bench_python.py [--build build] [--rounds 7] [--reps 9] [--blender blender.json]

The reference of a one-off (taper(), ffd(), ...) is the C++ bind + evaluate; of a bound evaluate
(Taper.evaluate, Ffd.evaluate; with out=, into a buffer the caller reuses) the C++ call the module makes:
AxialWarp::deform (the evaluate and its check that every input point is finite) for Taper, Ffd::evaluate
from the input into another array for Ffd. Requirements: a one-off at most 1.3x its reference, a bound
evaluate at most 1.1x. The two sides alternate in --rounds rounds (the C++ benchmark binaries once, then
each Python call, the median of --reps calls), so a slow spell of the machine weighs on both; the ratio is
the median over the rounds of each round's ratio. Both sides on every core (OMP_WAIT_POLICY=passive, as
scripts/bench.sh sets).
With --blender (scripts/bench_blender.py's output, same run) each one-off is also set against Blender's
modifier doing the same on the same grid (its share: evaluation with the modifier minus without, taken pair
by pair); requirement: the one-off at least 3x faster.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def grid(cells_x, cells_y, size_x, size_y):
    """geom::makeGrid's vertices: (i / cx * size_x, j / cy * size_y, 0), row-major, float32."""
    u = (np.arange(cells_x + 1, dtype=np.float32) / cells_x * size_x).astype(np.float32)
    v = (np.arange(cells_y + 1, dtype=np.float32) / cells_y * size_y).astype(np.float32)
    points = np.zeros((cells_y + 1, cells_x + 1, 3), np.float32)
    points[:, :, 0] = u[None, :]
    points[:, :, 1] = v[:, None]
    return points.reshape(-1, 3)


def cpp_times(build, binary, pattern):
    """Real time (ms) per benchmark name of one run of a benchmark binary, filtered."""
    with tempfile.NamedTemporaryFile(suffix=".json") as out:
        subprocess.run([os.path.join(build, "bin", binary), f"--benchmark_filter={pattern}",
                        f"--benchmark_out={out.name}", "--benchmark_out_format=json"],
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        data = json.load(open(out.name))
    times = {}
    for b in data["benchmarks"]:
        scale = {"ms": 1.0, "us": 1e-3, "ns": 1e-6}[b["time_unit"]]
        times[b["run_name"].split("/min_time")[0].replace("/real_time", "")] = b["real_time"] * scale
    return times


def median_ms(call, reps):
    call()  # warm: first-touch allocations and thread start-up are not what a script pays per call
    times = []
    for _ in range(reps):
        start = time.perf_counter()
        call()
        times.append((time.perf_counter() - start) * 1e3)
    return statistics.median(times)


def main(argv):
    parser = argparse.ArgumentParser()
    parser.add_argument("--build", default=os.path.join(ROOT, "build"))
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--reps", type=int, default=9)
    parser.add_argument("--blender", help="scripts/bench_blender.py's JSON, for the Blender column")
    args = parser.parse_args(argv)
    shares = json.load(open(args.blender))["modifier_share_ms"] if args.blender else {}
    sys.path.insert(0, os.path.join(args.build, "python"))
    import deformkit as dk  # noqa: E402  (the build's module)

    def cpp_round():
        times = cpp_times(args.build, "bench_barr", "BM_BarrBind|BM_BarrEvaluate/|BM_BarrDeform/|BM_BarrDeformSmall")
        times.update(cpp_times(args.build, "bench_ffd",
                               "BM_FfdBind|BM_FfdBSplineBind|BM_FfdEvaluateInto|BM_FfdBSplineEvaluate"))
        return times

    # tests/bench/barr_bench.cpp: the axis along the grid's long side through its middle, bend out of plane.
    points = grid(1000, 999, 4.0, 1.0)
    origin, axis, up = (np.array(v, np.float32) for v in ((0, 0.5, 0), (1, 0, 0), (0, 0, 1)))
    taper_z, taper_v = np.array([0, 1, 2.5, 4], np.float32), np.array([1, 0.6, 1.3, 0.4], np.float32)
    twist_z, twist_v = np.array([0, 2, 4], np.float32), np.array([0, 1, 3], np.float32)
    bound_taper = dk.Taper(points, origin, axis, taper_z, taper_v)
    taper_out = np.empty_like(points)  # a caller's buffer, reused from call to call
    rows = [
        ("taper()", lambda: dk.taper(points, origin, axis, taper_z, taper_v),
         ("BM_BarrBind/0", "BM_BarrEvaluate/0"), "bind + evaluate", 1.3, "taper"),
        ("twist()", lambda: dk.twist(points, origin, axis, twist_z, twist_v),
         ("BM_BarrBind/1", "BM_BarrEvaluate/1"), "bind + evaluate", 1.3, "twist"),
        ("bend()", lambda: dk.bend(points, origin, axis, up, 0.8, 2.0, 0.5, 3.5),
         ("BM_BarrBind/2", "BM_BarrEvaluate/2"), "bind + evaluate", 1.3, "bend"),
        ("Taper.evaluate", lambda: bound_taper.evaluate(points), ("BM_BarrDeform/0",), "deform", 1.1, None),
        ("Taper.evaluate(out=)", lambda: bound_taper.evaluate(points, out=taper_out), ("BM_BarrDeform/0",),
         "deform", 1.1, None),
    ]
    # tests/bench/ffd_bench.cpp: a 4x4x4 lattice around the unit grid, every control moved.
    fpoints = grid(1000, 999, 1.0, 1.0)
    lorigin = np.array([-0.05, -0.05, -0.5], np.float32)
    axes = np.array([[1.1, 0, 0], [0, 1.1, 0], [0, 0, 1.0]], np.float32)
    divisions = np.array([3, 3, 3], np.int32)
    bound_ffd = dk.Ffd(lorigin, axes, divisions)
    c = np.arange(64, dtype=np.float32)
    target = bound_ffd.source_points.reshape(-1, 3) + np.stack(
        [0.02 * np.sin(0.7 * c), 0.03 * np.cos(1.3 * c), 0.1 * np.sin(0.4 * c)], -1).astype(np.float32)
    target = target.reshape(4, 4, 4, 3).astype(np.float32)
    bound_ffd.bind(fpoints)
    ffd_out = np.empty_like(fpoints)
    bound_ffd.set_target(target)
    rows += [
        ("ffd()", lambda: dk.ffd(fpoints, lorigin, axes, divisions, target),
         ("BM_FfdBind", "BM_FfdEvaluateInto"), "bind + evaluate", 1.3, "lattice"),
        ("ffd(basis='bspline')", lambda: dk.ffd(fpoints, lorigin, axes, divisions, target, basis="bspline"),
         ("BM_FfdBSplineBind", "BM_FfdBSplineEvaluate"), "bind + evaluate", 1.3, "lattice"),
        ("Ffd.evaluate", lambda: bound_ffd.evaluate(fpoints), ("BM_FfdEvaluateInto",), "evaluate", 1.1, None),
        ("Ffd.evaluate(out=)", lambda: bound_ffd.evaluate(fpoints, out=ffd_out), ("BM_FfdEvaluateInto",),
         "evaluate", 1.1, None),
    ]
    python_ms = {name: [] for name, *_ in rows}
    cpp_ms = {name: [] for name, *_ in rows}
    ratios = {name: [] for name, *_ in rows}
    for _ in range(args.rounds):
        times = cpp_round()
        for name, call, parts, *_ in rows:
            ms, reference = median_ms(call, args.reps), sum(times[p] for p in parts)
            python_ms[name].append(ms)
            cpp_ms[name].append(reference)
            ratios[name].append(ms / reference)
    print(f"{args.rounds} rounds; medians over the rounds; ratio range: each round's Python / C++")
    print(f"{'Python call':24} {'Python':>9} {'C++':>9}  {'reference':16} {'ratio':>6}  {'range':12} "
          f"{'requirement':18}" + ("  Blender share  Blender / Python (>= 3)" if shares else ""))
    for name, call, parts, what, limit, modifier in rows:
        ms, reference = statistics.median(python_ms[name]), statistics.median(cpp_ms[name])
        ratio = statistics.median(ratios[name])
        spread = f"{min(ratios[name]):.2f}-{max(ratios[name]):.2f}"
        line = (f"{name:24} {ms:7.2f} ms {reference:6.2f} ms  {what:16} {ratio:5.2f}x  {spread:12} "
                f"{'<= ' + str(limit) + 'x ' + ('met' if ratio <= limit else 'NOT MET'):18}")
        if shares and modifier in shares:
            faster = shares[modifier] / ms
            line += f"  {shares[modifier]:9.1f} ms  {faster:5.1f}x {'met' if faster >= 3 else 'NOT MET'}"
        print(line)
    # The module's own cost per call, apart from the machine's noise between two 4 ms measurements: the bound
    # call on a 110-point grid, where the work is nothing, against the same C++ call (BM_BarrDeformSmall, the
    # last round's); both pay OpenMP's start of a parallel loop (about 50 us with OMP_WAIT_POLICY=passive).
    small = grid(10, 9, 4.0, 1.0)
    small_taper = dk.Taper(small, origin, axis, taper_z, taper_v)
    small_out = np.empty_like(small)
    calls = 20000
    start = time.perf_counter()
    for _ in range(calls):
        small_taper.evaluate(small, out=small_out)
    python_us, cpp_us = (time.perf_counter() - start) / calls * 1e6, times["BM_BarrDeformSmall"] * 1e3
    print(f"Taper.evaluate(out=) on 110 points: {python_us:.1f} us a call, the C++ deform {cpp_us:.1f} us: the "
          f"module adds {python_us - cpp_us:.1f} us a call")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
