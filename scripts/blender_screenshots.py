"""The Blender add-on's pictures for docs/blender.md, taken in a real (virtual-display) Blender window:

    blender -b --factory-startup --python scripts/blender_screenshots.py -- BUILD/blender OUT_DIR
      (writes OUT_DIR/scene.blend, then reopens it in a window:)
    xvfb-run -a -s "-screen 0 1600x900x24" blender OUT_DIR/scene.blend --python \
        scripts/blender_screenshots.py -- BUILD/blender OUT_DIR

The first run builds the scene (a tube with a slide driven by Empties and a twist about an Empty, the end
Empty dragged) and saves it; the second opens it with a window (a file given on the command line skips
the splash screen), shows the Modifiers tab, and writes OUT_DIR/panel.png (the Properties editor) and
OUT_DIR/viewport.png (the whole window).
"""

import math
import os
import sys

import bpy

args = sys.argv[sys.argv.index("--") + 1:]
stage, out_dir = args[0], os.path.abspath(args[1])
sys.path.insert(0, stage)
import deformkit as addon  # noqa: E402

addon.register()


def build_scene():
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    # An open tube, radius 1, 4 long along Z: 64 sides, 41 rings.
    sides, rings = 64, 41
    points = [(math.cos(2 * math.pi * s / sides), math.sin(2 * math.pi * s / sides), 4.0 * r / (rings - 1))
              for r in range(rings) for s in range(sides)]
    faces = [(r * sides + s, r * sides + (s + 1) % sides, (r + 1) * sides + (s + 1) % sides,
              (r + 1) * sides + s) for r in range(rings - 1) for s in range(sides)]
    mesh = bpy.data.meshes.new("Tube")
    mesh.from_pydata(points, [], faces)
    tube = bpy.data.objects.new("Tube", mesh)
    bpy.context.scene.collection.objects.link(tube)
    bpy.context.view_layer.objects.active = tube
    tube.select_set(True)
    # Cylindrical UVs (u around, v along) and Blender's generated colour grid, to show the surface slide.
    layer = mesh.uv_layers.new(name="UVMap")
    for polygon in mesh.polygons:
        r, s = divmod(polygon.index, sides)
        for loop, (dr, ds) in zip(polygon.loop_indices, ((0, 0), (0, 1), (1, 1), (1, 0))):
            layer.data[loop].uv = ((s + ds) / sides * 4.0, (r + dr) / (rings - 1))
    grid = bpy.data.images.new("grid", 1024, 1024)
    grid.generated_type = 'COLOR_GRID'
    material = bpy.data.materials.new("grid")
    material.use_nodes = True
    texture = material.node_tree.nodes.new('ShaderNodeTexImage')
    texture.image = grid
    material.node_tree.links.new(texture.outputs["Color"],
                                 material.node_tree.nodes["Principled BSDF"].inputs["Base Color"])
    mesh.materials.append(material)
    bpy.context.scene.cursor.location = (0.7, -0.7, 2.2)
    slide = bpy.ops.deformkit.add(type='slide')
    assert slide == {'FINISHED'}
    entry = tube.deformkit.entries[-1]
    entry.radius = 1.0
    entry.end.location = entry.start.location + type(entry.start.location)((0.3, 0.3, 0.5))
    bpy.ops.deformkit.add(type='twist')
    twist = tube.deformkit.entries[-1]
    twist.start_value, twist.end_value = 0.0, 0.8
    tube.deformkit.active_index = 0
    bpy.context.view_layer.update()
    bpy.ops.wm.save_as_mainfile(filepath=os.path.join(out_dir, "scene.blend"))


def shoot():
    screen = bpy.context.window.screen
    for area in screen.areas:
        if area.type == 'PROPERTIES':
            area.spaces.active.context = 'MODIFIER'
        if area.type == 'VIEW_3D':
            space = area.spaces.active
            space.shading.type = 'SOLID'
            space.shading.color_type = 'TEXTURE'
            space.overlay.show_floor = True
            region = space.region_3d
            region.view_distance = 11.0
            region.view_location = (0.0, 0.0, 2.0)
            region.view_rotation = (0.78, 0.45, 0.2, 0.38)

    def take():
        for area in bpy.context.window.screen.areas:
            if area.type == 'PROPERTIES':
                with bpy.context.temp_override(area=area):
                    bpy.ops.screen.screenshot_area(filepath=os.path.join(out_dir, "panel.png"))
        bpy.ops.screen.screenshot(filepath=os.path.join(out_dir, "viewport.png"))
        bpy.ops.wm.quit_blender()
        return None

    bpy.app.timers.register(take, first_interval=2.0)


os.makedirs(out_dir, exist_ok=True)
if bpy.app.background:
    build_scene()
else:
    bpy.context.view_layer.objects.active = bpy.data.objects["Tube"]
    bpy.data.objects["Tube"].select_set(True)
    addon.evaluate.evaluate_safely(bpy.data.objects["Tube"])
    shoot()
