"""Times Blender's Lattice and SimpleDeform modifiers on the benchmarks' 1,001,000-vertex grid, headless,
as the in-run reference for our FFD and Barr evaluates.

    blender -b --factory-startup --python scripts/bench_blender.py -- [--reps N] [--out FILE]

The modifier share of one repetition is (depsgraph evaluation of an object with the modifier) minus
(evaluation of the same grid without a modifier), both timed back to back; the JSON reports the median share
per modifier in ms. Blender is started without -t, so its task scheduler uses every core, as our OpenMP
loops do by default.

What is compared (the grids and lattice mirror tests/bench/ffd_bench.cpp and barr_bench.cpp):
- grid: 1000 x 999 quads, 1001 x 1000 vertices, in the z = 0 plane; 1 x 1 for the lattice, 4 x 1 for
  SimpleDeform (makeGrid({1000, 999, 1, 1}) and makeGrid({1000, 999, 4, 1})).
- Lattice: 4 x 4 x 4 points (our divisions 3, 3, 3) over the box origin (-0.05, -0.05, -0.5), edges 1.1, 1.1,
  1.0, every point moved by the offsets our benchmark gives its targets. Interpolation KEY_BSPLINE on all
  three axes (Blender's default): it is the only Blender type whose 4 weights per axis are all non-zero for
  every vertex, so Blender sums 64 controls per vertex as our Bernstein cubic does (KEY_LINEAR would skip
  the zero weights and do less work). The shapes differ (uniform B-spline vs Bernstein); the work is alike.
- SimpleDeform TAPER (factor 0.5) and TWIST (angle 3 rad) about the X axis, the grid's long side, and BEND
  (angle 1.6 rad) about Z, which curls the long side in the grid's plane (ours bends it out of the plane;
  the work per vertex is the same); default limits. Blender's taper is linear and its twist angle linear in the axis coordinate;
  ours read a smooth profile curve per point, which is more work per vertex, not less.
"""
import argparse
import json
import math
import os
import statistics
import sys
import time

import bpy
import numpy as np

CELLS_X, CELLS_Y = 1000, 999


def make_grid(name, size_x, size_y):
    """The quad grid of geom::makeGrid: vertex (i, j) at (i / cx * size_x, j / cy * size_y, 0), row-major."""
    nx, ny = CELLS_X + 1, CELLS_Y + 1
    u = np.arange(nx, dtype=np.float32) / CELLS_X * size_x
    v = np.arange(ny, dtype=np.float32) / CELLS_Y * size_y
    co = np.zeros((ny, nx, 3), dtype=np.float32)
    co[:, :, 0] = u[None, :]
    co[:, :, 1] = v[:, None]
    j, i = np.meshgrid(np.arange(CELLS_Y), np.arange(CELLS_X), indexing="ij")
    a = (j * nx + i).ravel().astype(np.int32)
    quads = np.stack([a, a + 1, a + 1 + nx, a + nx], axis=1).ravel()
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(nx * ny)
    mesh.vertices.foreach_set("co", co.ravel())
    mesh.loops.add(quads.size)
    mesh.loops.foreach_set("vertex_index", quads)
    faces = quads.size // 4
    mesh.polygons.add(faces)
    mesh.polygons.foreach_set("loop_start", np.arange(0, quads.size, 4, dtype=np.int32))
    mesh.polygons.foreach_set("loop_total", np.full(faces, 4, dtype=np.int32))
    mesh.update(calc_edges=True)
    mesh.validate()
    return mesh


def add_object(name, mesh):
    obj = bpy.data.objects.new(name, mesh.copy())
    bpy.context.scene.collection.objects.link(obj)
    return obj


def add_lattice(interpolation):
    """4 x 4 x 4 lattice over the box of ffd_bench.cpp, points moved as its targets are."""
    lat = bpy.data.lattices.new("lattice")
    lat.points_u = lat.points_v = lat.points_w = 4
    lat.interpolation_type_u = lat.interpolation_type_v = lat.interpolation_type_w = interpolation
    obj = bpy.data.objects.new("lattice", lat)
    # Blender's lattice spans [-0.5, 0.5]^3 in its object space: centre and scale it onto our box.
    obj.location = (-0.05 + 0.55, -0.05 + 0.55, 0.0)
    obj.scale = (1.1, 1.1, 1.0)
    bpy.context.scene.collection.objects.link(obj)
    size = (1.1, 1.1, 1.0)
    for k in range(4):
        for j in range(4):
            for i in range(4):
                c = (i * 4 + j) * 4 + k  # our control index (C order, k fastest)
                offset = (0.02 * math.sin(0.7 * c), 0.03 * math.cos(1.3 * c), 0.1 * math.sin(0.4 * c))
                p = lat.points[i + 4 * j + 16 * k]  # Blender's order: u fastest
                p.co_deform = [p.co[a] + offset[a] / size[a] for a in range(3)]
    return obj


def evaluate_ms(depsgraph, obj):
    obj.update_tag(refresh={"DATA"})
    start = time.perf_counter()
    depsgraph.update()
    return (time.perf_counter() - start) * 1e3


def main(argv):
    parser = argparse.ArgumentParser(prog="bench_blender.py")
    parser.add_argument("--reps", type=int, default=15, help="repetitions; medians are reported")
    parser.add_argument("--out", help="write the JSON here (default: stdout)")
    parser.add_argument("--lattice-interpolation", default="KEY_BSPLINE",
                        choices=["KEY_BSPLINE", "KEY_LINEAR", "KEY_CARDINAL", "KEY_CATMULL_ROM"],
                        help="the lattice's interpolation on all axes (KEY_BSPLINE: see the docstring)")
    args = parser.parse_args(argv)

    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    ffd_grid = make_grid("ffd_grid", 1.0, 1.0)
    barr_grid = make_grid("barr_grid", 4.0, 1.0)

    base_ffd = add_object("none_ffd", ffd_grid)
    base_barr = add_object("none_barr", barr_grid)
    lattice = add_object("lattice_grid", ffd_grid)
    mod = lattice.modifiers.new("lattice", "LATTICE")
    mod.object = add_lattice(args.lattice_interpolation)
    deformed = {"lattice": (lattice, base_ffd)}
    for method, amount in (("TAPER", 0.5), ("TWIST", 3.0), ("BEND", 1.6)):
        obj = add_object(method.lower() + "_grid", barr_grid)
        mod = obj.modifiers.new(method.lower(), "SIMPLE_DEFORM")
        mod.deform_method = method
        # Taper and twist about X, the long side; Blender's bend about X would bend along the flat grid's
        # z (a no-op), so the bend is about Z and curls the long side within the grid's plane.
        mod.deform_axis = "Z" if method == "BEND" else "X"
        if method == "TAPER":
            mod.factor = amount
        else:
            mod.angle = amount
        deformed[method.lower()] = (obj, base_barr)

    depsgraph = bpy.context.evaluated_depsgraph_get()
    depsgraph.update()
    # Check that each modifier really moves the grid (a share of an idle modifier would mean nothing).
    for name, (obj, base) in deformed.items():
        n = len(obj.data.vertices)
        a = np.empty(n * 3, dtype=np.float32)
        b = np.empty(n * 3, dtype=np.float32)
        obj.evaluated_get(depsgraph).data.vertices.foreach_get("co", a)
        base.evaluated_get(depsgraph).data.vertices.foreach_get("co", b)
        moved = float(np.abs(a - b).max())
        if n != 1001000 or not moved > 1e-3:
            raise SystemExit(f"bench_blender: {name} has {n} vertices and moves them by {moved}")

    for _ in range(2):  # warm-up: first evaluations allocate
        for obj in [base_ffd, base_barr] + [o for o, _ in deformed.values()]:
            evaluate_ms(depsgraph, obj)

    none = {"ffd_grid": [], "barr_grid": []}
    shares = {name: [] for name in deformed}
    totals = {name: [] for name in deformed}
    for _ in range(args.reps):
        for name, (obj, base) in deformed.items():
            without = evaluate_ms(depsgraph, base)
            with_mod = evaluate_ms(depsgraph, obj)
            none["ffd_grid" if base is base_ffd else "barr_grid"].append(without)
            totals[name].append(with_mod)
            shares[name].append(with_mod - without)

    result = {
        "blender": bpy.app.version_string,
        "cpus": os.cpu_count(),
        "threads": "all (Blender started without -t)",
        "vertices": len(base_ffd.data.vertices),
        "repetitions": args.reps,
        "lattice_interpolation": args.lattice_interpolation,
        "eval_without_modifier_ms": {k: statistics.median(v) for k, v in none.items()},
        "eval_with_modifier_ms": {k: statistics.median(v) for k, v in totals.items()},
        "modifier_share_ms": {k: statistics.median(v) for k, v in shares.items()},
    }
    text = json.dumps(result, indent=2)
    if args.out:
        with open(args.out, "w") as f:
            f.write(text + "\n")
    else:
        print(text)


if __name__ == "__main__":
    main(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else [])
