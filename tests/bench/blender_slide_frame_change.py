"""Frame-change time of a ~100k-vertex mesh in headless Blender with and without the add-on's slide entry
(Pinskiy's claim: a slide with ~500 active vertices, driven by a start and an end locator, costs a 100k-vertex
mesh under 5% of its frame rate).

    blender -b --factory-startup --python-exit-code 1 --python tests/bench/blender_slide_frame_change.py -- \\
        BUILD/blender [--reps N] [--frames N] [--active N] [--mesh sphere|suzanne] [--no-rig] [--out JSON] \\
        [--table TEXT]

BUILD/blender is the staged add-on (the `deformkit_blender_addon` target of the `all` build). Not a ctest
test: scripts/bench.sh runs it when Blender and the staged add-on exist.

The mesh, made here and applied to real geometry: a UV sphere of 200 segments x 125 rings with one
Catmull-Clark level (99,602 vertices, the default), or Suzanne with four levels (126,290). Each variant has
two scenes with their own copies of the same objects:
  with      the mesh with a slide entry added by the add-on's operator (deformkit.add, as a user would: the
            handle is the vertex nearest the 3D cursor), its radius chosen so that --active vertices (500)
            are in the geodesic support region (the module's Slider.active_vertices, bisection on the
            radius); the end Empty is keyframed, linearly from the start Empty to half the radius along the
            surface's tangent over the frames, so the slide changes every frame
  without   the same mesh without an entry, and the same two Empties with the same animation
Variants: `static` (nothing else moves the mesh) and `rig` (an Armature modifier with two keyed bones, every
vertex weighted, so Blender deforms the whole mesh every frame in both scenes).

One block times scene.frame_set(f) for f = 2 .. frames + 1 after an untimed frame_set(1) (frames 50); the
blocks alternate without / with (A/B/A/B), --reps blocks of each (5) after one untimed block of each, with
Python's garbage collector off inside a block. Reported per variant, from the median per-frame time over all
timed frames of all repetitions:
  slowdown = t_with / t_without
  drop     = 1 - rate_with / rate_without = 1 - t_without / t_with   (the claim: drop < 5%)
with the spread of the per-repetition ratios, the add-on's handler time per frame (frame_change_post,
recorded during the same blocks), the stack's evaluate alone on the same displacements (in the frames'
order from frame 1, as the slide's cost depends on its previous landings; again with its OpenMP loops on one
thread, which shows what waiting for a second thread costs on a busy machine), and "after":
t_with - t_without - handler, what Blender spends because the handler wrote the mesh (it evaluates the
object again after frame_change_post; with the Armature modifier, that is the armature deform again).

Checks that the figures measure a real slide: the add-on wrote the slid positions (moved vertices are in the
support region and their count is near the active count), they change from frame to frame, the evaluated
mesh carries them, the entry never rebinds during the timed frames, and its status line stays empty.
"""

import argparse
import ctypes
import gc
import json
import os
import statistics
import sys
import time

import bpy
import numpy as np


def parse(argv):
    parser = argparse.ArgumentParser(prog="blender_slide_frame_change.py")
    parser.add_argument("stage", help="the staged add-on folder (BUILD/blender)")
    parser.add_argument("--reps", type=int, default=5, help="timed blocks per scene (A/B/A/B)")
    parser.add_argument("--frames", type=int, default=50, help="frame changes per block")
    parser.add_argument("--active", type=int, default=500, help="target count of active vertices")
    parser.add_argument("--mesh", choices=["sphere", "suzanne"], default="sphere")
    parser.add_argument("--no-rig", action="store_true", help="only the static variant")
    parser.add_argument("--out", help="also write the figures as JSON here")
    parser.add_argument("--table", help="also write the printed table here (scripts/bench.sh shows it)")
    return parser.parse_args(argv)


ARGS = parse(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else [])
sys.path.insert(0, ARGS.stage)
import deformkit as addon  # noqa: E402  (the add-on package; its compiled module is addon.core.dk)

addon.register()
dk = addon.core.dk

# Where the handle goes (the 3D cursor; the operator takes the nearest vertex), per mesh: the sphere's
# equator, Suzanne's forehead.
HANDLE_AT = {"sphere": (1.0, 0.0, 0.0), "suzanne": (0.0, -0.75, 0.55)}


# ---- scene set-up -----------------------------------------------------------------------------------------

def clear():
    for collection in (bpy.data.objects, bpy.data.meshes, bpy.data.armatures, bpy.data.actions):
        for block in list(collection):
            collection.remove(block)


def make_mesh(kind):
    """The base mesh, its subdivision applied: a new mesh datablock."""
    if kind == "sphere":
        bpy.ops.mesh.primitive_uv_sphere_add(segments=200, ring_count=125, radius=1.0)
        levels = 1
    else:
        bpy.ops.mesh.primitive_monkey_add(size=2.0)
        levels = 4
    source = bpy.context.object
    modifier = source.modifiers.new("subdivision", 'SUBSURF')
    modifier.levels = levels
    modifier.quality = 3
    depsgraph = bpy.context.evaluated_depsgraph_get()
    mesh = bpy.data.meshes.new_from_object(source.evaluated_get(depsgraph))
    mesh.name = kind
    old = source.data
    bpy.data.objects.remove(source)
    bpy.data.meshes.remove(old)
    return mesh


def positions(mesh):
    out = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("co", out)
    return out.reshape(-1, 3)


def topology(mesh):
    counts = np.empty(len(mesh.polygons), np.int32)
    mesh.polygons.foreach_get("loop_total", counts)
    indices = np.empty(len(mesh.loops), np.int32)
    mesh.loops.foreach_get("vertex_index", indices)  # polygons' loops are in order in a new mesh
    return counts, indices


_radii = {}


def radius_for(mesh, vertex, target):
    """The geodesic radius whose support region around `vertex` holds about `target` vertices (bisection)."""
    if (mesh.name, vertex, target) not in _radii:
        _radii[mesh.name, vertex, target] = _bisect_radius(mesh, vertex, target)
    return _radii[mesh.name, vertex, target]


def _bisect_radius(mesh, vertex, target):
    points = positions(mesh)
    counts, indices = topology(mesh)

    def active(r):
        slider = dk.Slider(points, counts, indices, handle=vertex, radius=r, region="geodesic")
        return len(slider.active_vertices)

    lo, hi = 0.0, 0.01 * float(np.ptp(points, axis=0).max())
    while active(hi) < target:
        lo, hi = hi, 2.0 * hi
    for _ in range(24):
        mid = 0.5 * (lo + hi)
        n = active(mid)
        if abs(n - target) <= max(1, target // 100):
            return mid
        lo, hi = (mid, hi) if n < target else (lo, mid)
    return hi


def add_rig(scene, obj):
    """A two-bone Armature along Z over the mesh, both bones keyed, every vertex weighted (blended between
    the bones over the middle of the mesh), as the Armature modifier of `obj`."""
    points = positions(obj.data)
    zlo, zhi = float(points[:, 2].min()), float(points[:, 2].max())
    zmid = 0.5 * (zlo + zhi)
    data = bpy.data.armatures.new(f"{scene.name}_rig")
    rig = bpy.data.objects.new(f"{scene.name}_rig", data)
    scene.collection.objects.link(rig)
    bpy.context.view_layer.objects.active = rig
    bpy.ops.object.mode_set(mode='EDIT')
    lower = data.edit_bones.new("lower")
    lower.head, lower.tail = (0.0, 0.0, zlo), (0.0, 0.0, zmid)
    upper = data.edit_bones.new("upper")
    upper.head, upper.tail = (0.0, 0.0, zmid), (0.0, 0.0, zhi)
    upper.parent = lower
    upper.use_connect = True
    bpy.ops.object.mode_set(mode='OBJECT')
    for name, angle in (("lower", 0.2), ("upper", 0.5)):
        bone = rig.pose.bones[name]
        bone.rotation_mode = 'XYZ'
        bone.rotation_euler = (0.0, 0.0, 0.0)
        bone.keyframe_insert("rotation_euler", frame=1)
        bone.rotation_euler = (angle, 0.0, 0.3 * angle)
        bone.keyframe_insert("rotation_euler", frame=ARGS.frames + 1)
    linear(rig)

    blend = np.clip((points[:, 2] - zmid) / (0.4 * (zhi - zlo)) + 0.5, 0.0, 1.0)
    levels = np.round(blend * 20).astype(int)  # weights in steps of 1/20, added level by level
    groups = {name: obj.vertex_groups.new(name=name) for name in ("lower", "upper")}
    for level in range(21):
        members = np.flatnonzero(levels == level).tolist()
        if members:
            if level < 20:
                groups["lower"].add(members, 1.0 - level / 20.0, 'REPLACE')
            if level > 0:
                groups["upper"].add(members, level / 20.0, 'REPLACE')
    modifier = obj.modifiers.new("rig", 'ARMATURE')
    modifier.object = rig
    return rig


def linear(obj):
    for curve in obj.animation_data.action.fcurves:
        for key in curve.keyframe_points:
            key.interpolation = 'LINEAR'


def build_variant(name, base_mesh, rig):
    """The `with` and `without` scenes of one variant: (scene_with, scene_without, obj_with, entry)."""
    window = bpy.context.window
    scene_with = bpy.data.scenes.new(f"{name}_with")
    scene_without = bpy.data.scenes.new(f"{name}_without")
    for scene in (scene_with, scene_without):
        scene.frame_start, scene.frame_end = 1, ARGS.frames + 1
        scene.sync_mode = 'NONE'  # Play Every Frame, as the startup file's scene (a new one syncs to audio)

    window.scene = scene_with
    obj = bpy.data.objects.new(f"{name}_mesh", base_mesh.copy())
    scene_with.collection.objects.link(obj)
    if rig:
        add_rig(scene_with, obj)

    # The scene without the slide: copies made before the entry exists (no entry, no rest attribute).
    window.scene = scene_without
    plain = obj.copy()
    plain.data = obj.data.copy()
    plain.name = f"{name}_mesh_plain"
    scene_without.collection.objects.link(plain)
    if rig:  # the copy carries the vertex groups and the modifier; its rig is a copy too (the same action)
        plain_rig = obj.modifiers["rig"].object.copy()
        scene_without.collection.objects.link(plain_rig)
        plain.modifiers["rig"].object = plain_rig

    window.scene = scene_with
    view_layer = scene_with.view_layers[0]
    view_layer.objects.active = obj
    obj.select_set(True)
    scene_with.cursor.location = HANDLE_AT[ARGS.mesh]
    scene_with.frame_set(1)
    result = bpy.ops.deformkit.add(type="slide")
    assert result == {'FINISHED'}, result
    entry = obj.deformkit.entries[0]
    entry.radius = radius_for(base_mesh, entry.vertex, ARGS.active)

    # The end Empty moves from the start Empty to half the radius along the surface, linearly over the frames.
    normal = np.array(base_mesh.vertices[entry.vertex].normal, np.float64)
    tangent = np.cross(normal, (0.0, 0.0, 1.0) if abs(normal[2]) < 0.9 else (1.0, 0.0, 0.0))
    tangent /= np.linalg.norm(tangent)
    start = np.array(entry.start.location, np.float64)
    entry.end.location = start
    entry.end.keyframe_insert("location", frame=1)
    entry.end.location = start + 0.5 * entry.radius * tangent
    entry.end.keyframe_insert("location", frame=ARGS.frames + 1)
    linear(entry.end)
    for empty in (entry.start, entry.end):
        scene_without.collection.objects.link(empty.copy())  # same action: the same animation
    return scene_with, scene_without, obj, entry


# ---- timing ---------------------------------------------------------------------------------------------

_handler_ms = []


def _timed(handler):
    def wrapper(scene, depsgraph=None):
        t0 = time.perf_counter()
        handler(scene, depsgraph)
        _handler_ms.append((time.perf_counter() - t0) * 1e3)
    return wrapper


def time_block(scene):
    """Per-frame ms of frame_set(2 .. frames + 1) after an untimed frame_set(1), and the handler's ms."""
    bpy.context.window.scene = scene
    bpy.context.evaluated_depsgraph_get()  # the played scene's depsgraph is the active one, as in a session
    scene.frame_set(1)
    gc.collect()
    gc.disable()
    _handler_ms.clear()
    times = []
    try:
        for f in range(2, ARGS.frames + 2):
            t0 = time.perf_counter()
            scene.frame_set(f)
            times.append((time.perf_counter() - t0) * 1e3)
    finally:
        gc.enable()
    return times, list(_handler_ms)


def check_slide(scene, obj, entry, active):
    """The add-on really slid the mesh: returns (moved vertices, max change between two frames)."""
    bpy.context.window.scene = scene
    rest = addon.evaluate.rest_points(obj)
    scene.frame_set(ARGS.frames)
    before = positions(obj.data)
    scene.frame_set(ARGS.frames + 1)
    after = positions(obj.data)
    assert obj.deformkit.status == "", obj.deformkit.status
    moved = np.flatnonzero(np.any(after != rest, axis=1))
    assert moved.size > active.size // 2, (moved.size, active.size)
    assert np.isin(moved, active).all(), "vertices outside the support region moved"
    change = float(np.abs(after - before).max())
    assert change > 0.0, "the slide did not change between frames"
    if not obj.modifiers:  # the evaluated mesh carries the add-on's positions (Blender's second pass)
        depsgraph = bpy.context.evaluated_depsgraph_get()
        assert np.array_equal(positions(obj.evaluated_get(depsgraph).data), after)
    return moved, change


def evaluate_alone(scene, obj, entry):
    """ms of the stack's evaluate through the module on the frames' displacements, in the frames' order."""
    stack = addon.evaluate._cache[obj.name]["stack"]
    rest = addon.evaluate.rest_points(obj)
    start = np.array(entry.start.location, np.float64)
    curves = sorted(entry.end.animation_data.action.fcurves, key=lambda c: c.array_index)
    out = []
    for f in range(1, ARGS.frames + 2):
        stack.set(0, "displacement", np.array([c.evaluate(f) for c in curves]) - start)
        t0 = time.perf_counter()
        stack.evaluate(rest)
        if f > 1:
            out.append((time.perf_counter() - t0) * 1e3)
    return out


def openmp_runtime():
    """The OpenMP runtime the module runs on (already loaded in this process), or None."""
    for name in ("libgomp.so.1", "libomp.so", "libomp.so.5"):
        try:
            runtime = ctypes.CDLL(name, mode=getattr(os, "RTLD_NOLOAD", 0) | os.RTLD_GLOBAL)
        except OSError:
            continue
        runtime.omp_get_max_threads.restype = ctypes.c_int
        return runtime
    return None


def evaluate_alone_one_thread(scene, obj, entry):
    """evaluate_alone with the OpenMP loops on this thread only (None without a known runtime)."""
    runtime = openmp_runtime()
    if runtime is None:
        return None
    threads = runtime.omp_get_max_threads()
    runtime.omp_set_num_threads(1)
    try:
        return evaluate_alone(scene, obj, entry)
    finally:
        runtime.omp_set_num_threads(threads)


def median(values):
    return statistics.median(values)


def main():
    load_before = os.getloadavg()
    clear()
    base_mesh = make_mesh(ARGS.mesh)
    handlers = bpy.app.handlers.frame_change_post
    for i, h in enumerate(handlers):
        if h is addon.handlers.on_frame_change:
            handlers[i] = _timed(h)

    variants = {"static": build_variant("static", base_mesh, rig=False)}
    if not ARGS.no_rig:
        variants["rig"] = build_variant("rig", base_mesh, rig=True)

    results = {}
    for name, (scene_with, scene_without, obj, entry) in variants.items():
        counts, indices = topology(base_mesh)
        slider = dk.Slider(positions(base_mesh), counts, indices, handle=entry.vertex, radius=entry.radius,
                           region="geodesic")
        active = np.asarray(slider.active_vertices)
        time_block(scene_without)  # warm-up: first evaluations allocate, the slide's landings fill
        time_block(scene_with)
        stack = addon.evaluate._cache[obj.name]["stack"]
        binds = stack.bind_count
        samples = {"without": [], "with": []}
        handler = {"without": [], "with": []}
        for _ in range(ARGS.reps):
            for key, scene in (("without", scene_without), ("with", scene_with)):
                times, handled = time_block(scene)
                samples[key].append(times)
                handler[key].append(handled)
        assert stack.bind_count == binds, "the slide rebound during the timed frames"
        moved, change = check_slide(scene_with, obj, entry, active)
        alone = evaluate_alone(scene_with, obj, entry)
        alone_one = evaluate_alone_one_thread(scene_with, obj, entry)

        t_without = median([t for block in samples["without"] for t in block])
        t_with = median([t for block in samples["with"] for t in block])
        pair = [median(w) / median(o) for w, o in zip(samples["with"], samples["without"])]
        results[name] = {
            "vertices": len(obj.data.vertices),
            "active_vertices": int(active.size),
            "moved_vertices": int(moved.size),
            "max_change_between_frames": change,
            "handle_vertex": entry.vertex,
            "radius": entry.radius,
            "armature": bool(obj.modifiers),
            "frame_ms_without": t_without,
            "frame_ms_with": t_with,
            "slowdown": t_with / t_without,
            "drop": 1.0 - t_without / t_with,
            "slowdown_per_repetition": pair,
            "handler_ms_with": median([t for block in handler["with"] for t in block]),
            "handler_ms_without": median([t for block in handler["without"] for t in block]),
            "evaluate_alone_ms": median(alone),
            "evaluate_alone_one_thread_ms": median(alone_one) if alone_one else None,
            "block_medians_ms_without": [median(b) for b in samples["without"]],
            "block_medians_ms_with": [median(b) for b in samples["with"]],
        }

    first = next(iter(results.values()))
    openmp = {k: os.environ[k] for k in ("OMP_NUM_THREADS", "OMP_WAIT_POLICY") if k in os.environ}
    report = {"blender": bpy.app.version_string, "cpus": os.cpu_count(), "openmp_environment": openmp,
              "load_average_before": load_before, "load_average_after": os.getloadavg(), "mesh": ARGS.mesh,
              "frames": ARGS.frames, "repetitions": ARGS.reps, "variants": results}
    lines = [
        f"# Slide frame change in Blender {bpy.app.version_string}, headless, {os.cpu_count()} cpus (load "
        f"average {load_before[0]:.1f} before, {os.getloadavg()[0]:.1f} after; OpenMP environment "
        f"{' '.join(f'{k}={v}' for k, v in openmp.items()) or 'default'}): {ARGS.mesh} of "
        f"{first['vertices']:,} vertices, {first['active_vertices']} active (geodesic radius "
        f"{first['radius']:.4g}), end Empty keyed",
        f"# median frame_set over {ARGS.frames} frames x {ARGS.reps} repetitions per scene, alternating "
        f"without / with; drop = 1 - rate_with / rate_without (claim: < 5%); handler = the add-on's "
        f"frame_change_post, evaluate = the stack's evaluate alone (part of handler; 1 thr: OpenMP on one "
        f"thread), after = with - without - handler",
        f"{'variant':8} {'without':>10} {'with':>10} {'with/without':>13} {'drop':>6} {'per-rep ratio':>13} "
        f"{'handler':>9} {'evaluate':>9} {'1 thr':>9} {'after':>9} {'moved':>6}",
    ]
    for name, r in results.items():
        spread = f"{min(r['slowdown_per_repetition']):.3g}-{max(r['slowdown_per_repetition']):.3g}"
        verdict = "meets" if r["drop"] < 0.05 else "MISSES"
        after = r["frame_ms_with"] - r["frame_ms_without"] - r["handler_ms_with"]
        one = r["evaluate_alone_one_thread_ms"]
        one = f"{one:6.2f} ms" if one is not None else f"{'-':>9}"
        lines.append(
            f"{name:8} {r['frame_ms_without']:7.3f} ms {r['frame_ms_with']:7.2f} ms {r['slowdown']:12.3g}x "
            f"{100 * r['drop']:5.1f}% {spread:>13} {r['handler_ms_with']:6.2f} ms "
            f"{r['evaluate_alone_ms']:6.2f} ms {one} {after:6.2f} ms {r['moved_vertices']:6}  "
            f"({verdict} the claim)")
    print()
    print("\n".join(lines))
    if ARGS.table:
        with open(ARGS.table, "w") as f:
            f.write("\n".join(lines) + "\n")
    if ARGS.out:
        with open(ARGS.out, "w") as f:
            json.dump(report, f, indent=2)
            f.write("\n")


main()
