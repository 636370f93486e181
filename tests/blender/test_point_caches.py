"""Point caches between Blender and DeformKit, headless:

    blender -b --factory-startup --python-exit-code 1 --python test_point_caches.py -- ADDON_STAGE_DIR

Suzanne is rigged in Blender (a two-bone armature, automatic weights) and animated by keyframed bones over
frames 1-6. Blender's own exporters write the shot as PC2 (io_export_pc2) and MDD (io_shape_mdd); DeformKit
reads each frame and must find the positions Blender evaluates, bit for bit. Then DeformKit writes caches of
another motion and Blender's Mesh Cache modifier, on a copy of the mesh, must show those positions, bit for
bit. Blender's Mesh Cache modifier numbers a cache's samples from its own Frame Start (the PC2 header's start
frame is not used in its Frame mode), so it is set to the caches' first frame, 1. Last, a rigged tube's PC2
against its own OBJ and FBX exports: the OBJ keeps Blender's vertex order and reads the cache, the FBX is
welded and renumbered on reading, as many vertices in another order, and the cache is refused.
"""

import json
import os
import sys

import addon_utils
import bpy
import numpy as np

STAGE = sys.argv[sys.argv.index("--") + 1]
sys.path.insert(0, STAGE)
import deformkit as addon  # noqa: E402  (the add-on package; its compiled module is addon.core.dk)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import blender_tests  # noqa: E402

dk = addon.core.dk
FRAMES = range(1, 7)


def positions(obj):
    """World positions of the evaluated mesh at the current frame, float32 (the object sits at the origin, so
    world and object coordinates are the same numbers)."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    out = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("co", out)
    evaluated.to_mesh_clear()
    return out.reshape(-1, 3)


def add_suzanne():
    bpy.ops.mesh.primitive_monkey_add(location=(0.0, 0.0, 0.0))


def add_tube():
    """A 12-sided cylinder (height 2 about the origin) cut into 16 rings by subdivision: no two vertices in
    one place, so a welded reading keeps Blender's vertex count."""
    bpy.ops.mesh.primitive_cylinder_add(vertices=12, depth=2.0, radius=0.4, location=(0.0, 0.0, 0.0))
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.ops.mesh.select_all(action="SELECT")
    bpy.ops.mesh.subdivide(number_cuts=3)
    bpy.ops.object.mode_set(mode="OBJECT")


def rigged_suzanne(add_mesh=add_suzanne):
    """The mesh `add_mesh` adds at the origin, rigged by a two-bone armature (automatic weights) whose tip
    bone turns over frames 1-6 (frame 1: the rest pose)."""
    for block in list(bpy.data.objects):
        bpy.data.objects.remove(block)
    add_mesh()
    suzanne = bpy.context.object
    bpy.ops.object.armature_add(location=(0.0, 0.0, -1.0))
    rig = bpy.context.object
    bpy.ops.object.mode_set(mode="EDIT")
    root = rig.data.edit_bones[0]
    root.head, root.tail = (0.0, 0.0, -1.0), (0.0, 0.0, 0.0)
    tip = rig.data.edit_bones.new("tip")
    tip.head, tip.tail, tip.parent = (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), root
    bpy.ops.object.mode_set(mode="OBJECT")
    bpy.ops.object.select_all(action="DESELECT")
    suzanne.select_set(True)
    rig.select_set(True)
    bpy.context.view_layer.objects.active = rig
    bpy.ops.object.parent_set(type="ARMATURE_AUTO")
    bone = rig.pose.bones["tip"]
    bone.rotation_mode = "XYZ"
    for frame in FRAMES:
        bone.rotation_euler = (0.25 * (frame - 1), 0.0, 0.1 * (frame - 1))
        bone.keyframe_insert("rotation_euler", frame=frame)
    bpy.context.view_layer.objects.active = suzanne
    bpy.ops.object.select_all(action="DESELECT")
    suzanne.select_set(True)
    return suzanne


def test_blender_exports_read_by_deformkit(folder):
    suzanne = rigged_suzanne()
    scene = bpy.context.scene
    pc2, mdd = os.path.join(folder, "suzanne.pc2"), os.path.join(folder, "suzanne.mdd")
    result = bpy.ops.export_shape.pc2(filepath=pc2, range_start=1, range_end=6, sampling="1", world_space=True,
                                      rot_x90=False, apply_modifiers=True)
    assert result == {"FINISHED"}, result
    result = bpy.ops.export_shape.mdd(filepath=mdd, fps=24.0, frame_start=1, frame_end=6, use_rest_frame=False)
    assert result == {"FINISHED"}, result
    expected = {}
    for frame in FRAMES:
        scene.frame_set(frame)
        expected[frame] = positions(suzanne)
    moved = max(float(np.abs(expected[f] - expected[1]).max()) for f in FRAMES)
    assert moved > 0.3, f"the rig hardly moves Suzanne ({moved})"
    caches = (dk.PointCache(pc2), dk.PointCache(mdd))
    assert caches[0].frames == caches[1].frames == list(FRAMES)  # PC2's start frame; MDD counted from 1
    assert np.allclose(caches[1].times, np.arange(6) / 24.0)
    for cache in caches:
        assert cache.vertex_count == len(suzanne.data.vertices)
        for frame in FRAMES:
            got = cache.read(frame)
            assert np.array_equal(got, expected[frame]), (cache.format, frame, np.abs(got - expected[frame]).max())
    print(f"Blender's PC2 and MDD exports of a rigged Suzanne ({caches[0].vertex_count} vertices, frames 1-6, "
          f"moving up to {moved:.3f}) read by DeformKit: the evaluated positions, bit for bit")


def test_deformkit_caches_shown_by_blender(folder):
    suzanne = rigged_suzanne()
    base = np.empty(len(suzanne.data.vertices) * 3, np.float32)
    suzanne.data.vertices.foreach_get("co", base)
    base = base.reshape(-1, 3)
    # A motion Blender did not make: a wave along x growing with the frame.
    motion = np.stack([base + np.stack([np.zeros(len(base)), 0.1 * f * np.sin(3.0 * base[:, 0]),
                                        0.05 * f * np.cos(2.0 * base[:, 1])], -1).astype(np.float32)
                       for f in FRAMES]).astype(np.float32)
    for extension in ("pc2", "mdd"):
        path = os.path.join(folder, "deformkit." + extension)
        dk.write_point_cache(path, motion, first_frame=1, fps=24.0)
        copy = bpy.data.objects.new("cached_" + extension, suzanne.data.copy())
        bpy.context.scene.collection.objects.link(copy)
        cache = copy.modifiers.new("cache", "MESH_CACHE")
        cache.cache_format = extension.upper()
        cache.filepath = path
        cache.frame_start = 1.0
        for frame in FRAMES:
            bpy.context.scene.frame_set(frame)
            shown = positions(copy)
            assert np.array_equal(shown, motion[frame - 1]), (extension, frame,
                                                              np.abs(shown - motion[frame - 1]).max())
    print("DeformKit's PC2 and MDD shown by Blender's Mesh Cache modifier: the written positions, bit for bit")


def test_a_cache_against_a_renumbered_rest_mesh_is_refused(folder):
    tube = rigged_suzanne(add_tube)
    paths = {ext: os.path.join(folder, "tube." + ext) for ext in ("obj", "fbx", "pc2")}
    bpy.context.scene.frame_set(1)  # the rest pose: the rest meshes below
    bpy.ops.export_scene.obj(filepath=paths["obj"], use_selection=True, use_materials=False,
                             use_triangles=False)
    bpy.ops.export_scene.fbx(filepath=paths["fbx"], use_selection=True, apply_scale_options="FBX_SCALE_UNITS")
    result = bpy.ops.export_shape.pc2(filepath=paths["pc2"], range_start=1, range_end=6, sampling="1",
                                      world_space=True, rot_x90=False, apply_modifiers=True)
    assert result == {"FINISHED"}, result
    count = len(tube.data.vertices)
    obj, fbx = dk.read_mesh(paths["obj"]), dk.read_mesh(paths["fbx"])
    assert obj.num_vertices == fbx.num_vertices == count, (obj.num_vertices, fbx.num_vertices, count)
    moved = int(np.count_nonzero(np.abs(fbx.points - obj.points).max(axis=1) > 1e-4))
    assert moved > count // 2, f"the FBX reading keeps most of Blender's order ({moved} of {count} moved)"
    cache = dk.PointCache(paths["pc2"])
    for rest in ("obj", "fbx"):
        scene = os.path.join(folder, "tube_" + rest + ".json")
        with open(scene, "w") as out:
            json.dump({"deformkit_scene": 1, "frames": [1, 6], "objects": [
                {"name": "tube", "mesh": paths[rest], "deformed": paths["pc2"], "stack": []}]}, out)
        evaluator = dk.SceneEvaluator(scene)
        for frame in FRAMES:
            if rest == "obj":
                assert np.array_equal(evaluator.evaluate(0, frame), cache.read(frame)), frame
                continue
            try:
                evaluator.evaluate(0, frame)
            except dk.InvalidInput as error:
                message = str(error)
            else:
                raise AssertionError(f"frame {frame} of the cache read against the FBX's vertex order")
            assert f"tube.pc2: frame {frame}: stretches" in message, message
            assert "not in the rest mesh's order" in message and "tube.fbx" in message, message
    print(f"A rigged tube's PC2 ({count} vertices, frames 1-6) read against Blender's OBJ of the tube, refused "
          f"against its FBX ({moved} of its vertices renumbered): {message}")


def main():
    addon_utils.enable("io_export_pc2")
    addon_utils.enable("io_shape_mdd")
    blender_tests.run((test_blender_exports_read_by_deformkit, test_deformkit_caches_shown_by_blender,
                       test_a_cache_against_a_renumbered_rest_mesh_is_refused))


main()
