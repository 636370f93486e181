"""Makes a rigged shot: a skinned character animated by its armature's bones in Blender, exported frame by frame
as OBJ by Blender's exporter (what a rigger hands over). Run from the repository's root:

    blender -b --factory-startup --python scripts/make_rigged_shot.py -- \\
        --input CHARACTER.glb --out DIR [--frames 24] [--action NAME | --pose-keys BONE:AXIS:DEGREES ...]
    blender -b --factory-startup --python scripts/make_rigged_shot.py -- \\
        --input tests/data/spot/spot_quadrangulated.obj --auto-rig --out DIR [--frames 24]

A glTF/GLB is imported with Blender's glTF importer; its skinned mesh (the mesh with an Armature modifier) and
that armature are used. Vertices the file split where UVs or normals break are merged by position before anything
is animated (Merge by Distance, closer than --merge-distance times the bounding box's diagonal, 1e-6; at an
absolute 1e-6 Blender's merge leaves some copies with identical positions apart), so the shot has one vertex per
position and the file's UVs per corner. The bones are driven by:
- the character's own animation clip (--action NAME, or the clip the importer assigned): the N frames sample the
  clip evenly, first and last key included (frame i at start + (end - start) * (i - 1) / (N - 1));
- or keyed bone rotations (--pose-keys BONE:AXIS:DEGREES ..., AXIS in the bone's own X, Y or Z): each rotation
  goes linearly from 0 at frame 1 to DEGREES at frame N, the other bones stay at their rest (bind) pose;
- with --auto-rig (an OBJ such as Spot): an armature is built from the mesh's bounding box (a spine of three bones
  along its longest horizontal axis, then a neck and a head bone towards the end that rises highest), the mesh is
  parented to it with automatic weights, and the spine bends sideways by 60 degrees while the head turns by 60
  degrees (unless --pose-keys says otherwise).

Writes into DIR: rest.obj (the armature in its rest position), anim.0001.obj .. anim.NNNN.obj (the evaluated
mesh, same vertices in the same order every frame, UVs per corner, no normals or materials) and, if the file
embeds textures, texture.png (texture_2.png, ...; a PNG as it is, another format converted). Checks that every OBJ has the same vertex and face counts."""
import argparse
import math
import os
import sys

import numpy as np

# Debian's Blender 3.4 glTF importer still uses numpy aliases that numpy 1.24 removed.
for _alias, _type in (("bool", bool), ("int", int), ("float", float), ("complex", complex),
                      ("object", object), ("str", str)):
    if _alias not in np.__dict__:
        setattr(np, _alias, _type)

import addon_utils  # noqa: E402
import bmesh  # noqa: E402
import bpy  # noqa: E402

parser = argparse.ArgumentParser(prog="make_rigged_shot.py")
parser.add_argument("--input", required=True, help="a rigged .glb/.gltf, or an .obj with --auto-rig")
parser.add_argument("--out", required=True, help="folder for rest.obj, anim.NNNN.obj and texture.png")
parser.add_argument("--frames", type=int, default=24)
parser.add_argument("--action", help="the animation clip to play (default: the one the importer assigned)")
parser.add_argument("--pose-keys", nargs="+", metavar="BONE:AXIS:DEGREES",
                    help="key these bone rotations instead of playing a clip")
parser.add_argument("--auto-rig", action="store_true", help="build an armature for a mesh without one")
parser.add_argument("--merge-distance", type=float, default=1e-6,
                    help="merge vertices closer than this fraction of the bounding box's diagonal")
args = parser.parse_args(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else [])
if args.frames < 2:
    parser.error("--frames must be at least 2")
os.makedirs(args.out, exist_ok=True)
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene


def import_character(path):
    """Returns (mesh object, armature object or None)."""
    if path.lower().endswith((".glb", ".gltf")):
        addon_utils.enable("io_scene_gltf2")
        bpy.ops.import_scene.gltf(filepath=path)
    else:
        bpy.ops.wm.obj_import(filepath=path, forward_axis="NEGATIVE_Z", up_axis="Y")
    skinned = [o for o in scene.objects if o.type == "MESH"
               and any(m.type == "ARMATURE" and m.object for m in o.modifiers)]
    meshes = skinned or [o for o in scene.objects if o.type == "MESH"]
    if not meshes:
        sys.exit("no mesh in " + path)
    mesh = max(meshes, key=lambda o: len(o.data.vertices))
    if len(meshes) > 1:
        print("several meshes; using the largest,", mesh.name)
    armature = next((m.object for m in mesh.modifiers if m.type == "ARMATURE" and m.object), None)
    return mesh, armature


def merge_by_distance(mesh_object, fraction):
    mesh = mesh_object.data
    before = len(mesh.vertices)
    points = np.empty(3 * before, np.float32)
    mesh.vertices.foreach_get("co", points)
    points = points.reshape(-1, 3)
    distance = fraction * float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))
    bm = bmesh.new()
    bm.from_mesh(mesh)
    bmesh.ops.remove_doubles(bm, verts=bm.verts, dist=distance)
    bm.to_mesh(mesh)
    bm.free()
    mesh.update()
    print("merge by distance %g: %d -> %d vertices (%d distinct positions before)" % (
        distance, before, len(mesh.vertices), len(np.unique(points, axis=0))))


def report_uvs(mesh_object):
    layer = mesh_object.data.uv_layers.active
    if layer is None:
        sys.exit("the mesh has no UVs")
    uv = np.empty(2 * len(layer.data), np.float32)
    layer.data.foreach_get("uv", uv)
    uv = uv.reshape(-1, 2)
    lo, hi = uv.min(axis=0), uv.max(axis=0)
    print("UVs in [%.4f, %.4f] x [%.4f, %.4f]" % (lo[0], hi[0], lo[1], hi[1]))
    if (lo < 0).any() or (hi > 1).any():
        print("WARNING: UVs outside [0, 1] (not all in tile 1001); left as they are")


def slice_centre(points, along, up, side, t0, t1):
    """Centre (along, up) of the vertices in [t0, t1] along the long axis and near the mid plane."""
    width = points[:, side].max() - points[:, side].min()
    middle = 0.5 * (points[:, side].max() + points[:, side].min())
    for band in (0.05, 0.1, 0.2, 0.5):
        chosen = points[(points[:, along] >= t0) & (points[:, along] <= t1)
                        & (np.abs(points[:, side] - middle) <= band * width)]
        if len(chosen):
            return 0.5 * (t0 + t1), 0.5 * (chosen[:, up].min() + chosen[:, up].max()), middle
    return 0.5 * (t0 + t1), float(points[:, up].mean()), middle


def auto_rig(mesh_object):
    """An armature of spine_1..spine_3, neck and head along the mesh's longest horizontal axis, the head at the
    end that rises highest; the mesh parented with automatic weights. Returns the armature object and the keys."""
    count = len(mesh_object.data.vertices)
    points = np.empty(3 * count, np.float32)
    mesh_object.data.vertices.foreach_get("co", points)
    points = points.reshape(-1, 3) @ np.array(mesh_object.matrix_world.to_3x3()).T \
        + np.array(mesh_object.matrix_world.translation)
    extent = points.max(axis=0) - points.min(axis=0)
    along = 0 if extent[0] >= extent[1] else 1
    side, up = 1 - along, 2
    lo, hi = points[:, along].min(), points[:, along].max()
    length = hi - lo
    end_rise = [points[points[:, along] <= lo + 0.15 * length, up].max(),
                points[points[:, along] >= hi - 0.15 * length, up].max()]
    sign = 1.0 if end_rise[1] >= end_rise[0] else -1.0  # the head's end
    fractions = [0.06, 0.26, 0.44, 0.62, 0.74, 0.98]    # spine_1..3 joints, neck, head, snout
    joints = []
    for fraction in fractions:
        t = lo + fraction * length if sign > 0 else hi - fraction * length
        half = 0.04 * length
        _, height, middle = slice_centre(points, along, up, side, t - half, t + half)
        joint = [0.0, 0.0, 0.0]
        joint[along], joint[up], joint[side] = t, height, middle
        joints.append(joint)
    names = ["spine_1", "spine_2", "spine_3", "neck", "head"]
    data = bpy.data.armatures.new("rig")
    armature = bpy.data.objects.new("rig", data)
    scene.collection.objects.link(armature)
    bpy.context.view_layer.objects.active = armature
    bpy.ops.object.mode_set(mode="EDIT")
    parent = None
    for name, head, tail in zip(names, joints[:-1], joints[1:]):
        bone = data.edit_bones.new(name)
        bone.head, bone.tail = head, tail
        bone.roll = 0.0
        if parent is not None:
            bone.parent, bone.use_connect = parent, True
        parent = bone
    bpy.ops.object.mode_set(mode="OBJECT")
    for name, head, tail in zip(names, joints[:-1], joints[1:]):
        print("bone %-8s head (%.3f %.3f %.3f) tail (%.3f %.3f %.3f)" % (name, *head, *tail))
    bpy.ops.object.select_all(action="DESELECT")
    mesh_object.select_set(True)
    armature.select_set(True)
    bpy.context.view_layer.objects.active = armature
    bpy.ops.object.parent_set(type="ARMATURE_AUTO")
    weighted = {g.group for v in mesh_object.data.vertices for g in v.groups if g.weight > 0}
    print("automatic weights: %d vertex groups with weights" % len(weighted))
    # Bend the spine sideways (about the bones' own Z, the vertical for a level bone with roll 0) by 60 degrees
    # and turn the head by 60 degrees more, both the same way.
    return armature, ["spine_2:Z:30", "spine_3:Z:30", "neck:Z:30", "head:Z:30"]


def key_rotations(armature, keys, frames):
    for bone in armature.pose.bones:  # every bone at its rest (bind) pose but the keyed rotations
        bone.location = (0.0, 0.0, 0.0)
        bone.rotation_quaternion = (1.0, 0.0, 0.0, 0.0)
        bone.rotation_euler = (0.0, 0.0, 0.0)
        bone.scale = (1.0, 1.0, 1.0)
    for key in keys:
        name, axis, degrees = key.split(":")
        bone = armature.pose.bones.get(name)
        if bone is None:
            sys.exit("no bone %r; bones: %s" % (name, ", ".join(b.name for b in armature.pose.bones)))
        bone.rotation_mode = "XYZ"
        index = "XYZ".index(axis.upper())
        for frame, angle in ((1, 0.0), (frames, math.radians(float(degrees)))):
            bone.rotation_euler[index] = angle
            bone.keyframe_insert("rotation_euler", index=index, frame=frame)
    for curve in armature.animation_data.action.fcurves:
        for point in curve.keyframe_points:
            point.interpolation = "LINEAR"
    return [float(f) for f in range(1, frames + 1)]


def play_clip(armature, name, frames):
    data = armature.animation_data
    if name:
        wanted = ([a for a in bpy.data.actions if a.name == name]  # the importer names them CLIP_OBJECT
                  or [a for a in bpy.data.actions if a.name.startswith(name + "_")])
        if not wanted:
            sys.exit("no action %r; actions: %s" % (name, ", ".join(a.name for a in bpy.data.actions)))
        data.action = wanted[0]
    for track in data.nla_tracks:  # the importer's other clips, one NLA track each
        track.mute = True
    start, end = data.action.frame_range
    print("clip %s: frames %g-%g, sampled at %d frames" % (data.action.name, start, end, frames))
    return [start + (end - start) * i / (frames - 1) for i in range(frames)]


def save_textures(mesh_object):
    images = []
    for slot in mesh_object.material_slots:
        if slot.material and slot.material.node_tree:
            images += [n.image for n in slot.material.node_tree.nodes
                       if n.type == "TEX_IMAGE" and n.image and n.image not in images]
    for index, image in enumerate(images):
        path = os.path.join(args.out, "texture.png" if index == 0 else "texture_%d.png" % (index + 1))
        if image.packed_file and image.packed_file.data[:8] == b"\x89PNG\r\n\x1a\n":
            with open(path, "wb") as f:
                f.write(image.packed_file.data)
        else:  # another format (JPEG, say): its 8-bit pixels into a PNG, no colour transform
            pixels = np.empty(4 * image.size[0] * image.size[1], np.float32)
            image.pixels.foreach_get(pixels)
            copy = bpy.data.images.new("png", image.size[0], image.size[1], alpha=True)
            copy.pixels.foreach_set(pixels)
            copy.filepath_raw = path
            copy.file_format = "PNG"
            copy.save()
        print("texture", image.name, tuple(image.size), "->", path)


def export(mesh_object, path):
    bpy.ops.object.select_all(action="DESELECT")
    mesh_object.select_set(True)
    bpy.ops.wm.obj_export(filepath=path, export_selected_objects=True, apply_modifiers=True,
                          export_uv=True, export_normals=False, export_materials=False,
                          export_triangulated_mesh=False, forward_axis="NEGATIVE_Z", up_axis="Y")
    with open(path) as f:
        lines = f.read().splitlines()
    return sum(line.startswith("v ") for line in lines), sum(line.startswith("f ") for line in lines)


mesh_object, armature = import_character(os.path.abspath(args.input))
merge_by_distance(mesh_object, args.merge_distance)
report_uvs(mesh_object)
keys = args.pose_keys
if args.auto_rig:
    if armature is not None:
        sys.exit("--auto-rig: the mesh already has an armature")
    armature, default_keys = auto_rig(mesh_object)
    keys = keys or default_keys
if armature is None:
    sys.exit("no armature deforms the mesh (use --auto-rig)")
if keys:
    if armature.animation_data:
        armature.animation_data.action = None
        for track in armature.animation_data.nla_tracks:
            track.mute = True
    times = key_rotations(armature, keys, args.frames)
elif armature.animation_data and (args.action or armature.animation_data.action):
    times = play_clip(armature, args.action, args.frames)
else:
    sys.exit("the armature has no animation clip; give --pose-keys")
print("mesh %s: %d vertices, %d faces; armature %s: %d bones" % (
    mesh_object.name, len(mesh_object.data.vertices), len(mesh_object.data.polygons), armature.name,
    len(armature.data.bones)))
save_textures(mesh_object)

armature.data.pose_position = "REST"
scene.frame_set(1)
counts = {"rest.obj": export(mesh_object, os.path.join(args.out, "rest.obj"))}
armature.data.pose_position = "POSE"
turned = {}
for number, time in enumerate(times, 1):
    scene.frame_set(int(math.floor(time)), subframe=time - math.floor(time))
    for bone in armature.pose.bones:
        turned[bone.name] = max(turned.get(bone.name, 0.0),
                                math.degrees(bone.matrix_basis.to_quaternion().angle))
    name = "anim.%04d.obj" % number
    counts[name] = export(mesh_object, os.path.join(args.out, name))
assert len(set(counts.values())) == 1, counts
print("bones turned (most degrees over the shot):",
      ", ".join("%s %.0f" % (n, a) for n, a in turned.items() if a > 1.0))
print("wrote %s: rest.obj and %d frames, %d vertices and %d faces each" % (
    args.out, len(times), *counts["rest.obj"]))
