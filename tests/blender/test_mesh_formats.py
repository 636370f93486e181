"""Meshes in the formats artists export, read by DeformKit against the same mesh as OBJ, headless:

    blender -b --factory-startup --python-exit-code 1 --python test_mesh_formats.py -- ADDON_STAGE_DIR

The rigged Fox's rest mesh (tests/data/fox/rest.obj: 290 vertices, 576 triangles, 14 UV charts) is imported
into Blender and exported by Blender's own exporters as OBJ, glTF (GLB), FBX, PLY and Collada, each with the
axes and units that make its numbers the OBJ's (Y up; FBX without its unit scale). deformkit.read_mesh reads
each; every face must come back with the OBJ's corner positions and UVs (as multisets of faces: exporters
may order faces differently), and the vertex count each format's rule gives: glTF and PLY keep the file's
split vertices (one per distinct position, UV and normal), FBX and Collada are welded back to the OBJ's 290.
The skinned Fox (Fox.glb), its mesh and armature moved, turned and scaled and posed, exported as glTF, FBX
and Collada, reads as Blender's OBJ of its rest pose.
"""

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
FOX = os.path.join(os.environ.get("DEFORMKIT_TEST_DATA", os.path.join(os.path.dirname(__file__), "..", "data")),
                   "fox", "rest.obj")
# The reference is Blender's OBJ text (six decimals of its float32 values); the other files carry Blender's
# floats through their own axis conversions. At the Fox's size (|x| < 128, a float32 ulp of 7.6e-6) they are
# measured at most 2 ulps apart (glb 1.5e-5, dae 1.1e-5, fbx 3.8e-6, ply 9.5e-7): the tolerance is 4 ulps.
TOLERANCE = 4 * 2.0 ** -23 * 128
# The rigged Fox moved, turned and scaled by 1.5 (|x| < 256, an ulp of 1.5e-5) is posed through matrix
# products in another order than Blender's: measured at most 3.5 ulps (glb 5.3e-5, dae 4.6e-5, fbx 2.3e-5);
# the tolerance is 8 ulps. Leaving out Collada's bind shape matrix moves the mesh by 10.
RIGGED_TOLERANCE = 8 * 2.0 ** -23 * 256


def faces_of(mesh):
    """Each face as a tuple of (x, y, z, u, v) corners starting at its smallest corner, sorted: a multiset of
    faces that ignores face order and the corner a face starts at, keeping its winding."""
    points, uvs = mesh.points.astype(np.float64), mesh.uvs.astype(np.float64)
    faces, offset = [], 0
    for count in mesh.face_counts:
        corners = [tuple(points[mesh.face_indices[offset + k]]) + tuple(uvs[mesh.uv_indices[offset + k]])
                   for k in range(count)]
        offset += count
        start = corners.index(min(corners))
        faces.append(tuple(corners[start:] + corners[:start]))
    return np.array(sorted(faces))


def export_all(folder):
    for block in list(bpy.data.objects):
        bpy.data.objects.remove(block)
    bpy.ops.import_scene.obj(filepath=FOX)  # Blender's OBJ importer: Y up in the file, Z up in Blender
    fox = bpy.context.selected_objects[0]
    bpy.context.view_layer.objects.active = fox
    paths = {ext: os.path.join(folder, "fox." + ext) for ext in ("obj", "glb", "fbx", "ply", "dae")}
    bpy.ops.export_scene.obj(filepath=paths["obj"], use_selection=True, use_materials=False)
    bpy.ops.export_scene.gltf(filepath=paths["glb"], export_format="GLB", use_selection=True)
    bpy.ops.export_scene.fbx(filepath=paths["fbx"], use_selection=True, apply_scale_options="FBX_SCALE_UNITS")
    bpy.ops.export_mesh.ply(filepath=paths["ply"], use_selection=True, axis_forward="-Z", axis_up="Y")
    bpy.ops.wm.collada_export(filepath=paths["dae"], selected=True)
    return paths


def test_formats_read_as_the_obj(folder):
    paths = export_all(folder)
    reference = dk.read_mesh(paths["obj"])
    assert reference.num_vertices == 290 and reference.num_faces == 576
    want = faces_of(reference)
    for ext in ("glb", "fbx", "ply", "dae"):
        mesh = dk.read_mesh(paths[ext])
        got = faces_of(mesh)
        assert got.shape == want.shape, (ext, got.shape, want.shape)
        error = float(np.abs(got - want).max())
        assert error <= TOLERANCE, (ext, error)
        distinct = len(np.unique(mesh.points, axis=0))
        if ext in ("fbx", "dae"):
            assert mesh.num_vertices == 290, (ext, mesh.num_vertices)
        else:  # the file's own split vertices, each position kept as often as the file has it
            assert mesh.num_vertices > 290 and distinct == 290, (ext, mesh.num_vertices, distinct)
        print(f"{ext}: {mesh.num_vertices} vertices ({distinct} positions), {mesh.num_faces} faces, "
              f"corners within {error:g} of the OBJ's")
    # A file that is no mesh names the formats.
    bad = os.path.join(folder, "fox.txt")
    with open(bad, "w") as f:
        f.write("not a mesh\n")
    try:
        dk.read_mesh(bad)
        raise AssertionError("a .txt file read as a mesh")
    except dk.Error as e:
        assert ".obj, .gltf, .glb, .fbx, .ply, .dae" in str(e), str(e)


def test_rigged_formats_read_at_rest(folder):
    """A skinned character placed as riggers place one: the Fox (Fox.glb, its armature and skin) with the mesh
    moved and turned relative to its armature, and the armature moved, turned and scaled, posed by its Run
    clip. Collada, FBX and glTF exports read as Blender's OBJ of the rest pose (the armature at rest): Collada
    writes the mesh's placement relative to the armature as its bind shape matrix, under the armature's
    node."""
    for alias, kind in (("bool", bool), ("int", int), ("float", float), ("object", object), ("str", str)):
        if alias not in np.__dict__:  # Debian's Blender 3.4 glTF importer uses aliases numpy 1.24 removed
            setattr(np, alias, kind)
    for block in list(bpy.data.objects):
        bpy.data.objects.remove(block)
    bpy.ops.import_scene.gltf(filepath=os.path.join(os.path.dirname(FOX), "Fox.glb"))
    scene = bpy.context.scene
    mesh = next(o for o in scene.objects if o.type == "MESH")
    armature = next(o for o in scene.objects if o.type == "ARMATURE")
    assert mesh.parent == armature
    mesh.rotation_mode = armature.rotation_mode = "XYZ"
    mesh.location.x += 10
    mesh.rotation_euler.z += 0.3
    armature.location.y += 5
    armature.rotation_euler.x += 0.2
    armature.rotation_euler.z += 0.5
    armature.scale = (1.5, 1.5, 1.5)
    run = [a for a in bpy.data.actions if a.name.startswith("Run")]
    assert run, [a.name for a in bpy.data.actions]
    armature.animation_data.action = run[-1]
    scene.frame_set(8)
    bpy.ops.object.select_all(action="DESELECT")
    mesh.select_set(True)
    armature.select_set(True)
    bpy.context.view_layer.objects.active = mesh
    paths = {ext: os.path.join(folder, "rigged." + ext) for ext in ("obj", "glb", "fbx", "dae")}
    bpy.ops.export_scene.gltf(filepath=paths["glb"], export_format="GLB", use_selection=True)
    bpy.ops.export_scene.fbx(filepath=paths["fbx"], use_selection=True, apply_scale_options="FBX_SCALE_UNITS")
    bpy.ops.wm.collada_export(filepath=paths["dae"], selected=True)
    armature.data.pose_position = "REST"
    scene.frame_set(8)
    armature.select_set(False)
    bpy.ops.export_scene.obj(filepath=paths["obj"], use_selection=True, use_materials=False)
    want = faces_of(dk.read_mesh(paths["obj"]))
    for ext in ("glb", "fbx", "dae"):
        got = faces_of(dk.read_mesh(paths[ext]))
        assert got.shape == want.shape, (ext, got.shape, want.shape)
        error = float(np.abs(got - want).max())
        print(f"rigged {ext}: corners within {error:g} of the rest OBJ's")
        assert np.abs(want[:, :, :3]).max() < 256
        assert error <= RIGGED_TOLERANCE, (ext, error)


def main():
    addon_utils.enable("io_scene_gltf2")
    addon_utils.enable("io_scene_fbx")
    blender_tests.run((test_formats_read_as_the_obj, test_rigged_formats_read_at_rest))


main()
