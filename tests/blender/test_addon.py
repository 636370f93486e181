"""The DeformKit add-on in real Blender, headless:

    blender -b --factory-startup --python-exit-code 1 --python test_addon.py -- ADDON_STAGE_DIR

Each test builds a scene, drives the add-on as a user would (operators, moving Empties and lattice points,
changing frames) and compares the mesh's vertex positions with the same deformation computed through the
`deformkit` Python module directly, from values the test sets itself.
"""

import json
import os
import pathlib
import re
import shutil
import sys
import tempfile
import traceback
import zipfile

import bpy
import mathutils
import numpy as np

STAGE = sys.argv[sys.argv.index("--") + 1]
sys.path.insert(0, STAGE)
import deformkit as addon  # noqa: E402  (the add-on package; its compiled module is addon.core.dk)

addon.register()
dk = addon.core.dk

N = 21  # grid vertices per side, [-1, 1]^2 in the z = 0 plane: vertex (i, j) is j * N + i
CENTRE = (N // 2) * N + N // 2


def fresh():
    for collection in (bpy.data.objects, bpy.data.meshes, bpy.data.lattices, bpy.data.curves, bpy.data.images,
                       bpy.data.materials):
        for block in list(collection):
            collection.remove(block)
    addon.evaluate.clear_cache()
    addon.uvwarp.clear_live()
    bpy.context.scene.frame_set(1)
    bpy.context.scene.cursor.location = (0.0, 0.0, 0.0)


def grid_object(name="grid"):
    xs = np.linspace(-1.0, 1.0, N, dtype=np.float32)
    points = [(x, y, 0.0) for y in xs for x in xs]
    faces = [(j * N + i, j * N + i + 1, (j + 1) * N + i + 1, (j + 1) * N + i)
             for j in range(N - 1) for i in range(N - 1)]
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(points, [], faces)
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    return obj


def positions(obj):
    out = np.empty(len(obj.data.vertices) * 3, np.float32)
    obj.data.vertices.foreach_get("co", out)
    return out.reshape(-1, 3)


def direct_stack(obj, rest):
    """A DeformerStack on the object's rest mesh, built through the module (not the add-on)."""
    counts = np.full(len(obj.data.polygons), 4, np.int32)
    indices = np.array([v for p in obj.data.polygons for v in p.vertices], np.int32)
    stack = dk.DeformerStack()
    stack.set_rest(dk.Mesh(rest, counts, indices))
    return stack


def set_all(stack, index, params):
    """Sets each (name, value) of params on entry `index` of a module DeformerStack."""
    for name, value in params:
        stack.set(index, name, value)


def z_up(empty):
    """Places an Empty at the origin, unscaled, its Y axis along world Z: the quaternion (1/2, 1/2, 1/2, 1/2)
    (120 degrees about (1, 1, 1)) whose matrix has exact entries, so the handle is exactly (0, 0, 1)."""
    empty.location = (0.0, 0.0, 0.0)
    empty.scale = (1.0, 1.0, 1.0)
    empty.rotation_mode = 'QUATERNION'
    empty.rotation_quaternion = (0.5, 0.5, 0.5, 0.5)


def add(kind):
    result = bpy.ops.deformkit.add(type=kind)
    assert result == {'FINISHED'}, result
    return bpy.context.object.deformkit.entries[-1]


def assert_same(actual, expected, what):
    # The add-on and the direct stack run the same kernels on the same float32 rest points with the same
    # parameter values (the test picks values exact in float32), so they agree to the last bit; 1e-6 leaves
    # room only for a different order of float operations.
    err = float(np.abs(actual - expected).max())
    assert err <= 1e-6, f"{what}: differs by {err}"


# ---- tests ------------------------------------------------------------------------------------------------

def test_the_addon_is_registered_and_zipped():
    assert hasattr(bpy.types, "DEFORMKIT_PT_stack")
    assert bpy.types.DEFORMKIT_PT_stack.bl_space_type == 'PROPERTIES'
    assert addon.bl_info["blender"] == (3, 4, 0)
    with zipfile.ZipFile(os.path.join(STAGE, "deformkit-blender.zip")) as z:
        names = set(z.namelist())
    assert "deformkit/__init__.py" in names
    assert any(n.startswith("deformkit/deformkit.") and n.endswith(".so") for n in names), names
    # The library's OpenImageIO module ships beside the compiled module and serves the add-on's image calls.
    assert "deformkit/deformkit_image_oiio.so" in names, names
    dk.write_image(os.path.join(tempfile.mkdtemp(), "probe.exr"), np.zeros((2, 2, 1), np.float32))
    with open("/proc/self/maps") as maps:
        loaded = {line.split()[-1] for line in maps if line.rstrip().endswith("deformkit_image_oiio.so")}
    assert loaded == {os.path.realpath(os.path.join(STAGE, "deformkit", "deformkit_image_oiio.so"))}, loaded


def test_slide_follows_the_end_empty():
    fresh()
    obj = grid_object()
    rest = positions(obj).copy()
    entry = add("slide")
    assert entry.vertex == CENTRE  # nearest the 3D cursor at the origin
    assert entry.start is not None and entry.end is not None
    assert np.array_equal(positions(obj), rest)  # start == end: no slide yet

    entry.end.location = (0.25, 0.125, 0.0)  # the animator drags the end Empty
    bpy.context.view_layer.update()  # the depsgraph handler sees the control edit
    stack = direct_stack(obj, rest)
    stack.add("slide", "s")
    set_all(stack, 0, [("vertex", CENTRE), ("radius", 0.5), ("geodesic", 1), ("falloff", 0),
                       ("displacement", (0.25, 0.125, 0.0))])
    expected = stack.evaluate(rest)
    assert np.abs(expected - rest).max() > 0.1
    assert_same(positions(obj), expected, "slide after dragging the end Empty")
    assert obj.deformkit.status == ""

    # The paper's painted-weights rule and the fold limit reach the stack: a drag of 0.9 the radius folds the
    # smooth falloff, and with the fold limit the result is the stack's with foldLimit 1.
    entry.weights_are_falloff = True
    entry.fold_limit = True
    entry.end.location = (0.45, 0.0, 0.0)
    bpy.context.view_layer.update()
    stack = direct_stack(obj, rest)
    stack.add("slide", "s")
    set_all(stack, 0, [("vertex", CENTRE), ("radius", 0.5), ("geodesic", 1), ("paintedWeights", 1),
                       ("foldLimit", 1), ("falloff", 0), ("displacement", (0.45, 0.0, 0.0))])
    assert_same(positions(obj), stack.evaluate(rest), "slide with the paper's rule and the fold limit")
    entry.weights_are_falloff = False
    entry.fold_limit = False
    entry.end.location = (0.25, 0.125, 0.0)
    bpy.context.view_layer.update()
    assert_same(positions(obj), expected, "slide back to the default rules")

    # A frame change that moves no control evaluates nothing: a marker written into the mesh stays.
    obj.data.vertices[0].co.z = 7.0
    bpy.context.scene.frame_set(2)
    assert obj.data.vertices[0].co.z == 7.0
    entry.end.location = (0.25, 0.25, 0.0)  # a control edit does evaluate
    bpy.context.view_layer.update()
    assert obj.data.vertices[0].co.z == 0.0


def test_frame_changes_follow_an_animated_empty():
    fresh()
    obj = grid_object()
    rest = positions(obj).copy()
    entry = add("slide")
    end = entry.end
    end.location = (0.0, 0.0, 0.0)
    end.keyframe_insert("location", frame=1)
    end.location = (0.5, 0.0, 0.0)
    end.keyframe_insert("location", frame=11)
    for curve in end.animation_data.action.fcurves:
        for key in curve.keyframe_points:
            key.interpolation = 'LINEAR'
    bpy.context.scene.frame_set(6)  # half way: (0.25, 0, 0)
    stack = direct_stack(obj, rest)
    stack.add("slide", "s")
    set_all(stack, 0, [("vertex", CENTRE), ("radius", 0.5), ("geodesic", 1), ("displacement", (0.25, 0, 0))])
    assert_same(positions(obj), stack.evaluate(rest), "slide at frame 6")
    bpy.context.scene.frame_set(1)
    assert_same(positions(obj), rest, "slide at frame 1 (no displacement)")


def test_twist_about_an_empty_and_vertex_group_weights():
    fresh()
    obj = grid_object()
    rest = positions(obj).copy()
    entry = add("twist")
    z_up(entry.frame)
    entry.start_value, entry.end_value = 0.0, 1.5
    bpy.context.view_layer.update()
    params = [("handleOrigin", (0, 0, 0)), ("handleY", (0, 0, 1)), ("startAngle", 0.0), ("endAngle", 1.5),
              ("lowBound", -1.0), ("highBound", 1.0)]
    # Handle Y is the world Z axis: the twist turns the grid about Z.
    stack = direct_stack(obj, rest)
    stack.add("twist", "t")
    set_all(stack, 0, params)
    assert_same(positions(obj), stack.evaluate(rest), "twist about the Empty's Y axis")

    group = obj.vertex_groups.new(name="paint")
    weights = np.where(rest[:, 0] > 0.0, 0.25, 1.0).astype(np.float32)
    for v, w in enumerate(weights):
        group.add([v], float(w), 'REPLACE')
    entry.vertex_group = "paint"
    stack.set_weights(0, weights)
    assert_same(positions(obj), stack.evaluate(rest), "twist with vertex-group weights")
    entry.envelope = 0.5
    stack.set_envelope(0, 0.5)
    assert_same(positions(obj), stack.evaluate(rest), "twist at envelope 0.5")
    # A renamed group is followed, as Blender's own modifiers follow it: the entry takes the new name and
    # keeps its weights (it said the group did not exist).
    group.name = "painted"
    bpy.context.view_layer.update()
    bpy.context.scene.frame_set(bpy.context.scene.frame_current)
    assert obj.deformkit.status == "", obj.deformkit.status
    assert entry.vertex_group == "painted", entry.vertex_group
    assert_same(positions(obj), stack.evaluate(rest), "twist after the group's rename")


def test_ffd_follows_lattice_points():
    fresh()
    obj = grid_object()
    rest = positions(obj).copy()
    entry = add("ffd")
    entry.basis = "0"  # Sederberg and Parry's, as the module's basis 0 below
    lattice = entry.lattice
    assert (lattice.data.points_u, lattice.data.points_v, lattice.data.points_w) == (3, 3, 3)
    # The new lattice fits the mesh's bounding box padded by 2% on each axis (it measured 2.04x before),
    # centred; the flat grid's zero height gets 2% of its longest side.
    bpy.context.view_layer.update()
    corners = np.array([lattice.matrix_world @ p.co for p in lattice.data.points])
    world = np.array([obj.matrix_world @ mathutils.Vector(p) for p in rest])
    size = world.max(axis=0) - world.min(axis=0)
    expected = np.maximum(1.02 * size, 0.02 * size.max())
    np.testing.assert_allclose(corners.max(axis=0) - corners.min(axis=0), expected, atol=1e-5)
    np.testing.assert_allclose(corners.mean(axis=0), 0.5 * (world.max(axis=0) + world.min(axis=0)), atol=1e-5)
    lattice.location, lattice.rotation_euler, lattice.scale = (0, 0, 0), (0, 0, 0), (2.5, 2.5, 1.0)
    # A new 3-point lattice spans [-1, 1] of its object space, so [-2.5, 2.5]^2 x [-1, 1] here. Lift the
    # centre point by 0.5 and push the (2, 2, 2) corner by 0.25 of the object's space along x (Blender lists
    # points u fastest).
    assert tuple(lattice.data.points[0].co) == (-1.0, -1.0, -1.0)
    centre = (1 * 3 + 1) * 3 + 1
    lattice.data.points[centre].co_deform = (0.0, 0.0, 0.5)
    corner = (2 * 3 + 2) * 3 + 2
    lattice.data.points[corner].co_deform = (1.25, 1.0, 1.0)
    lattice.data.update_tag()
    bpy.context.view_layer.update()
    # Reference lattice written in our order (k fastest): control (i, j, k) at origin + (i, j, k) / 2 * edge.
    origin, edge = np.array([-2.5, -2.5, -1.0]), np.array([5.0, 5.0, 2.0])
    points = np.array([origin + np.array([i, j, k]) / 2.0 * edge
                       for i in range(3) for j in range(3) for k in range(3)])
    points[(1 * 3 + 1) * 3 + 1] += (0.0, 0.0, 0.5)
    points[(2 * 3 + 2) * 3 + 2] += (0.25 * 2.5, 0.0, 0.0)
    stack = direct_stack(obj, rest)
    stack.add("ffd", "f")
    set_all(stack, 0, [("basis", 0), ("divisions", (2, 2, 2)), ("origin", origin),
                       ("axes", (5.0, 0, 0, 0, 5.0, 0, 0, 0, 2.0)), ("points", points.ravel())])
    expected = stack.evaluate(rest)
    assert np.abs(expected[:, 2]).max() > 0.05  # the grid's centre rises by 0.5 B(1/2)^3 = 1/16
    assert_same(positions(obj), expected, "FFD from the lattice")


def test_taper_and_bend_about_an_empty():
    fresh()
    obj = grid_object()
    rest = positions(obj).copy()
    taper = add("taper")
    z_up(taper.frame)
    taper.frame.location = (0.0, 0.0, -1.0)
    taper.start_value, taper.end_value = 1.0, 0.5
    bend = add("bend")
    bend.frame.location, bend.frame.rotation_euler, bend.frame.scale = (0, 0, 0), (0, 0, 0), (1, 1, 1)
    bend.curvature = 0.75
    bpy.context.view_layer.update()
    stack = direct_stack(obj, rest)
    stack.add("taper", "t")
    stack.add("bend", "b")
    set_all(stack, 0, [("handleOrigin", (0, 0, -1)), ("handleY", (0, 0, 1)), ("startScale", 1.0),
                       ("endScale", 0.5)])
    stack.set(1, "curvature", 0.75)  # handle: the world axes at the origin, the defaults
    expected = stack.evaluate(rest)
    assert np.abs(expected - rest).max() > 0.1
    assert_same(positions(obj), expected, "taper then bend")


def test_wire_curve_and_cage_mesh():
    fresh()
    obj = grid_object()
    rest = positions(obj).copy()
    wire = add("wires")
    wire.dropoff = 0.5
    wire.smooth = True
    rest_wire = np.array([(-1.0 + 0.5 * i, 0.0, 0.0) for i in range(5)])  # along x, the grid's first axis
    assert np.array_equal(np.array([p.co[:3] for p in wire.rest_curve.data.splines[0].points]), rest_wire)
    wire.curve.data.splines[0].points[2].co = (0.0, 0.0, 0.25, 1.0)  # lift the wire's middle point
    wire.curve.data.update_tag()
    bpy.context.view_layer.update()
    moved = rest_wire.copy()
    moved[2, 2] = 0.25
    stack = direct_stack(obj, rest)
    stack.add("wires", "w")
    set_all(stack, 0, [("smooth", 1), ("restCurve", rest_wire.ravel()), ("curveSizes", [0]),
                       ("dropoff", [0.5]), ("curve", moved.ravel())])
    expected = stack.evaluate(rest)
    assert np.abs(expected[:, 2]).max() > 0.1
    assert_same(positions(obj), expected, "wire")

    cage = add("meshwarp")
    corners = np.array([v.co[:] for v in cage.rest_cage.data.vertices])
    # A box around the grid padded by 0.05 of its size (2) on every axis.
    assert np.allclose(np.abs(corners), [1.1, 1.1, 0.1], atol=1e-6)
    top = int(np.flatnonzero((corners > 0).all(axis=1))[0])  # the (+x, +y, +z) corner
    cage.cage.data.vertices[top].co.z += 0.25
    cage.cage.data.update_tag()
    bpy.context.view_layer.update()
    deformed = corners.copy()
    deformed[top, 2] += np.float32(0.25)
    stack.add("meshwarp", "m")
    faces = [list(p.vertices) for p in cage.rest_cage.data.polygons]
    set_all(stack, 1, [("restCage", corners.ravel()), ("cageFaceCounts", [len(f) for f in faces]),
                       ("cageFaceIndices", [i for f in faces for i in f]), ("cage", deformed.ravel())])
    expected2 = stack.evaluate(rest)
    assert np.abs(expected2 - expected).max() > 0.01
    assert_same(positions(obj), expected2, "wire then cage")

    # The cage edited in Edit Mode, as the docs say to: its positions are in its edit mesh there (its mesh
    # read 0 vertices, and the stack refused the cage).
    import bmesh
    bpy.context.view_layer.objects.active = cage.cage
    bpy.ops.object.mode_set(mode='EDIT')
    edit = bmesh.from_edit_mesh(cage.cage.data)
    edit.verts.ensure_lookup_table()
    edit.verts[top].co.z += 0.25
    bmesh.update_edit_mesh(cage.cage.data)
    bpy.context.view_layer.update()
    deformed[top, 2] += np.float32(0.25)
    stack.set(1, "cage", deformed.ravel())
    assert addon.evaluate.evaluate_safely(obj, force=True) == ""
    assert_same(positions(obj), stack.evaluate(rest), "the cage edited in Edit Mode")
    bpy.ops.object.mode_set(mode='OBJECT')
    bpy.context.view_layer.objects.active = obj


def test_reorder_and_remove():
    fresh()
    obj = grid_object()
    rest = positions(obj).copy()
    twist = add("twist")
    z_up(twist.frame)
    twist.start_value, twist.end_value = 0.0, 1.0
    slide = add("slide")
    slide.end.location = (0.25, 0.0, 0.0)
    bpy.context.view_layer.update()
    assert [e.type for e in obj.deformkit.entries] == ["twist", "slide"]
    bpy.ops.deformkit.move(direction='UP')  # the slide (active) moves above the twist

    stack = direct_stack(obj, rest)
    stack.add("slide", "s")
    stack.add("twist", "t")
    set_all(stack, 0, [("vertex", CENTRE), ("radius", 0.5), ("geodesic", 1), ("displacement", (0.25, 0, 0))])
    set_all(stack, 1, [("handleY", (0, 0, 1)), ("startAngle", 0.0), ("endAngle", 1.0)])
    assert [e.type for e in obj.deformkit.entries] == ["slide", "twist"]
    assert_same(positions(obj), stack.evaluate(rest), "slide then twist")

    bpy.ops.deformkit.remove()
    bpy.ops.deformkit.remove()
    assert len(obj.deformkit.entries) == 0
    assert np.array_equal(positions(obj), rest)  # the rest shape is back


def test_errors_reach_the_user_as_reports():
    fresh()
    obj = grid_object()
    entry = add("bend")
    before = positions(obj).copy()
    entry.frame.scale = (1.0, 2.0, 1.0)  # X and Y not as long: no circular arc
    bpy.context.view_layer.update()
    assert "handle scale" in obj.deformkit.status, obj.deformkit.status
    assert np.array_equal(positions(obj), before)  # the last good result stays
    try:
        bpy.ops.deformkit.evaluate()
        raise AssertionError("evaluate did not report the error")
    except RuntimeError as e:
        assert "handle scale" in str(e), str(e)

    entry.frame = None
    assert "no handle Empty set" in obj.deformkit.status, obj.deformkit.status


def test_adding_from_edit_mode_keeps_the_rest_shape_and_the_selected_handle():
    # The rest shape is read from the mesh, which Edit Mode holds apart: added from there, it was all zeros
    # (the attribute had no elements) and a later twist collapsed the mesh onto the origin.
    fresh()
    obj = grid_object()
    before = positions(obj).copy()
    bpy.ops.object.mode_set(mode='EDIT')
    bpy.ops.mesh.select_all(action='DESELECT')
    bpy.ops.object.mode_set(mode='OBJECT')
    obj.data.vertices[CENTRE + 3].select = True
    bpy.ops.object.mode_set(mode='EDIT')
    entry = add("slide")
    assert obj.mode == 'EDIT'  # the user stays where they were
    bpy.ops.object.mode_set(mode='OBJECT')
    assert entry.vertex == CENTRE + 3, entry.vertex  # the selected vertex, not the one nearest the cursor
    assert_same(addon.evaluate.rest_points(obj), before, "rest shape captured in Edit Mode")
    twist = add("twist")
    twist.start_value = twist.end_value = 0.0
    bpy.ops.deformkit.evaluate()
    assert obj.deformkit.status == "", obj.deformkit.status
    assert_same(positions(obj), before, "mesh after an identity twist")


def test_a_frame_changed_in_edit_mode_is_evaluated_on_leaving_it():
    fresh()
    obj = grid_object()
    entry = add("twist")
    entry.start_value = 0.0
    key(entry, "end_value", {1: 0.0, 10: 1.0})
    scene = bpy.context.scene
    scene.frame_set(1)
    at_one = positions(obj).copy()
    scene.frame_set(10)
    at_ten = positions(obj).copy()
    assert np.abs(at_ten - at_one).max() > 0.1
    scene.frame_set(1)
    bpy.ops.object.mode_set(mode='EDIT')
    scene.frame_set(10)  # written now, Blender would drop it on leaving Edit Mode
    bpy.ops.object.mode_set(mode='OBJECT')
    bpy.context.view_layer.update()
    assert_same(positions(obj), at_ten, "frame 10 after leaving Edit Mode")


def test_objects_renamed_or_given_another_mesh_are_not_confused():
    # The stacks were cached by object name and checked by vertex count only.
    fresh()
    a, b = grid_object("A"), grid_object("B")
    for obj, x in ((a, 0.0), (b, 5.0)):
        obj.data.vertices.foreach_set("co", (positions(obj) + np.array([x, 0.0, 0.0], np.float32)).ravel())
        bpy.context.view_layer.objects.active = obj
        add("twist")
    expected = {obj.as_pointer(): positions(obj).copy() for obj in (a, b)}
    a.name, b.name = "tmp", "A"
    a.name = "B"
    bpy.context.scene.frame_set(2)
    for obj in (a, b):
        addon.evaluate.evaluate_object(obj, force=True)
        assert_same(positions(obj), expected[obj.as_pointer()], f"object {obj.name} after the names were swapped")
    # Another mesh of the same vertex count, without a rest shape: said, and nothing written into it.
    other = grid_object("other").data
    other.vertices.foreach_set("co", (positions(bpy.data.objects["other"]) * 2.0).ravel())
    b.data = other
    message = addon.evaluate.evaluate_safely(b, force=True)
    assert "no rest shape" in message, message
    assert float(positions(bpy.data.objects["other"])[:, 0].max()) == 2.0


def test_modelling_between_stacks_and_with_entries_off_becomes_the_rest_shape():
    # Removing the last entry forgot nothing: the next first entry restored the shape from before the
    # modelling done in between. Reset Rest put the old rest back before taking it, so the documented
    # workflow (entries off, edit, Reset Rest) lost the edit.
    fresh()
    obj = grid_object()
    add("twist")
    bpy.ops.deformkit.remove()
    assert not addon.evaluate.has_rest(obj)
    raised = positions(obj) + np.array([0.0, 0.0, 0.5], np.float32)
    obj.data.vertices.foreach_set("co", raised.ravel())
    obj.data.update()
    slide = add("slide")  # no drag: the mesh stays as modelled
    assert_same(addon.evaluate.rest_points(obj), raised, "rest shape taken by the new first entry")
    assert_same(positions(obj), raised, "mesh after adding a slide that does not move")

    # With an entry on, the mesh shows its deformation: Reset Rest refuses, naming the entry.
    slide.end.location = (0.2, 0.0, 0.5)
    bpy.context.view_layer.update()
    try:
        bpy.ops.deformkit.reset_rest()
        raise AssertionError("Reset Rest took a deformed shape")
    except RuntimeError as e:
        assert "disable every entry first" in str(e) and slide.name in str(e), str(e)
    # Entries off, the mesh edited: Reset Rest takes the edit, and the entries deform it when on again.
    slide.enabled = False
    bpy.context.view_layer.update()
    assert_same(positions(obj), raised, "mesh with the entry off")
    edited = raised + np.array([0.0, 0.0, 0.25], np.float32)
    obj.data.vertices.foreach_set("co", edited.ravel())
    obj.data.update()
    assert bpy.ops.deformkit.reset_rest() == {'FINISHED'}
    assert_same(addon.evaluate.rest_points(obj), edited, "rest shape after Reset Rest")
    slide.enabled = True
    bpy.context.view_layer.update()
    stack = direct_stack(obj, edited)
    stack.add("slide", "s")
    displacement = np.array(slide.end.location) - np.array(slide.start.location)
    set_all(stack, 0, [("vertex", slide.vertex), ("radius", slide.radius), ("geodesic", 1),
                       ("displacement", displacement)])
    assert_same(positions(obj), stack.evaluate(edited), "slide over the new rest shape")


def test_polygons_changed_under_a_stack_are_refused_until_reset_rest():
    # New vertices had rest position (0, 0, 0): a cube added in Edit Mode collapsed onto the origin, and
    # deleted vertices moved the slide's handle to another vertex, without a word.
    fresh()
    obj = grid_object()
    twist = add("twist")
    twist.start_value = twist.end_value = 0.0
    before = positions(obj).copy()
    bpy.ops.object.mode_set(mode='EDIT')
    bpy.ops.mesh.select_all(action='DESELECT')
    bpy.ops.mesh.primitive_cube_add(size=0.5, location=(2.0, 0.0, 0.0))
    bpy.ops.object.mode_set(mode='OBJECT')
    bpy.context.view_layer.update()
    message = obj.deformkit.status
    assert "the mesh's polygons changed since its rest shape was taken (441 vertices then, 449 vertices now)" in \
        message and "press Reset Rest" in message, message
    cube = positions(obj)[441:]
    assert float(cube[:, 0].min()) > 1.7, cube  # the new vertices where they were modelled
    assert_same(positions(obj)[:441], before, "the grid, untouched")
    twist.enabled = False
    assert bpy.ops.deformkit.reset_rest() == {'FINISHED'}
    twist.enabled = True
    assert addon.evaluate.evaluate_safely(obj, force=True) == ""
    assert float(positions(obj)[441:, 0].min()) > 1.7


def test_a_linked_duplicate_with_a_stack_is_refused():
    # Alt+D gives two objects one mesh: each stack wrote that mesh, the last one evaluated won.
    fresh()
    obj = grid_object()
    add("twist")
    twin = obj.copy()  # a linked duplicate: the same mesh
    bpy.context.scene.collection.objects.link(twin)
    twin.location = (3.0, 0.0, 0.0)
    message = addon.evaluate.evaluate_safely(obj, force=True)
    assert f"its mesh '{obj.data.name}' is also '{twin.name}''s" in message and "Make Single User" in message, \
        message


def test_a_linked_duplicate_never_takes_or_drops_the_other_stacks_rest():
    # Adding to the twin took the twisted shape as the rest of both meshes' stacks before refusing; removing
    # a copied stack's last entry put back and dropped the rest the original still used.
    fresh()
    obj = grid_object()
    model = positions(obj).copy()
    add("twist").end_value = 1.0
    bpy.context.view_layer.update()
    twin = bpy.data.objects.new("twin", obj.data)  # Alt+D: the same mesh, no stack
    bpy.context.scene.collection.objects.link(twin)
    bpy.context.view_layer.objects.active = twin
    try:
        bpy.ops.deformkit.add(type="slide")
        raise AssertionError("adding to a linked duplicate of a stacked mesh was not refused")
    except RuntimeError as refused:  # the operator's error report
        assert "its mesh 'grid' is also 'grid''s" in str(refused), refused
    assert len(twin.deformkit.entries) == 0
    assert_same(addon.evaluate.rest_points(obj), model, "the original's rest, after the refused add")
    copy = obj.copy()  # a linked duplicate of the stacked object: its entries come along
    bpy.context.scene.collection.objects.link(copy)
    bpy.context.view_layer.objects.active = copy
    assert bpy.ops.deformkit.remove() == {'FINISHED'}
    assert len(copy.deformkit.entries) == 0 and addon.evaluate.has_rest(obj)
    assert_same(addon.evaluate.rest_points(obj), model, "the original's rest, after the copy's last remove")


def test_remove_and_reset_rest_work_from_edit_mode():
    # Both read or wrote the mesh's rest attribute, which Blender keeps empty in Edit Mode: a traceback, the
    # entry gone and the twisted mesh left as the next stack's rest.
    fresh()
    obj = grid_object()
    model = positions(obj).copy()
    add("twist").end_value = 1.0
    bpy.context.view_layer.update()
    assert float(np.abs(positions(obj) - model).max()) > 0.1
    bpy.ops.object.mode_set(mode='EDIT')
    assert bpy.ops.deformkit.remove() == {'FINISHED'}
    assert obj.mode == 'EDIT'
    bpy.ops.object.mode_set(mode='OBJECT')
    assert len(obj.deformkit.entries) == 0 and not addon.evaluate.has_rest(obj)
    assert_same(positions(obj), model, "the mesh back to its rest shape")
    twist = add("twist")
    twist.enabled = False
    bpy.context.view_layer.update()
    bpy.ops.object.mode_set(mode='EDIT')
    assert bpy.ops.deformkit.reset_rest() == {'FINISHED'}
    assert obj.mode == 'EDIT'
    bpy.ops.object.mode_set(mode='OBJECT')
    assert_same(addon.evaluate.rest_points(obj), model, "the rest taken from Edit Mode")


def test_modelling_in_edit_mode_with_every_entry_off_survives_leaving_it():
    # The documented way to change a stacked mesh: entries off, model, Reset Rest. Leaving Edit Mode
    # evaluated the stack, which wrote the stored rest shape over the modelling before Reset Rest.
    import bmesh
    fresh()
    obj = grid_object()
    model = positions(obj).copy()
    twist = add("twist")
    twist.end_value = 1.0
    bpy.context.view_layer.update()
    twist.enabled = False
    bpy.context.view_layer.update()
    assert_same(positions(obj), model, "entries off: the rest shape")
    bpy.ops.object.mode_set(mode='EDIT')
    edit = bmesh.from_edit_mesh(obj.data)
    for vertex in edit.verts:
        vertex.co.z += 0.25
    bmesh.update_edit_mesh(obj.data)
    bpy.ops.object.mode_set(mode='OBJECT')
    bpy.context.view_layer.update()
    modelled = model + np.float32([0.0, 0.0, 0.25])
    assert_same(positions(obj), modelled, "the modelling, after leaving Edit Mode")
    assert bpy.ops.deformkit.reset_rest() == {'FINISHED'}
    assert_same(addon.evaluate.rest_points(obj), modelled, "the rest taken from the modelling")
    twist.enabled = True
    bpy.context.view_layer.update()
    assert float(np.abs(positions(obj) - modelled).max()) > 0.1  # the twist, on the new rest
    twist.enabled = False
    bpy.context.view_layer.update()
    assert_same(positions(obj), modelled, "entries off again: the new rest")


def test_a_transform_without_inverse_is_named():
    # numpy's bare "Singular matrix" was the whole message.
    fresh()
    obj = grid_object()
    add("twist")
    obj.scale.z = 0.0
    bpy.context.view_layer.update()
    message = addon.evaluate.evaluate_safely(obj, force=True)
    assert message.startswith("grid: its transform has no inverse (a scale of 0"), message


def test_ffd_follows_a_lattice_edited_in_edit_mode():
    # In Edit Mode Blender's `co` of a lattice point is garbage (it is computed from the point's index in
    # another array): the FFD read a rest grid of 1e8 and differed from Blender's Lattice modifier by 20.
    fresh()
    obj = grid_object("ours")
    entry = add("ffd")
    lattice = entry.lattice
    theirs = bpy.data.objects.new("theirs", obj.data.copy())
    bpy.context.scene.collection.objects.link(theirs)
    theirs.modifiers.new("Lattice", 'LATTICE').object = lattice
    bpy.context.view_layer.update()
    bpy.context.view_layer.objects.active = lattice
    bpy.ops.object.mode_set(mode='EDIT')
    lattice.data.points[len(lattice.data.points) // 2].co_deform = (0.2, 0.3, 0.9)
    lattice.data.update_tag()
    bpy.context.view_layer.update()
    assert addon.evaluate.evaluate_safely(obj, force=True) == ""
    blender = theirs.evaluated_get(bpy.context.evaluated_depsgraph_get()).data
    expected = np.empty(len(blender.vertices) * 3, np.float32)
    blender.vertices.foreach_get("co", expected)
    moved = float(np.abs(expected.reshape(-1, 3) - positions(theirs)).max())
    assert moved > 0.05, moved  # the edit reached Blender's modifier
    assert_same(positions(obj), expected.reshape(-1, 3), "the FFD against the Lattice modifier, in Edit Mode")
    bpy.ops.object.mode_set(mode='OBJECT')


def test_moving_the_deformed_object_evaluates_it_again():
    # Controls are read in the object's space: moving the object under a still handle changes the
    # deformation at once, as Blender's SimpleDeform does, not at the next frame change.
    fresh()
    obj = grid_object()
    rest = positions(obj).copy()
    twist = add("twist")
    z_up(twist.frame)
    twist.frame.location = (0.5, 0.0, 0.0)
    twist.start_value, twist.end_value = 0.0, 1.0
    bpy.context.view_layer.update()
    at_origin = positions(obj).copy()
    obj.location = (0.25, 0.0, 0.0)
    bpy.context.view_layer.update()
    moved = positions(obj).copy()
    assert np.abs(moved - at_origin).max() > 1e-3
    stack = direct_stack(obj, rest)
    stack.add("twist", "t")
    set_all(stack, 0, [("handleOrigin", (0.25, 0.0, 0.0)), ("handleY", (0, 0, 1)), ("startAngle", 0.0),
                       ("endAngle", 1.0)])
    assert_same(moved, stack.evaluate(rest), "twist after the object moved")


def test_a_scripted_bake_without_frames_bakes_the_scenes_range():
    fresh()
    obj = grid_object()
    layer = obj.data.uv_layers.new(name="UVMap")
    corners = np.array([obj.data.vertices[l.vertex_index].co[:2] for l in obj.data.loops], np.float32)
    layer.data.foreach_set("uv", ((corners + 1.0) / 2.0).ravel())
    add("twist")
    obj.deformkit.uv_rigidity = bpy.data.images.new("rigidity", 16, 16, float_buffer=True)
    out = tempfile.mkdtemp()
    obj.deformkit.uv_output = out
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 2, 4
    try:
        assert bpy.ops.deformkit.bake_redirect() == {'FINISHED'}
    finally:
        scene.frame_start, scene.frame_end = 1, 250
    assert sorted(f for f in os.listdir(out) if f.endswith(".exr")) == [
        f"redirect.1001.{f:04d}.exr" for f in (2, 3, 4)]


def test_shape_keys_an_empty_mesh_and_an_unsaved_output_are_refused_with_reports():
    fresh()
    obj = grid_object()
    obj.shape_key_add(name="Basis")
    bpy.ops.deformkit.add(type="twist")  # added, with the reason it cannot show in the status
    assert "shape keys" in obj.deformkit.status, obj.deformkit.status
    obj.data.uv_layers.new(name="UVMap")
    obj.deformkit.uv_output = tempfile.mkdtemp()
    obj.deformkit.uv_rigidity = bpy.data.images.new("rig", 8, 8)
    try:
        bpy.ops.deformkit.bake_redirect(frame_start=1, frame_end=1)
        raise AssertionError("a bake of a pose the deformers could not write did not report")
    except RuntimeError as e:
        assert "frame 1" in str(e) and "shape keys" in str(e), str(e)

    fresh()
    obj = grid_object()
    obj.data.uv_layers.new(name="UVMap")
    add("twist")
    obj.deformkit.uv_output = tempfile.mkdtemp()
    obj.deformkit.uv_rigidity = bpy.data.images.new("rig", 8, 8)
    bpy.ops.object.mode_set(mode='EDIT')
    try:
        bpy.ops.deformkit.bake_redirect(frame_start=1, frame_end=1)
        raise AssertionError("a bake in Edit Mode did not report")
    except RuntimeError as e:
        assert "Edit Mode" in str(e), str(e)
    bpy.ops.object.mode_set(mode='OBJECT')

    fresh()
    empty = bpy.data.objects.new("empty", bpy.data.meshes.new("empty"))
    bpy.context.scene.collection.objects.link(empty)
    bpy.context.view_layer.objects.active = empty
    try:
        bpy.ops.deformkit.add(type="twist")
        raise AssertionError("adding to an empty mesh did not report")
    except RuntimeError as e:
        assert "no vertices" in str(e), str(e)
    assert len(empty.deformkit.entries) == 0  # no half-made entry left behind

    fresh()
    obj = grid_object()
    obj.data.uv_layers.new(name="UVMap")
    add("twist")
    obj.deformkit.uv_rigidity = bpy.data.images.new("rig", 8, 8)
    assert not bpy.data.filepath and obj.deformkit.uv_output.startswith("//")
    try:
        bpy.ops.deformkit.bake_redirect(frame_start=1, frame_end=1)
        raise AssertionError("a bake to a path relative to an unsaved file did not report")
    except RuntimeError as e:
        assert "not saved yet" in str(e), str(e)


def test_uv_warp_bake_writes_the_solvers_maps_and_the_redirect_nodes():
    fresh()
    obj = grid_object()
    layer = obj.data.uv_layers.new(name="UVMap")
    corners = np.array([obj.data.vertices[l.vertex_index].co[:2] for l in obj.data.loops], np.float32)
    layer.data.foreach_set("uv", ((corners + 1.0) / 2.0).ravel())  # the grid fills tile 1001
    rest = positions(obj).copy()
    entry = add("slide")
    entry.end.location = (0.0, 0.0, 0.0)
    entry.end.keyframe_insert("location", frame=1)
    entry.end.location = (0.25, 0.0, 0.0)
    entry.end.keyframe_insert("location", frame=3)
    # A rigid disk painted in a 32 x 32 float image (Blender rows bottom-up).
    size = 32
    ys, xs = np.mgrid[0:size, 0:size]
    disk = (((xs + 0.5) / size - 0.5) ** 2 + ((ys + 0.5) / size - 0.5) ** 2 < 0.2 ** 2).astype(np.float32)
    image = bpy.data.images.new("rigidity", size, size, float_buffer=True)
    rgba = np.zeros((size, size, 4), np.float32)
    rgba[..., 0] = disk
    rgba[..., 3] = 1.0
    image.pixels.foreach_set(rgba.ravel())
    obj.deformkit.uv_rigidity = image
    out = tempfile.mkdtemp()
    obj.deformkit.uv_output = out
    assert bpy.ops.deformkit.bake_redirect(frame_start=1, frame_end=3) == {'FINISHED'}
    files = sorted(os.listdir(out))
    assert files == [f"redirect.1001.{f:04d}.exr" for f in (1, 2, 3)] + ["report.html", "report_files",
                                                                            "uvwarp.jsonl"], files
    check_bake_report(obj, out, disk)

    # The same solve through the module: the mesh's own positions at each frame, the painted disk (row 0 at
    # v = 1, so Blender's bottom-up rows flipped), the shot preset (each frame from the identity, refined by
    # the grid's size): the same bytes.
    counts = np.full(len(obj.data.polygons), 4, np.int32)
    indices = np.array([v for p in obj.data.polygons for v in p.vertices], np.int32)
    uv_indices = np.arange(len(indices), dtype=np.int32)
    uvs = (rest[indices][:, :2] + 1.0) / 2.0
    solver = dk.UvWarpSolver(rest, counts, indices, uvs.astype(np.float32), uv_indices, 1001,
                             np.ascontiguousarray(disk[::-1]), preset="shot")
    for frame in (1, 2, 3):
        bpy.context.scene.frame_set(frame)
        solver.solve(positions(obj))
        baked = dk.read_image(os.path.join(out, f"redirect.1001.{frame:04d}.exr"))
        assert np.array_equal(baked[:, :, :2], solver.redirect_map()), f"frame {frame}"
    assert np.abs(solver.redirect_map() - dk.read_image(os.path.join(out, "redirect.1001.0001.exr"))[:, :, :2]
                  ).max() > 1e-4  # the slide at frame 3 does warp the texture

    # Each map's header says what made it: the library's version, tile, frame, solver and inputs.
    for frame in (1, 2, 3):
        header = dk.read_image_info(os.path.join(out, f"redirect.1001.{frame:04d}.exr"))["attributes"]
        assert (header["deformkit:version"], header["deformkit:uvwarp:tile"], header["deformkit:uvwarp:frame"]) == (
            dk.__version__, "1001", str(frame)), header
        assert json.loads(header["deformkit:uvwarp:inputs"]) == {
            "rest": "Blender object 'grid'", "rigidity": "rigidity image 'rigidity' tile 1001", "mask": "derived",
            "orientation": "none", "deformed": f"Blender object 'grid' evaluated at frame {frame}"}, header
        assert json.loads(header["deformkit:uvwarp:solver"])["texels"] == size

    # Resume: a bake that lost frame 2's map sets frame 2 only (each frame is solved from the identity, so
    # frame 1 is not needed) and writes that map alone, the same bytes; the others are not written (they keep
    # an old modification time set here).
    old = 10**18  # ns: 2001

    def files_now():  # the maps (the log and the report tell each bake)
        return {name: (os.stat(os.path.join(out, name)).st_mtime_ns == old,
                       open(os.path.join(out, name), "rb").read())
                for name in sorted(os.listdir(out)) if name.startswith("redirect.")}

    for name in os.listdir(out):
        os.utime(os.path.join(out, name), ns=(old, old))
    first = files_now()
    os.remove(os.path.join(out, "redirect.1001.0002.exr"))
    frames_set = []

    def record(scene, *_):
        frames_set.append(scene.frame_current)

    bpy.context.scene.frame_set(3)
    bpy.app.handlers.frame_change_post.append(record)
    try:
        assert bpy.ops.deformkit.bake_redirect(frame_start=1, frame_end=3, resume=True) == {'FINISHED'}
    finally:
        bpy.app.handlers.frame_change_post.remove(record)
    # Frame 2 for its map, the worst frame for the report's heatmaps, then the scene back on its frame.
    assert frames_set[0] == 2 and frames_set[-1] == 3 and len(frames_set) == 3, frames_set
    resumed = files_now()
    assert {name: data for name, (_, data) in resumed.items()} == {name: data for name, (_, data) in first.items()}
    assert [resumed[name][0] for name in sorted(first)] == [True, False, True], resumed.keys()
    # With every map there, a resumed bake solves nothing.
    report = addon.uvwarp.bake_redirect_maps(bpy.context, obj, image, None, range(1, 4), out, resume=True)
    assert [report[1001][k] for k in ("written", "replayed", "skipped", "files")] == [0, 0, 3, []], report
    # The operator's default writes every map again (a rigger re-baking after repainting), the same bytes here.
    for name in os.listdir(out):
        os.utime(os.path.join(out, name), ns=(old, old))
    assert bpy.ops.deformkit.bake_redirect(frame_start=1, frame_end=3) == {'FINISHED'}
    assert files_now() == {name: (False, data) for name, (_, data) in first.items()}

    material = bpy.data.materials.new("skin")
    material.use_nodes = True
    albedo = material.node_tree.nodes.new('ShaderNodeTexImage')
    obj.data.materials.append(material)
    assert bpy.ops.deformkit.redirect_material(frame_start=1, frame_end=3) == {'FINISHED'}
    group = bpy.data.node_groups["DeformKit Redirect"]
    assert [s.name for s in group.inputs] == ["UV", "Redirect"] and [s.name for s in group.outputs] == ["UV"]
    links = albedo.inputs["Vector"].links
    assert len(links) == 1 and links[0].from_node.type == 'GROUP'
    redirect = [n for n in material.node_tree.nodes if n.label == "DeformKit Redirect"][0]
    assert redirect.image.source == 'SEQUENCE' and redirect.image_user.frame_duration == 3
    bpy.data.images.remove(redirect.image)
    shutil.rmtree(out, ignore_errors=True)


def check_bake_report(obj, out, disk):
    """The bake's shot report: written beside the maps, its figures those of the bake's log, its heatmaps made
    from the evaluated object and the painted image (neither is a file), and an operator that opens it."""
    page = os.path.join(out, "report.html")
    assert obj.deformkit.uv_report == page
    lines = [json.loads(line) for line in open(os.path.join(out, "uvwarp.jsonl"))]
    assert [(l["tile"], l["frame"], l["status"]) for l in lines] == [(1001, f, "written") for f in (1, 2, 3)]
    html = open(page, encoding="utf-8").read()
    data = json.loads(re.search(r'<script type="application/json" id="deformkit-shot">(.*?)</script>', html,
                                re.S).group(1))
    tile = data["tiles"][0]
    assert tile["frames"] == [1, 2, 3]
    assert tile["rigid_stretch_removed"] == [l["metrics"]["rigid_stretch_removed"] for l in lines]
    worst = min(lines, key=lambda l: l["metrics"]["rigid_stretch_removed"])
    assert tile["worst_frame"] == worst["frame"]
    assert "measured again from its files: the same" in html, "the heatmaps' inputs differ from the bake's"
    assert html.count("data:image/png;base64,") == 4 and "no heatmaps" not in html
    opened = []
    real = addon.ops.webbrowser.open
    addon.ops.webbrowser.open = opened.append
    try:
        assert bpy.ops.deformkit.open_uvwarp_report() == {'FINISHED'}
    finally:
        addon.ops.webbrowser.open = real
    assert opened == [pathlib.Path(page).resolve().as_uri()], opened


def test_bake_errors_are_reports():
    fresh()
    obj = grid_object()
    add("slide")
    obj.deformkit.uv_output = tempfile.mkdtemp()
    try:
        bpy.ops.deformkit.bake_redirect(frame_start=1, frame_end=2)
        raise AssertionError("a bake without UVs did not report")
    except RuntimeError as e:
        assert "no UV map" in str(e), str(e)


def key(owner, path, values, index=-1):
    """Keys owner.path (its component `index`, or the whole property) at the given {frame: value}."""
    for frame, value in values.items():
        if index >= 0:
            getattr(owner, path)[index] = value
        else:
            setattr(owner, path, value)
        owner.keyframe_insert(path, index=index, frame=frame)


def fcurve(id_block, path, index=0):
    """The F-curve of id_block's path[index], made linear between its keys."""
    curve = id_block.animation_data.action.fcurves.find(path, index=index)
    assert curve is not None, path
    for key in curve.keyframe_points:
        key.interpolation = 'LINEAR'
    return curve


def animated_twist_and_lattice(obj):
    """A twist whose end angle is keyed (0.3 at frame 1, 1.5 at frame 5) and an FFD whose lattice's centre
    point is keyed (up 0 at frame 1, 0.5 at frame 5) on `obj`; returns a function giving the module's
    result for a frame, from the F-curves' own values there."""
    twist = add("twist")
    z_up(twist.frame)
    twist.start_value = 0.0
    key(twist, "end_value", {1: 0.3, 5: 1.5})
    twist_curve = fcurve(obj, 'deformkit.entries[0].end_value', 0)
    ffd = add("ffd")
    ffd.basis = "0"  # Sederberg and Parry's, as the module's basis 0 in expected()
    lattice = ffd.lattice
    lattice.location, lattice.rotation_euler, lattice.scale = (0, 0, 0), (0, 0, 0), (2.5, 2.5, 1.0)
    centre = (1 * 3 + 1) * 3 + 1
    key(lattice.data.points[centre], "co_deform", {1: 0.0, 5: 0.5}, index=2)
    lift_curve = fcurve(lattice.data, f'points[{centre}].co_deform', 2)
    rest = addon.evaluate.rest_points(obj)
    origin, edge = np.array([-2.5, -2.5, -1.0]), np.array([5.0, 5.0, 2.0])
    grid = np.array([origin + np.array([i, j, k]) / 2.0 * edge
                     for i in range(3) for j in range(3) for k in range(3)])

    def expected(frame):
        stack = direct_stack(obj, rest)
        stack.add("twist", "t")
        set_all(stack, 0, [("handleOrigin", (0, 0, 0)), ("handleY", (0, 0, 1)), ("startAngle", 0.0),
                           ("endAngle", np.float32(twist_curve.evaluate(frame))), ("lowBound", -1.0),
                           ("highBound", 1.0)])
        points = grid.copy()
        points[centre, 2] += np.float32(lift_curve.evaluate(frame))
        stack.add("ffd", "f")
        set_all(stack, 1, [("basis", 0), ("divisions", (2, 2, 2)), ("origin", origin),
                           ("axes", (5.0, 0, 0, 0, 5.0, 0, 0, 0, 2.0)), ("points", points.ravel())])
        return stack.evaluate(rest)

    return expected


def test_an_animation_render_deforms_each_frame_as_keyed():
    # Blender flushes animated values back to the original data only for the active depsgraph; a render
    # evaluates its own. Each rendered frame must show that frame's keyed twist angle and lattice point.
    fresh()
    scene = bpy.context.scene
    obj = grid_object()
    expected = animated_twist_and_lattice(obj)
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    scene.collection.objects.link(camera)
    camera.location = (0.0, 0.0, 5.0)  # looking down -Z
    camera.data.type = 'ORTHO'
    camera.data.ortho_scale = 4.0  # [-2, 2]^2: 16 pixels per unit at 64 x 64
    scene.camera = camera
    scene.render.engine = 'CYCLES'
    scene.cycles.samples = 1
    scene.cycles.use_denoising = False
    scene.render.film_transparent = True
    scene.render.resolution_x = scene.render.resolution_y = 64
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = 'PNG'
    scene.render.image_settings.color_mode = 'RGBA'
    scene.frame_start, scene.frame_end = 1, 5
    scene.frame_set(5)  # the viewport shows frame 5: a render that kept it would show frame 5 everywhere

    seen = {}

    def capture(scene_, depsgraph):  # after the add-on's handler: what it wrote for this depsgraph
        if depsgraph.mode == 'RENDER':
            seen[scene_.frame_current] = positions(obj).copy()

    folder = tempfile.mkdtemp()
    widths = {}
    bpy.app.handlers.frame_change_post.append(capture)
    try:
        scene.render.filepath = os.path.join(folder, "frame")
        bpy.ops.render.render(animation=True)
        for frame in range(1, 6):
            want = expected(frame)
            if frame in seen:  # the same kernels on the same float32 values
                assert_same(seen[frame], want, f"rendered frame {frame}'s mesh")
            # The picture: the grid seen from above is a square turned by the twist's angle at z = 0; the
            # bounding box of its covered pixels is the expected mesh's, to within a pixel and a half
            # (one sample a pixel), and it grows from 36 to 45 pixels wide between frames 1 and 5.
            image = bpy.data.images.load(os.path.join(folder, f"frame{frame:04d}.png"))
            alpha = np.array(image.pixels[:], np.float32).reshape(64, 64, 4)[:, :, 3]
            bpy.data.images.remove(image)
            columns = np.nonzero(alpha.max(axis=0) > 0.5)[0]
            rows = np.nonzero(alpha.max(axis=1) > 0.5)[0]
            covered = np.array([columns[0], columns[-1] + 1, rows[0], rows[-1] + 1], np.float64)
            pixels = 16.0 * np.array([want[:, 0].min(), want[:, 0].max(), want[:, 1].min(),
                                      want[:, 1].max()]) + 32.0
            assert np.abs(covered - pixels).max() <= 1.5, f"frame {frame}: covered {covered}, mesh {pixels}"
            widths[frame] = covered[1] - covered[0]
        assert widths[5] - widths[1] >= 6, widths  # the pictures differ as the keyed angle does
        assert sorted(seen) == [1, 2, 3, 4, 5], sorted(seen)  # the handler ran in the render's depsgraph
    finally:
        bpy.app.handlers.frame_change_post.remove(capture)
        shutil.rmtree(folder, ignore_errors=True)
        scene.render.engine = 'BLENDER_EEVEE'
        scene.camera = None


def test_another_scene_changed_with_frame_set_deforms_as_keyed():
    # A scene that is not the window's: its depsgraph is not the active one.
    fresh()
    obj = grid_object()
    expected = animated_twist_and_lattice(obj)
    other = bpy.data.scenes.new("other")
    try:
        other.collection.objects.link(obj)
        for control in addon.evaluate.controls(obj):
            other.collection.objects.link(bpy.data.objects[control])
        for frame in (4, 2, 5):
            other.frame_set(frame)
            assert_same(positions(obj), expected(frame), f"the other scene at frame {frame}")
        bpy.context.scene.frame_set(3)
        assert_same(positions(obj), expected(3), "the window's scene at frame 3")
    finally:
        bpy.data.scenes.remove(other)


def data_path(*parts):
    data = os.environ.get("DEFORMKIT_TEST_DATA",
                          os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data"))
    path = os.path.join(data, *parts)
    assert os.path.exists(path), path
    return path


def mesh_object_from_obj(path, name, uvs=False):
    """A mesh object with the OBJ's points and faces (and its UVs as the UV map), read through the module
    (not Blender's importer)."""
    source = dk.read_mesh(path)
    counts, indices = np.asarray(source.face_counts), np.asarray(source.face_indices)
    starts = np.concatenate(([0], np.cumsum(counts)[:-1]))
    faces = [indices[s:s + c].tolist() for s, c in zip(starts, counts)]
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(np.asarray(source.points).tolist(), [], faces)
    if uvs:
        layer = mesh.uv_layers.new(name="UVMap")  # loops in face order, as the OBJ's corners
        layer.data.foreach_set("uv", np.asarray(source.uvs)[np.asarray(source.uv_indices)].ravel())
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def test_as_the_lattice_equals_blenders_lattice_modifier_on_real_meshes():
    # A rig's lattice deforms a DeformKit FFD ("As the Lattice") as Blender's own Lattice modifier deforms a
    # copy of the mesh: Spot and Suzanne (their own shapes, off-centre, moved and turned), lattices of
    # several sizes and each interpolation (and a mixed one), covering part of the mesh only, so points lie
    # inside and outside, every lattice point moved at random.
    fresh()
    meshes = [data_path("spot", "spot_quadrangulated.obj"), data_path("suzanne", "suzanne.0001.obj")]
    rng = np.random.default_rng(20)
    cases = [((2, 2, 2), ("KEY_LINEAR",) * 3), ((3, 4, 5), ("KEY_BSPLINE",) * 3),
             ((4, 3, 3), ("KEY_CARDINAL",) * 3), ((5, 2, 4), ("KEY_CATMULL_ROM",) * 3),
             ((4, 5, 3), ("KEY_BSPLINE", "KEY_CATMULL_ROM", "KEY_LINEAR"))]
    worst = 0.0
    for path in meshes:
        for (size, kinds) in cases:
            fresh()
            ours = mesh_object_from_obj(path, "ours")
            ours.location, ours.rotation_euler = (0.3, -0.2, 0.1), (0.2, 0.0, 0.4)
            rest = positions(ours).copy()
            theirs = bpy.data.objects.new("theirs", ours.data.copy())
            bpy.context.scene.collection.objects.link(theirs)
            theirs.location, theirs.rotation_euler = ours.location, ours.rotation_euler
            lattice_data = bpy.data.lattices.new("rig")
            lattice_data.points_u, lattice_data.points_v, lattice_data.points_w = size
            (lattice_data.interpolation_type_u, lattice_data.interpolation_type_v,
             lattice_data.interpolation_type_w) = kinds
            lattice = bpy.data.objects.new("rig", lattice_data)
            bpy.context.scene.collection.objects.link(lattice)
            # About 80% of the mesh's extent, off its centre and turned: points inside and outside.
            bpy.context.view_layer.update()
            world = np.array([ours.matrix_world @ mathutils.Vector(p) for p in rest])
            low, high = world.min(axis=0), world.max(axis=0)
            lattice.location = 0.5 * (low + high) + 0.1 * (high - low)
            lattice.rotation_euler = (0.1, -0.15, 0.3)
            lattice.scale = 0.8 * (high - low) / (np.array(size) - 1)  # a new lattice's points are 1 apart
            diagonal = float(np.linalg.norm(high - low))
            for point in lattice_data.points:
                point.co_deform = mathutils.Vector(point.co) + mathutils.Vector(rng.uniform(-0.2, 0.2, 3))
            modifier = theirs.modifiers.new("Lattice", 'LATTICE')
            modifier.object = lattice
            bpy.context.view_layer.objects.active = ours
            entry = add("ffd")
            assert entry.basis == "LATTICE"  # the default
            entry.lattice = lattice
            bpy.context.view_layer.update()
            depsgraph = bpy.context.evaluated_depsgraph_get()
            blender = theirs.evaluated_get(depsgraph).data
            expected = np.empty(len(blender.vertices) * 3, np.float32)
            blender.vertices.foreach_get("co", expected)
            expected = expected.reshape(-1, 3)
            moved = np.abs(expected - rest).max(axis=1) > 1e-3 * diagonal
            local = np.array([lattice.matrix_world.inverted() @ p for p in map(mathutils.Vector, world)])
            corner = np.array(lattice_data.points[-1].co)  # the lattice spans [-corner, corner]
            outside = (np.abs(local) > corner).any(axis=1)
            assert moved.mean() > 0.9 and 0.1 < outside.mean() < 0.9, (moved.mean(), outside.mean())
            error = float(np.abs(positions(ours) - expected).max()) / diagonal
            worst = max(worst, error)
            assert error <= 1e-6, f"{os.path.basename(path)} {size} {kinds}: {error:.2e} of the diagonal"
    print(f"  as the lattice against the Lattice modifier: worst {worst:.2e} of the bounding-box diagonal")


def test_live_uv_warp_follows_frame_changes_through_the_material():
    # Spot with its own UVs, twisted by a keyed angle, rigid disks painted in a 128 x 128 image; live mode
    # on: every frame change solves the warm-started warp and fills the live image the material reads.
    # The same solver through the module, fed the mesh at each frame, gives the same bytes.
    fresh()
    obj = mesh_object_from_obj(data_path("spot", "spot_quadrangulated.obj"), "spot", uvs=True)
    bpy.context.view_layer.objects.active = obj
    rest = positions(obj).copy()
    material = bpy.data.materials.new("skin")
    material.use_nodes = True
    texture = material.node_tree.nodes.new('ShaderNodeTexImage')
    texture.image = bpy.data.images.new("scales", 8, 8)
    obj.data.materials.append(material)
    twist = add("twist")
    twist.start_value = 0.0
    key(twist, "end_value", {1: 0.0, 5: 1.2})
    fcurve(obj, 'deformkit.entries[0].end_value', 0)
    size = 128
    ys, xs = np.mgrid[0:size, 0:size]
    disks = np.zeros((size, size), np.float32)
    for cx, cy in ((0.3, 0.3), (0.6, 0.5), (0.45, 0.75), (0.8, 0.2)):
        disks[((xs + 0.5) / size - cx) ** 2 + ((ys + 0.5) / size - cy) ** 2 < 0.05 ** 2] = 1.0
    rgba = np.zeros((size, size, 4), np.float32)
    rgba[..., 0], rgba[..., 3] = disks, 1.0
    rigidity = bpy.data.images.new("rigidity", size, size, float_buffer=True)
    rigidity.pixels.foreach_set(rgba.ravel())
    obj.deformkit.uv_rigidity = rigidity
    bpy.context.scene.frame_set(1)

    assert bpy.ops.deformkit.uvwarp_live() == {'FINISHED'}
    assert addon.uvwarp.live_active(obj)
    live = bpy.data.images[addon.uvwarp.LIVE_IMAGE.format(obj.name)]
    assert tuple(live.size) == (size, size)
    redirect_nodes = [n for n in material.node_tree.nodes if n.label == addon.uvwarp.GROUP_NAME]
    assert [n.image for n in redirect_nodes] == [live]
    group = next(n for n in material.node_tree.nodes if n.type == 'GROUP')
    assert texture.inputs["Vector"].links[0].from_node == group

    counts = np.full(len(obj.data.polygons), 4, np.int32)
    indices = np.array([v for p in obj.data.polygons for v in p.vertices], np.int32)
    uvs = np.empty(len(obj.data.loops) * 2, np.float32)
    obj.data.uv_layers.active.data.foreach_get("uv", uvs)
    solver = dk.UvWarpSolver(rest, counts, indices, uvs.reshape(-1, 2), np.arange(len(indices), dtype=np.int32),
                             1001, np.ascontiguousarray(disks[::-1]), preset="live")
    solver.solve(positions(obj))  # the operator's first frame
    for frame in (2, 3, 4, 5):
        bpy.context.scene.frame_set(frame)
        solver.solve(positions(obj))
        pixels = np.empty(size * size * 4, np.float32)
        live.pixels.foreach_get(pixels)
        shown = pixels.reshape(size, size, 4)[::-1, :, :2]
        assert np.array_equal(shown, solver.redirect_map()), f"frame {frame}"
    identity = dk.UvWarpSolver(rest, counts, indices, uvs.reshape(-1, 2), np.arange(len(indices), dtype=np.int32),
                               1001, np.ascontiguousarray(disks[::-1])).redirect_map()
    assert np.abs(shown - identity).max() > 1e-3  # the twist does warp the texture
    rate = addon.uvwarp.live_rate(obj)
    assert rate is not None and rate[0] > 0.0
    # The live preset by grid size, the library's (docs/decisions.md UV-30): the measured schedules of 64 to
    # 2048 cells, the coarse levels over-relaxed by 1.4; preset="live" runs them.
    presets = {cells: dk.uv_warp_live_options(cells)["sweeps_per_level"]
               for cells in (64, 128, 256, 512, 1024, 2048, 4096)}
    assert presets == {64: [8, 16, 32], 128: [8, 16, 32], 256: [3, 8, 12], 512: [2, 2, 10], 1024: [1, 1, 10],
                       2048: [1, 1, 2, 8], 4096: [1, 1, 2, 8]}
    assert [dk.uv_warp_live_options(cells)["max_levels"] for cells in (512, 1024, 2048)] == [0, 4, 5]
    assert all(abs(dk.uv_warp_live_options(cells)["coarse_relaxation"] - 1.4) < 1e-6  # a float32
               for cells in (128, 1024, 4096))
    assert {k: solver.options[k] for k in dk.uv_warp_live_options(size)} == dk.uv_warp_live_options(size)
    print(f"  live UV warp, Spot at {size}^2: {rate[0]:.1f} frames/s ({rate[1]:.1f} ms a frame)")

    # Renamed, the object stays live (its state followed its name, and stopped without a word).
    obj.name = "spot renamed"
    bpy.context.scene.frame_set(4)
    solver.solve(positions(obj))
    live.pixels.foreach_get(pixels)
    assert np.array_equal(pixels.reshape(size, size, 4)[::-1, :, :2], solver.redirect_map()), "after a rename"
    bpy.context.scene.frame_set(5)
    solver.solve(positions(obj))
    live.pixels.foreach_get(pixels)
    assert addon.uvwarp.live_active(obj)

    # Off: frame changes leave the image alone.
    assert bpy.ops.deformkit.uvwarp_live() == {'FINISHED'}
    assert not addon.uvwarp.live_active(obj)
    bpy.context.scene.frame_set(3)
    after = np.empty(size * size * 4, np.float32)
    live.pixels.foreach_get(after)
    assert np.array_equal(after, pixels)


def test_live_uv_warp_refuses_udim_layouts_with_a_report():
    fresh()
    obj = grid_object()
    layer = obj.data.uv_layers.new(name="UVMap")
    corners = np.array([obj.data.vertices[l.vertex_index].co[:2] for l in obj.data.loops], np.float32)
    layer.data.foreach_set("uv", (corners + 1.0).ravel())  # [0, 2]^2: tiles 1001, 1002, 1011, 1012
    obj.deformkit.uv_rigidity = bpy.data.images.new("rigidity", 16, 16, float_buffer=True)
    try:
        bpy.ops.deformkit.uvwarp_live()
        raise AssertionError("live mode on a UDIM layout did not report")
    except RuntimeError as e:
        assert "tile 1001 only" in str(e) and "1012" in str(e), str(e)
    assert not addon.uvwarp.live_active(obj)

def _select(*objects):
    for other in bpy.context.view_layer.objects:
        other.select_set(False)
    for obj in objects:
        obj.select_set(True)
    bpy.context.view_layer.objects.active = objects[-1]


def test_a_mesh_joined_into_an_object_takes_its_own_rest_shape():
    # Join copied the twisted object's rest attribute into the active one, (0, 0, 0) for its own vertices and
    # no polygons beside it: its first entry kept that rest, and a taper by 1 collapsed the mesh on the origin.
    fresh()
    twisted = grid_object("twisted")
    twist = add("twist")
    twist.start_value, twist.end_value = 0.0, 1.0
    plain = grid_object("plain")
    plain.location = (3.0, 0.0, 0.0)
    bpy.context.view_layer.update()
    _select(twisted, plain)
    assert bpy.ops.object.join() == {'FINISHED'}
    joined = bpy.context.object
    shape = positions(joined).copy()
    taper = add("taper")
    taper.start_value = taper.end_value = 1.0  # the identity
    assert addon.evaluate.evaluate_safely(joined, force=True) == ""
    assert_same(addon.evaluate.rest_points(joined), shape, "rest shape of the joined mesh's first entry")
    assert_same(positions(joined), shape, "joined mesh under a taper by 1")


def test_a_deformation_that_cannot_be_taken_back_is_never_taken_as_the_rest():
    # Following the refusal's advice after a cube was added under a twist (entries off, Reset Rest) took the
    # twisted grid as the rest: the twist was applied twice when the entry came back on.
    fresh()
    obj = grid_object()
    rest = positions(obj).copy()
    twist = add("twist")
    twist.start_value, twist.end_value = 0.0, 1.0
    bpy.context.view_layer.update()
    twisted = positions(obj).copy()
    assert np.abs(twisted - rest).max() > 0.1
    bpy.ops.object.mode_set(mode='EDIT')
    bpy.ops.mesh.select_all(action='DESELECT')
    bpy.ops.mesh.primitive_cube_add(size=0.5, location=(2.0, 0.0, 0.0))
    bpy.ops.object.mode_set(mode='OBJECT')
    bpy.context.view_layer.update()
    assert "Undo the change" in obj.deformkit.status, obj.deformkit.status
    twist.enabled = False
    bpy.context.view_layer.update()
    try:
        bpy.ops.deformkit.reset_rest()
        raise AssertionError("Reset Rest took the twisted grid as the rest")
    except RuntimeError as e:
        assert "still shows its deformation" in str(e) and "441 vertices then, 449 vertices now" in str(e), str(e)
    assert_same(addon.evaluate.rest_points(obj)[:441], rest, "the rest shape, kept")
    # Removing the stack keeps the mesh as it shows (the new cube has no rest position to go back to).
    bpy.ops.deformkit.remove()
    assert not addon.evaluate.has_rest(obj)
    assert_same(positions(obj)[:441], twisted, "the grid as shown")
    assert float(positions(obj)[441:, 0].min()) > 1.7, "the cube where it was modelled"

    # The way the message gives: the entry off first (the mesh back at rest), then the change, then Reset Rest.
    fresh()
    obj = grid_object()
    twist = add("twist")
    twist.start_value, twist.end_value = 0.0, 1.0
    bpy.context.view_layer.update()
    assert addon.evaluate.shows_deformation(obj)
    twist.enabled = False
    bpy.context.view_layer.update()
    assert not addon.evaluate.shows_deformation(obj)
    bpy.ops.object.mode_set(mode='EDIT')
    bpy.ops.mesh.select_all(action='DESELECT')
    bpy.ops.mesh.primitive_cube_add(size=0.5, location=(2.0, 0.0, 0.0))
    bpy.ops.object.mode_set(mode='OBJECT')
    assert bpy.ops.deformkit.reset_rest() == {'FINISHED'}
    twist.enabled = True
    assert addon.evaluate.evaluate_safely(obj, force=True) == ""
    stack = dk.DeformerStack()
    counts = np.array([len(p.vertices) for p in obj.data.polygons], np.int32)
    indices = np.array([v for p in obj.data.polygons for v in p.vertices], np.int32)
    new_rest = addon.evaluate.rest_points(obj)
    assert_same(new_rest[:441], rest, "the grid's rest, from before the change")
    stack.set_rest(dk.Mesh(new_rest, counts, indices))
    stack.add("twist", "t")
    set_all(stack, 0, addon.evaluate.entry_parameters(obj, twist))
    assert_same(positions(obj), stack.evaluate(new_rest), "the twist, once, over grid and cube")


def test_polygons_flipped_under_a_stack_are_refused_at_once_as_after_reopening():
    # Flipping normals keeps the counts: the open file went on with the old polygons, the reopened one refused.
    fresh()
    obj = grid_object()
    twist = add("twist")
    twist.start_value, twist.end_value = 0.0, 1.0
    bpy.context.view_layer.update()
    bpy.ops.object.mode_set(mode='EDIT')
    bpy.ops.mesh.select_all(action='SELECT')
    bpy.ops.mesh.flip_normals()
    bpy.ops.object.mode_set(mode='OBJECT')
    twist.end_value = 1.5
    bpy.context.view_layer.update()
    message = obj.deformkit.status
    assert "polygons changed since its rest shape was taken (the same 441 vertices)" in message, message
    path = os.path.join(tempfile.mkdtemp(), "flipped.blend")
    bpy.ops.wm.save_as_mainfile(filepath=path)
    bpy.ops.wm.open_mainfile(filepath=path)
    obj = bpy.data.objects["grid"]
    assert addon.evaluate.evaluate_safely(obj, force=True) == message
    bpy.ops.wm.read_factory_settings(use_empty=True)  # the tests after this one start from an unsaved file


def test_a_linked_mesh_and_a_deleted_control_are_reported():
    # A mesh linked from a library ignored the positions written to it: the object stayed at its saved
    # shape on every frame, without a word. A control deleted with X stayed in the file through the
    # entry's pointer, hidden, and went on deforming.
    fresh()
    obj = grid_object("linked grid")
    add("twist")
    library = os.path.join(tempfile.mkdtemp(), "library.blend")
    bpy.ops.wm.save_as_mainfile(filepath=library)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon.evaluate.clear_cache()
    with bpy.data.libraries.load(library, link=True) as (source, target):
        target.objects = ["linked grid"]
    linked = target.objects[0]
    bpy.context.scene.collection.objects.link(linked)
    message = addon.evaluate.evaluate_safely(linked, force=True)
    assert f"its mesh 'linked grid' is linked from '{library}'" in message and "Make Local" in message, message

    fresh()
    obj = grid_object()
    twist = add("twist")
    handle = twist.frame
    _select(handle)
    assert bpy.ops.object.delete() == {'FINISHED'}
    bpy.context.view_layer.update()
    twist.end_value = 2.0
    message = obj.deformkit.status
    assert f"its handle Empty '{handle.name}' was deleted (it is in no scene)" in message, message


def test_apply_keeps_the_deformation_and_bend_curvature_takes_either_sign():
    fresh()
    obj = grid_object()
    bend = add("bend")
    bend.curvature = -0.75  # away from the Empty's X; 0 is straight
    bpy.context.view_layer.update()
    assert obj.deformkit.status == ""
    rest = addon.evaluate.rest_points(obj).copy()
    stack = direct_stack(obj, rest)
    stack.add("bend", "b")
    set_all(stack, 0, addon.evaluate.entry_parameters(obj, bend))
    bent = stack.evaluate(rest)
    assert_same(positions(obj), bent, "bend with a negative curvature")
    assert np.abs(bent - rest).max() > 0.05
    bend.curvature = 0.0
    bpy.context.view_layer.update()
    assert_same(positions(obj), rest, "bend with curvature 0")
    bend.curvature = -0.75
    bpy.context.view_layer.update()
    assert bpy.ops.deformkit.apply() == {'FINISHED'}
    assert len(obj.deformkit.entries) == 0 and not addon.evaluate.has_rest(obj)
    assert_same(positions(obj), bent, "the applied bend")
    add("taper")  # a new first entry starts from the applied shape
    assert_same(addon.evaluate.rest_points(obj), bent, "rest after applying")


def test_redirect_nodes_read_the_solved_uv_map_through_the_materials_mapping():
    # The live warp solved on the active UV map while its nodes read the render map, and the texture's own
    # Mapping node (4 x tiling) was unlinked.
    fresh()
    obj = grid_object()
    layout = obj.data.uv_layers.new(name="UVMap")
    corners = np.array([obj.data.vertices[l.vertex_index].co[:2] for l in obj.data.loops], np.float32)
    layout.data.foreach_set("uv", (corners * 0.45 + 0.5).ravel())
    flipped = obj.data.uv_layers.new(name="Flipped")
    flipped.data.foreach_set("uv", (corners[:, ::-1] * 0.45 + 0.5).ravel())
    add("twist")
    rigidity = bpy.data.images.new("rigidity", 32, 32, float_buffer=True)
    obj.deformkit.uv_rigidity = rigidity
    material = bpy.data.materials.new("skin")
    material.use_nodes = True
    obj.data.materials.append(material)
    tree = material.node_tree
    texture = tree.nodes.new('ShaderNodeTexImage')
    texture.image = bpy.data.images.new("albedo", 8, 8)
    uv_node = tree.nodes.new('ShaderNodeUVMap')
    uv_node.uv_map = "UVMap"
    mapping = tree.nodes.new('ShaderNodeMapping')
    tree.links.new(uv_node.outputs["UV"], mapping.inputs["Vector"])
    tree.links.new(mapping.outputs["Vector"], texture.inputs["Vector"])
    obj.data.uv_layers.active = flipped  # edited in the UV editor; the texture reads "UVMap"
    try:
        bpy.ops.deformkit.uvwarp_live()
        raise AssertionError("live mode solved one UV map for a texture reading another")
    except RuntimeError as e:
        assert "image texture 'Image Texture' reads UV map 'UVMap', but the warp is solved on the active UV " \
            "map 'Flipped'" in str(e), str(e)
    assert not addon.uvwarp.live_active(obj)
    obj.data.uv_layers.active = layout
    assert bpy.ops.deformkit.uvwarp_live() == {'FINISHED'}
    group = next(n for n in tree.nodes if n.type == 'GROUP')
    assert texture.inputs["Vector"].links[0].from_node == mapping, "the Mapping node stays before the texture"
    assert mapping.inputs["Vector"].links[0].from_node == group, "the redirect comes before the Mapping"
    source = group.inputs["UV"].links[0].from_node
    assert source.type == 'UVMAP' and source.uv_map == "UVMap"
    assert bpy.ops.deformkit.uvwarp_live() == {'FINISHED'}  # off

    # Through a Reroute and an offset added to the UVs, the redirect goes where the UVs enter (not into the
    # offset's constant); a texture read at object coordinates is left alone, and said so.
    fresh_material = bpy.data.materials.new("offset")
    fresh_material.use_nodes = True
    obj.data.materials[0] = fresh_material
    tree = fresh_material.node_tree
    shifted = tree.nodes.new('ShaderNodeTexImage')
    shifted.image = bpy.data.images.new("detail", 8, 8)
    add_offset = tree.nodes.new('ShaderNodeVectorMath')
    add_offset.operation = 'ADD'
    reroute = tree.nodes.new('NodeReroute')
    uv_node = tree.nodes.new('ShaderNodeUVMap')
    uv_node.uv_map = "UVMap"
    tree.links.new(uv_node.outputs["UV"], reroute.inputs[0])
    tree.links.new(reroute.outputs[0], add_offset.inputs[1])  # input 0 keeps its constant offset
    tree.links.new(add_offset.outputs["Vector"], shifted.inputs["Vector"])
    projected = tree.nodes.new('ShaderNodeTexImage')
    projected.image = bpy.data.images.new("projected", 8, 8)
    coordinates = tree.nodes.new('ShaderNodeTexCoord')
    tree.links.new(coordinates.outputs["Object"], projected.inputs["Vector"])
    skipped = []
    addon.uvwarp.add_live_nodes(fresh_material, obj, bpy.data.images.new("live", 8, 8), skipped)
    group = next(n for n in tree.nodes if n.type == 'GROUP')
    assert not add_offset.inputs[0].is_linked, "the offset's constant stays"
    assert add_offset.inputs[1].links[0].from_node == reroute
    assert reroute.inputs[0].links[0].from_node == group
    assert group.inputs["UV"].links[0].from_node.uv_map == "UVMap"
    assert projected.inputs["Vector"].links[0].from_node == coordinates
    assert skipped == [projected.name], skipped

    # Another object renamed to take this one's name while live: each keeps its own image.
    first = obj
    assert bpy.ops.deformkit.uvwarp_live() == {'FINISHED'}
    first_image = addon.uvwarp._live[first.as_pointer()]["image"]
    assert first_image == "DeformKit Live grid"
    first.name = "renamed"
    second = grid_object("grid")
    second.data.uv_layers.new(name="UVMap").data.foreach_set("uv", (corners * 0.45 + 0.5).ravel())
    add("twist")
    second.deformkit.uv_rigidity = rigidity
    assert bpy.ops.deformkit.uvwarp_live() == {'FINISHED'}
    assert addon.uvwarp._live[first.as_pointer()]["image"] == first_image
    second_image = addon.uvwarp._live[second.as_pointer()]["image"]
    assert second_image != first_image, second_image
    assert bpy.data.images[second_image] != bpy.data.images[first_image]


def main():
    failures = 0
    tests = [(name, f) for name, f in sorted(globals().items()) if name.startswith("test_") and callable(f)]
    for name, test in tests:
        try:
            test()
            print(f"PASS {name}")
        except Exception:  # noqa: BLE001
            failures += 1
            print(f"FAIL {name}")
            traceback.print_exc()
    print(f"{len(tests) - failures} of {len(tests)} Blender tests passed")
    if failures:
        sys.exit(1)


main()
