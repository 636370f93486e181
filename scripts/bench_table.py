#!/usr/bin/env python3
"""Prints one table from Google Benchmark JSON files: median throughput per benchmark and the ratio
against the reference benchmark measured in the same run. Usage: bench_table.py FILE.json..."""
import json
import sys

# benchmark -> (reference benchmark, what the ratio means)
REFERENCES = {
    "BM_ObjRead": ("BM_PlainRead", "OBJ read / plain read of the same bytes"),
    "BM_ObjParse": ("BM_PlainRead", "OBJ parse from memory / plain read"),
    "BM_BvhClosestPoint": ("BM_BruteForceClosestPoint", "BVH / brute-force closest point"),
    "BM_BvhRayCast": ("BM_BruteForceRayCast", "BVH / brute-force ray cast"),
    "BM_BarrEvaluateEngine": ("BM_BarrEvaluate", "generic engine / fast path"),
    "BM_WiresEngineEvaluate": ("BM_WiresEvaluate", "generic engine / fast path"),
}


def split_name(name):
    """'BM_X/2/real_time' -> ('BM_X', '/2')."""
    parts = name.split("/")
    args = [a for a in parts[1:] if not a.startswith(("real_time", "min_time", "repeats", "iterations"))]
    return parts[0], "".join("/" + a for a in args)


def reference_for(name, medians):
    """The in-run reference of a benchmark: an explicit pair, or its 1-thread twin."""
    base, args = split_name(name)
    if base in REFERENCES:
        ref_base, meaning = REFERENCES[base]
        for candidate in (ref_base + args, ref_base):
            if candidate in medians:
                return candidate, meaning
    for suffix in ("1Thread", "_1Thread"):
        twin = base + suffix + args
        if twin in medians:
            return twin, "speed-up over 1 thread"
    return None, None


def throughput(run):
    if "bytes_per_second" in run:
        return run["bytes_per_second"] / 1e6, "MB/s"
    if "items_per_second" in run:
        return run["items_per_second"], "items/s"
    return 1e9 / run["real_time"] if run.get("time_unit") == "ns" else None, "runs/s"


def format_time(value, unit):
    seconds = value * {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[unit]
    for scale, name in ((1.0, "s"), (1e-3, "ms"), (1e-6, "us")):
        if seconds >= scale:
            return f"{seconds / scale:.3g} {name}"
    return f"{seconds / 1e-9:.3g} ns"


def main(paths):
    medians = {}
    context = None
    for path in paths:
        with open(path) as f:
            data = json.load(f)
        context = context or data.get("context", {})
        runs = data["benchmarks"]
        has_aggregates = any(r.get("run_type") == "aggregate" for r in runs)
        for r in runs:
            if has_aggregates and r.get("aggregate_name") != "median":
                continue
            name = r["run_name"] if "run_name" in r else r["name"]
            base, args = split_name(name)
            medians[base + args] = r
    if context:
        print(f"# {context.get('host_name', '')}: {context.get('num_cpus', '?')} cpus, "
              f"{context.get('date', '')}; medians of repetitions")
    print(f"{'benchmark':40} {'median time':>14} {'throughput':>18}   ratio vs reference")
    for name, run in sorted(medians.items()):
        value, unit = throughput(run)
        time = format_time(run["real_time"], run["time_unit"])
        ratio = ""
        ref, meaning = reference_for(name, medians)
        if ref and value is not None:
            ref_value, _ = throughput(medians[ref])
            ratio = f"{value / ref_value:8.3f}x  ({meaning})"
        shown = f"{value:,.1f} {unit}" if value is not None else "-"
        print(f"{name:40} {time:>14} {shown:>18}   {ratio}")


if __name__ == "__main__":
    main(sys.argv[1:])
