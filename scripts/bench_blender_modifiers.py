"""The add-on against Blender's own modifiers doing the same deformation, inside one headless Blender run.

    blender -b --factory-startup --python scripts/bench_blender_modifiers.py -- BUILD/blender \
        [--rounds N] [--grid-only | --mesh-only] [--profile]

Two meshes: Keenan Crane's Spot (tests/data/spot) subdivided twice by Blender's Subdivision Surface
(46,850 vertices), and a 1,001,000-vertex grid. On each, seven scenes hold a copy of the mesh:
  plain       no deformer: what a frame change costs anyway
  write       a handler writes precomputed positions into the mesh: the floor of any add-on that deforms
              by writing the mesh from Python (Blender then copies and evaluates the mesh again)
  cache       the same positions written by a handler into a PC2 file that Blender's Mesh Cache modifier
              reads (the mesh left alone; the object tagged for evaluation)
  nodes       the same positions written into a vertex-only helper mesh that a Geometry Nodes modifier
              copies onto the mesh (Object Info, Sample Index by index, Set Position)
  shapekey    the same positions written into a shape key of value 1 (the mesh left alone, its Key tagged)
  blender     SimpleDeform TWIST (angle keyed) then a Lattice modifier (4 x 4 x 4 points, B-spline, moved)
  deformkit   the add-on's stack: twist (angles keyed to the same twist) then FFD "As the Lattice" on the
              same lattice object
write, cache, nodes and shapekey are the ways a Python add-on can hand Blender positions from a frame handler;
each is checked to show, after frame_set, the shape its handler wrote in that frame. Each round sets every
scene to the next frame with `scene.frame_set` (rounds alternate the scenes, so load from other processes
falls on all of them alike) and times it. Printed: medians over the rounds, the
net cost (minus the plain frame change), the ratio deformkit / blender of the net costs, and the largest
distance between the two deformed meshes (the same deformation, to float rounding). --profile prints where
the add-on's frame changes go instead (cProfile; Spot, or the grid with --grid-only).
"""

import os
import shutil
import statistics
import struct
import sys
import tempfile
import time

import bpy
import mathutils
import numpy as np

args = sys.argv[sys.argv.index("--") + 1:]
sys.path.insert(0, args[0])
rounds = int(args[args.index("--rounds") + 1]) if "--rounds" in args else 40
import deformkit as addon  # noqa: E402

addon.register()
dk = addon.core.dk
HERE = os.path.dirname(os.path.abspath(__file__))
FRAMES = 48
ANGLE = (0.5, 2.0)  # the twist angle (radians per unit along Z) keyed at frames 1 and FRAMES


def mesh_from_arrays(name, points, counts, indices):
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(len(points))
    mesh.vertices.foreach_set("co", np.asarray(points, np.float32).ravel())
    mesh.loops.add(len(indices))
    mesh.loops.foreach_set("vertex_index", np.asarray(indices, np.int32))
    mesh.polygons.add(len(counts))
    starts = np.concatenate(([0], np.cumsum(counts)[:-1])).astype(np.int32)
    mesh.polygons.foreach_set("loop_start", starts)
    mesh.polygons.foreach_set("loop_total", np.asarray(counts, np.int32))
    mesh.update()
    return mesh


def spot_subdivided():
    source = dk.read_mesh(os.path.join(HERE, "..", "tests", "data", "spot", "spot_quadrangulated.obj"))
    base = mesh_from_arrays("spot_base", source.points, source.face_counts, source.face_indices)
    holder = bpy.data.objects.new("spot_base", base)
    bpy.context.scene.collection.objects.link(holder)
    subsurf = holder.modifiers.new("Subdivision", 'SUBSURF')
    subsurf.levels = 2
    depsgraph = bpy.context.evaluated_depsgraph_get()
    mesh = bpy.data.meshes.new_from_object(holder.evaluated_get(depsgraph))
    mesh.name = "spot"
    bpy.data.objects.remove(holder)
    return mesh


def grid(n=1001, m=1000):
    xs = np.linspace(-1.0, 1.0, n, dtype=np.float32)
    ys = np.linspace(-1.0, 1.0, m, dtype=np.float32)
    X, Y = np.meshgrid(xs, ys)
    points = np.stack([X.ravel(), Y.ravel(), 0.25 * np.sin(3.0 * X.ravel())], axis=1)
    i, j = np.meshgrid(np.arange(n - 1), np.arange(m - 1))
    v0 = (j * n + i).ravel()
    faces = np.stack([v0, v0 + 1, v0 + n + 1, v0 + n], axis=1)
    return mesh_from_arrays("grid", points, np.full(len(faces), 4), faces.ravel())


def z_up(empty):
    """An Empty at the origin whose Y axis is world Z (the twist axis of SimpleDeform's deform_axis Z)."""
    empty.rotation_mode = 'QUATERNION'
    empty.rotation_quaternion = (0.5, 0.5, 0.5, 0.5)


def linear(id_block):
    for curve in id_block.animation_data.action.fcurves:
        for key in curve.keyframe_points:
            key.interpolation = 'LINEAR'


SHAPES = []  # the two position sets the floor handlers write, alternately
WRITTEN = {}  # per floor scene, the index of the shape its handler wrote last
SCRATCH = tempfile.mkdtemp(prefix="deformkit-bench-")


def pc2_header(vertices):
    """A PC2 point cache of one sample: 'POINTCACHE2\\0', version 1, points, start frame, sample rate, samples."""
    return b"POINTCACHE2\0" + struct.pack("<iiffi", 1, vertices, 0.0, 1.0, 1)


def handler_floors(scenes, points):
    """The ways a Python add-on can give Blender positions from frame_change_post, each writing precomputed
    positions (two sets, alternately): into the mesh, into a PC2 file read by a Mesh Cache modifier, into a
    helper mesh read by a Geometry Nodes modifier, into a shape key."""
    SHAPES[:] = [points.ravel().copy(), (points * 1.001).ravel()]

    def alternate(kind, own, write):
        state = {"next": 0}

        def handler(scene_, _depsgraph):
            if scene_ == own:
                write(SHAPES[state["next"]])
                WRITTEN[kind] = state["next"]
                state["next"] ^= 1

        bpy.app.handlers.frame_change_post.append(handler)

    scene, obj = scenes["write"]

    def write_mesh(shape, mesh=obj.data):
        mesh.vertices.foreach_set("co", shape)
        mesh.update()

    alternate("write", scene, write_mesh)

    scene, obj = scenes["cache"]
    path = os.path.join(SCRATCH, obj.name + ".pc2")
    with open(path, "wb") as f:
        f.write(pc2_header(len(points)) + SHAPES[0].tobytes())
    cache = obj.modifiers.new("Positions", 'MESH_CACHE')
    cache.cache_format, cache.filepath = 'PC2', path
    cache.play_mode, cache.time_mode, cache.interpolation, cache.eval_frame = 'CUSTOM', 'FRAME', 'NONE', 0.0

    def write_cache(shape, obj=obj):
        with open(path, "r+b") as f:
            f.seek(len(pc2_header(0)))
            f.write(shape.tobytes())
        obj.update_tag()

    alternate("cache", scene, write_cache)

    scene, obj = scenes["nodes"]
    helper_mesh = bpy.data.meshes.new(obj.name + "_positions")
    helper_mesh.vertices.add(len(points))
    helper_mesh.vertices.foreach_set("co", SHAPES[0])
    helper = bpy.data.objects.new(obj.name + "_positions", helper_mesh)
    scene.collection.objects.link(helper)
    group = bpy.data.node_groups.new("positions_by_index", 'GeometryNodeTree')
    group.inputs.new('NodeSocketGeometry', "Geometry")
    group.outputs.new('NodeSocketGeometry', "Geometry")
    nodes, links = group.nodes, group.links
    group_in, group_out = nodes.new('NodeGroupInput'), nodes.new('NodeGroupOutput')
    info = nodes.new('GeometryNodeObjectInfo')
    info.inputs['Object'].default_value = helper
    sample = nodes.new('GeometryNodeSampleIndex')
    sample.data_type, sample.domain = 'FLOAT_VECTOR', 'POINT'
    position, index = nodes.new('GeometryNodeInputPosition'), nodes.new('GeometryNodeInputIndex')
    set_position = nodes.new('GeometryNodeSetPosition')
    links.new(info.outputs['Geometry'], sample.inputs['Geometry'])
    links.new(position.outputs['Position'], sample.inputs[3])  # the vector value input
    links.new(index.outputs['Index'], sample.inputs['Index'])
    links.new(group_in.outputs[0], set_position.inputs['Geometry'])
    links.new(sample.outputs[2], set_position.inputs['Position'])  # the vector value output
    links.new(set_position.outputs['Geometry'], group_out.inputs[0])
    obj.modifiers.new("Positions", 'NODES').node_group = group

    def write_helper(shape, mesh=helper_mesh):
        mesh.vertices.foreach_set("co", shape)
        mesh.update()

    alternate("nodes", scene, write_helper)

    scene, obj = scenes["shapekey"]
    obj.shape_key_add(name="Basis")
    block = obj.shape_key_add(name="Positions")
    block.value = 1.0

    def write_key(shape, block=block, key=obj.data.shape_keys):
        block.data.foreach_set("co", shape)
        key.update_tag()

    alternate("shapekey", scene, write_key)


def check_floors(scenes):
    """Each floor scene shows, after frame_set, the shape its handler wrote in that frame (no frame of lag)."""
    for kind in ("write", "cache", "nodes", "shapekey"):
        scene, obj = scenes[kind]
        scene.frame_set(7)
        evaluated = obj.evaluated_get(scene.view_layers[0].depsgraph).data
        co = np.empty(len(evaluated.vertices) * 3, np.float32)
        evaluated.vertices.foreach_get("co", co)
        assert np.array_equal(co, SHAPES[WRITTEN[kind]]), f"{kind}: the evaluated mesh is not this frame's shape"


def build(mesh):
    points = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("co", points)
    points = points.reshape(-1, 3)
    low, high = points.min(axis=0), points.max(axis=0)
    lattice_data = bpy.data.lattices.new(mesh.name + "_lattice")
    lattice_data.points_u = lattice_data.points_v = lattice_data.points_w = 4  # B-spline, Blender's default
    rng = np.random.default_rng(3)
    lattice = bpy.data.objects.new(mesh.name + "_lattice", lattice_data)
    lattice.location = 0.5 * (low + high)
    lattice.scale = 1.1 * (high - low + 1e-3) / 3.0  # a new lattice's points are 1 apart: 3 units across
    for point in lattice_data.points:
        point.co_deform = mathutils.Vector(point.co) + mathutils.Vector(rng.uniform(-0.25, 0.25, 3))
    scenes = {}
    for kind in ("plain", "write", "cache", "nodes", "shapekey", "blender", "deformkit"):
        # The add-on's operators work on the context's scene: the deformkit copy goes there.
        scene = bpy.context.scene if kind == "deformkit" else bpy.data.scenes.new(kind)
        obj = bpy.data.objects.new(f"{mesh.name}_{kind}", mesh.copy())
        scene.collection.objects.link(obj)
        scene.collection.objects.link(lattice)
        scenes[kind] = (scene, obj)
    handler_floors(scenes, points)
    # Blender's modifiers: SimpleDeform TWIST about Z (origin: world), angle keyed; then the lattice.
    scene, obj = scenes["blender"]
    twist = obj.modifiers.new("Twist", 'SIMPLE_DEFORM')
    twist.deform_method, twist.deform_axis = 'TWIST', 'Z'
    for frame, angle in ((1, ANGLE[0]), (FRAMES, ANGLE[1])):
        twist.angle = angle
        obj.keyframe_insert(f'modifiers["Twist"].angle', frame=frame)
    linear(obj)
    obj.modifiers.new("Lattice", 'LATTICE').object = lattice
    # The add-on: a twist whose angles at the mesh's lowest and highest z are SimpleDeform's (theta = angle z /
    # (its limits' span), constant beyond them), keyed at the same frames; then the FFD on the same lattice.
    scene, obj = scenes["deformkit"]
    bpy.context.view_layer.objects.active = obj
    bpy.ops.deformkit.add(type='twist')
    bpy.ops.deformkit.add(type='ffd')
    entry_twist, entry_ffd = obj.deformkit.entries
    frame_empty = entry_twist.frame
    frame_empty.location, frame_empty.scale = (0.0, 0.0, 0.0), (1.0, 1.0, 1.0)
    z_up(frame_empty)
    for frame, angle in ((1, ANGLE[0]), (FRAMES, ANGLE[1])):
        # The module's documented SimpleDeform mapping: bounds at the limits, angles there.
        mapped = dk.blender_simple_deform_params("TWIST", points, angle=angle, deform_axis="Z")
        assert np.allclose(mapped["axis_dir"], (0, 0, 1)) and np.allclose(mapped["axis_origin"], 0)
        entry_twist.low_bound, entry_twist.high_bound = mapped["z_samples"]
        entry_twist.start_value, entry_twist.end_value = mapped["value_samples"]
        entry_twist.keyframe_insert("start_value", frame=frame)
        entry_twist.keyframe_insert("end_value", frame=frame)
    linear(obj)
    added = entry_ffd.lattice
    entry_ffd.lattice = lattice
    bpy.data.objects.remove(added)
    assert entry_ffd.basis == "LATTICE"
    return scenes


def time_scenes(scenes):
    timings = {kind: [] for kind in scenes}
    frame = 2
    for _ in range(rounds):
        for kind, (scene, _obj) in scenes.items():
            t0 = time.perf_counter()
            scene.frame_set(frame)
            timings[kind].append((time.perf_counter() - t0) * 1e3)
        frame = frame + 1 if frame < FRAMES else 2
    return {kind: statistics.median(v) for kind, v in timings.items()}


def same_deformation(scenes):
    """Largest distance between the two deformed meshes at one frame, over the mesh's bounding-box diagonal."""
    frame = FRAMES // 2
    for scene, _obj in scenes.values():
        scene.frame_set(frame)
    scene, obj = scenes["blender"]
    evaluated = obj.evaluated_get(scene.view_layers[0].depsgraph).data
    theirs = np.empty(len(evaluated.vertices) * 3, np.float32)
    evaluated.vertices.foreach_get("co", theirs)
    _scene, ours_obj = scenes["deformkit"]
    assert ours_obj.deformkit.status == "", ours_obj.deformkit.status
    ours = np.empty(len(ours_obj.data.vertices) * 3, np.float32)
    ours_obj.data.vertices.foreach_get("co", ours)
    theirs, ours = theirs.reshape(-1, 3), ours.reshape(-1, 3)
    diagonal = float(np.linalg.norm(theirs.max(axis=0) - theirs.min(axis=0)))
    return float(np.abs(theirs - ours).max()) / diagonal


def report(name, scenes):
    for scene, _obj in scenes.values():
        scene.frame_set(1)  # bind, caches, first evaluation: outside the timing
    difference = same_deformation(scenes)
    check_floors(scenes)
    t = time_scenes(scenes)
    blender_net, ours_net = t["blender"] - t["plain"], t["deformkit"] - t["plain"]
    write_net, cache_net, nodes_net, key_net = (t[k] - t["plain"] for k in ("write", "cache", "nodes", "shapekey"))
    vertices = len(scenes["plain"][1].data.vertices)
    print(f"{name} ({vertices:,} vertices), median of {rounds} frame changes each:")
    print(f"  plain frame change              {t['plain']:8.2f} ms")
    print(f"  SimpleDeform + Lattice          {t['blender']:8.2f} ms   net {blender_net:8.2f} ms")
    print(f"  DeformKit twist + FFD           {t['deformkit']:8.2f} ms   net {ours_net:8.2f} ms")
    print(f"  a Python write of the mesh      {t['write']:8.2f} ms   net {write_net:8.2f} ms   "
          f"({write_net / blender_net:.2f}x Blender's: the floor of writing the mesh)")
    print(f"  a PC2 file + Mesh Cache         {t['cache']:8.2f} ms   net {cache_net:8.2f} ms   "
          f"({cache_net / blender_net:.2f}x)")
    print(f"  a helper mesh + Geometry Nodes  {t['nodes']:8.2f} ms   net {nodes_net:8.2f} ms   "
          f"({nodes_net / blender_net:.2f}x)")
    print(f"  a shape key                     {t['shapekey']:8.2f} ms   net {key_net:8.2f} ms   "
          f"({key_net / blender_net:.2f}x)")
    print(f"  DeformKit / Blender (net)       {ours_net / blender_net:8.2f}x   (goal <= 0.5x)")
    print(f"  same deformation: meshes differ by {difference:.1e} of the bounding-box diagonal")


print(f"# Blender {bpy.app.version_string}, {os.cpu_count()} cores, "
      f"OMP_WAIT_POLICY={os.environ.get('OMP_WAIT_POLICY', '(unset)')}")
if "--profile" in args:  # where the add-on's frame change goes (cProfile, the deformkit scene only)
    import cProfile
    import pstats
    scenes = build(spot_subdivided() if "--grid-only" not in args else grid())
    scene = scenes["deformkit"][0]
    scene.frame_set(1)
    profile = cProfile.Profile()
    profile.enable()
    for f in range(2, 2 + rounds):
        scene.frame_set(f)
    profile.disable()
    pstats.Stats(profile).sort_stats("cumulative").print_stats(25)
    sys.exit(0)
if "--grid-only" not in args:
    report("Spot subdivided twice", build(spot_subdivided()))
if "--mesh-only" not in args:
    report("grid", build(grid()))
shutil.rmtree(SCRATCH, ignore_errors=True)
