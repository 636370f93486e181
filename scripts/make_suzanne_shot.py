"""Makes tests/data/suzanne: Blender's Suzanne with Blender's own UVs, subdivided once, bent and twisted by
keyframed SimpleDeform modifiers, exported frame by frame as OBJ by Blender's exporter (the animation a DCC
hands over). Run from the repository's root:

    blender -b --factory-startup --python scripts/make_suzanne_shot.py -- tests/data/suzanne

Writes suzanne.0001.obj .. suzanne.0006.obj; frame 1 (both angles 0) is the rest pose, the same bytes as the
mesh exported without its modifiers."""
import os
import sys

import bpy

out = sys.argv[sys.argv.index("--") + 1] if "--" in sys.argv else "tests/data/suzanne"
os.makedirs(out, exist_ok=True)
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.mesh.primitive_monkey_add(size=2.0, calc_uvs=True)
suzanne = bpy.context.active_object
suzanne.name = "suzanne"
subdivision = suzanne.modifiers.new("subdivide", "SUBSURF")
subdivision.levels = 1
subdivision.uv_smooth = "PRESERVE_BOUNDARIES"
bpy.ops.object.modifier_apply(modifier=subdivision.name)

scene = bpy.context.scene
scene.frame_start, scene.frame_end = 1, 6
bend = suzanne.modifiers.new("bend", "SIMPLE_DEFORM")
bend.deform_method = "BEND"
bend.deform_axis = "Z"
twist = suzanne.modifiers.new("twist", "SIMPLE_DEFORM")
twist.deform_method = "TWIST"
twist.deform_axis = "Y"
for frame, (bent, twisted) in {1: (0.0, 0.0), 6: (1.0, 0.8)}.items():
    bend.angle, twist.angle = bent, twisted
    bend.keyframe_insert("angle", frame=frame)
    twist.keyframe_insert("angle", frame=frame)
for curve in suzanne.animation_data.action.fcurves:
    for key in curve.keyframe_points:
        key.interpolation = "LINEAR"


def export(path):
    bpy.ops.wm.obj_export(filepath=path, export_selected_objects=True, apply_modifiers=True,
                          export_uv=True, export_normals=False, export_materials=False,
                          export_triangulated_mesh=False, forward_axis="NEGATIVE_Z", up_axis="Y")


suzanne.select_set(True)
for frame in range(1, 7):
    scene.frame_set(frame)
    export(os.path.join(out, "suzanne.%04d.obj" % frame))
print("wrote", out)
