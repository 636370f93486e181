"""Interactive rate of the Blender add-on: a 100k-vertex slide evaluated on frame change, headless.

    blender -b --factory-startup --python scripts/bench_blender_addon.py -- BUILD/blender [--frames N]

Prints medians over N frame changes (the slide's end Empty animated, so every frame has a new
displacement) of, in the same run:
  frame change, DeformKit   scene.frame_set with the add-on's stack on the grid (Blender's frame change,
                            the handler reading the controls, the stack's evaluate, writing the mesh)
  frame change, no stack    the same scene with the stack's envelope at 0 (what Blender costs anyway)
  evaluate alone            DeformerStack.evaluate through the module on the same rest points and parameters
and the ratios: the add-on's frame over the bare evaluate, and its frames per second.
"""

import statistics
import sys
import time

import bpy
import numpy as np

args = sys.argv[sys.argv.index("--") + 1:]
sys.path.insert(0, args[0])
frames = int(args[args.index("--frames") + 1]) if "--frames" in args else 30
import deformkit as addon  # noqa: E402

addon.register()
dk = addon.core.dk

n = 317  # 100,489 vertices on [-1, 1]^2
xs = np.linspace(-1.0, 1.0, n, dtype=np.float32)
X, Y = np.meshgrid(xs, xs)
points = np.stack([X.ravel(), Y.ravel(), np.zeros(n * n, np.float32)], axis=1)
i, j = np.meshgrid(np.arange(n - 1), np.arange(n - 1))
v0 = (j * n + i).ravel()
faces = np.stack([v0, v0 + 1, v0 + n + 1, v0 + n], axis=1)
mesh = bpy.data.meshes.new("grid")
mesh.vertices.add(len(points))
mesh.vertices.foreach_set("co", points.ravel())
mesh.loops.add(faces.size)
mesh.loops.foreach_set("vertex_index", faces.ravel().astype(np.int32))
mesh.polygons.add(len(faces))
mesh.polygons.foreach_set("loop_start", np.arange(0, faces.size, 4, dtype=np.int32))
mesh.polygons.foreach_set("loop_total", np.full(len(faces), 4, np.int32))
mesh.update()
obj = bpy.data.objects.new("grid", mesh)
bpy.context.scene.collection.objects.link(obj)
bpy.context.view_layer.objects.active = obj
bpy.context.scene.cursor.location = (0.0, 0.0, 0.0)

bpy.ops.deformkit.add(type='slide')
entry = obj.deformkit.entries[0]
entry.radius = 0.5  # about 20% of the vertices move
end = entry.end
for f in range(1, frames + 3):
    end.location = (0.2 * np.cos(f / 5.0), 0.2 * np.sin(f / 5.0), 0.0)
    end.keyframe_insert("location", frame=f)
scene = bpy.context.scene


def time_frames(first):
    out = []
    for f in range(first, first + frames):
        t0 = time.perf_counter()
        scene.frame_set(f)
        out.append((time.perf_counter() - t0) * 1e3)
    return out


scene.frame_set(2)  # bind (geodesic region, adjacency) once, outside the timing
time_frames(3)  # a rehearsal: the slide's first pass over new landings is slower (its caches fill)
scene.frame_set(2)
with_stack = time_frames(3)
scene.frame_set(2)
assert obj.deformkit.status == "", obj.deformkit.status

# The same displacements in the same order from the same state (the slide starts each evaluation from the
# last one's landings, so its cost depends on the path): the Empty's curves evaluated at each frame.
stack = addon.evaluate._cache[obj.name]["stack"]
rest = addon.evaluate.rest_points(obj)
curves = sorted(end.animation_data.action.fcurves, key=lambda c: c.array_index)


def displacement(f):
    return [c.evaluate(f) for c in curves]


stack.set(0, "displacement", displacement(2))
stack.evaluate(rest)
evaluate_alone = []
for f in range(3, 3 + frames):
    stack.set(0, "displacement", displacement(f))
    t0 = time.perf_counter()
    stack.evaluate(rest)
    evaluate_alone.append((time.perf_counter() - t0) * 1e3)

entry.envelope = 0.0
scene.frame_set(2)
without_stack = time_frames(3)

a, b, c = (statistics.median(x) for x in (with_stack, without_stack, evaluate_alone))
print(f"# Blender {bpy.app.version_string}, {len(points):,}-vertex grid, slide radius 0.5, median of {frames}")
print(f"frame change, DeformKit   {a:8.2f} ms   ({1000.0 / a:5.1f} frames/s)")
print(f"frame change, no stack    {b:8.2f} ms")
print(f"evaluate alone            {c:8.2f} ms")
print(f"add-on frame / evaluate   {a / c:8.2f}x")
