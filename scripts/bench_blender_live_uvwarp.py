"""Frame rate of the add-on's live UV warp inside Blender, headless.

    blender -b --factory-startup --python scripts/bench_blender_live_uvwarp.py -- BUILD/blender \
        [--texels T] [--frames N] [--profile]

Keenan Crane's Spot (tests/data/spot) with its own UVs, twisted by a keyed angle over N frames (24), rigid
disks painted in a T x T rigidity image (1024): live mode on, every frame change solves the warm-started
warp (the add-on's live preset for a T x T grid: one iteration a frame) and fills the T x T redirect image
the material reads. Prints the medians over the frames of: the whole frame change with live mode, the same
frame change without it, and the live step alone (solve, redirect map, image fill), with its frame rate.
"""

import os
import statistics
import sys
import time

import bpy
import numpy as np

args = sys.argv[sys.argv.index("--") + 1:]
sys.path.insert(0, args[0])
texels = int(args[args.index("--texels") + 1]) if "--texels" in args else 1024
frames = int(args[args.index("--frames") + 1]) if "--frames" in args else 24
import deformkit as addon  # noqa: E402

addon.register()
dk = addon.core.dk
HERE = os.path.dirname(os.path.abspath(__file__))

source = dk.read_mesh(os.path.join(HERE, "..", "tests", "data", "spot", "spot_quadrangulated.obj"))
counts, indices = np.asarray(source.face_counts), np.asarray(source.face_indices)
starts = np.concatenate(([0], np.cumsum(counts)[:-1]))
mesh = bpy.data.meshes.new("spot")
mesh.from_pydata(np.asarray(source.points).tolist(), [], [indices[s:s + c].tolist() for s, c in zip(starts, counts)])
mesh.uv_layers.new(name="UVMap").data.foreach_set("uv", np.asarray(source.uvs)[np.asarray(source.uv_indices)].ravel())
obj = bpy.data.objects.new("spot", mesh)
scene = bpy.context.scene
scene.collection.objects.link(obj)
bpy.context.view_layer.objects.active = obj
material = bpy.data.materials.new("skin")
material.use_nodes = True
material.node_tree.nodes.new('ShaderNodeTexImage').image = bpy.data.images.new("scales", 8, 8)
mesh.materials.append(material)

bpy.ops.deformkit.add(type='twist')
entry = obj.deformkit.entries[0]
entry.start_value = 0.0
for frame, angle in ((1, 0.0), (frames + 1, 1.2)):
    entry.end_value = angle
    entry.keyframe_insert("end_value", frame=frame)

# Rigid disks (radius 0.02 of the tile, 0.06 apart) all over the tile: those outside the charts are inert.
ys, xs = np.mgrid[0:texels, 0:texels]
disks = np.zeros((texels, texels), np.float32)
for cy in np.arange(0.03, 1.0, 0.06):
    for cx in np.arange(0.03, 1.0, 0.06):
        disks[((xs + 0.5) / texels - cx) ** 2 + ((ys + 0.5) / texels - cy) ** 2 < 0.02 ** 2] = 1.0
rgba = np.zeros((texels, texels, 4), np.float32)
rgba[..., 0], rgba[..., 3] = disks[::-1], 1.0  # Blender's rows bottom-up
rigidity = bpy.data.images.new("rigidity", texels, texels, float_buffer=True)
rigidity.pixels.foreach_set(rgba.ravel())
obj.deformkit.uv_rigidity = rigidity


def time_frames():
    out = []
    for f in range(2, frames + 2):
        t0 = time.perf_counter()
        scene.frame_set(f)
        out.append((time.perf_counter() - t0) * 1e3)
    return out


scene.frame_set(1)
without = time_frames()
scene.frame_set(1)
assert bpy.ops.deformkit.uvwarp_live() == {'FINISHED'}
with_live = time_frames()
live_fps, live_ms = addon.uvwarp.live_rate(obj)
a, b = statistics.median(with_live), statistics.median(without)
print(f"# Blender {bpy.app.version_string}, {os.cpu_count()} cores, Spot ({len(mesh.vertices):,} vertices), "
      f"{texels}^2 redirect map, median of {frames} frames")
print(f"frame change, live UV warp   {a:8.1f} ms   ({1000.0 / a:5.1f} frames/s)")
print(f"frame change, without        {b:8.1f} ms")
print(f"live step alone              {live_ms:8.1f} ms   ({live_fps:5.1f} frames/s)")
if "--profile" in args:  # the live step's parts, timed around the module's calls
    state = addon.uvwarp._live[obj.name]
    solver, image = state["solver"], bpy.data.images[state["image"]]
    points = addon.uvwarp.live_points(obj, bpy.context.evaluated_depsgraph_get(), solver.num_vertices)
    parts = {"solve": [], "redirect_map": [], "fill": []}
    for _ in range(10):
        t0 = time.perf_counter()
        solver.solve(points)
        t1 = time.perf_counter()
        redirect = solver.redirect_map()
        t2 = time.perf_counter()
        addon.uvwarp._fill(state, image, redirect)
        t3 = time.perf_counter()
        for name, dt in (("solve", t1 - t0), ("redirect_map", t2 - t1), ("fill", t3 - t2)):
            parts[name].append(dt * 1e3)
    print("  " + ", ".join(f"{k} {statistics.median(v):.1f} ms" for k, v in parts.items()))
