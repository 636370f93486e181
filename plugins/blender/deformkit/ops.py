"""Operators: add, remove and reorder stack entries (creating their controls), evaluate, reset the rest
shape. Failures are operator reports."""

import os
import pathlib
import webbrowser

import bpy
import numpy as np
from bpy.props import BoolProperty, EnumProperty, IntProperty
from mathutils import Euler, Matrix, Vector

from . import evaluate, uvwarp
from .props import DEFORMER_TYPES


def _mesh_object(context):
    obj = context.object
    return obj if obj is not None and obj.type == 'MESH' else None


def _link(context, obj, like):
    collection = like.users_collection[0] if like.users_collection else context.scene.collection
    collection.objects.link(obj)
    return obj


def _new_empty(context, owner, name, world_location, display='PLAIN_AXES', size=0.25):
    empty = bpy.data.objects.new(name, None)
    empty.empty_display_type = display
    empty.empty_display_size = size
    empty.location = world_location
    return _link(context, empty, owner)


def _unique_label(settings, base):
    labels = {e.name for e in settings.entries}
    if base not in labels:
        return base
    n = 2
    while f"{base}{n}" in labels:
        n += 1
    return f"{base}{n}"


def _bounds(points):
    lo, hi = points.min(axis=0), points.max(axis=0)
    return lo, hi, np.maximum(hi - lo, 1e-3)


def _world(obj, local):
    m = np.array(obj.matrix_world, np.float64)
    return tuple(m[:3, :3] @ np.asarray(local, np.float64) + m[:3, 3])


def _handle_vertex(context, obj, rest, from_edit_mode):
    """The selected vertex when the deformer is added from Edit Mode, else the vertex nearest the 3D
    cursor."""
    mesh = obj.data
    selected = np.zeros(len(mesh.vertices), bool)
    mesh.vertices.foreach_get("select", selected)
    if from_edit_mode and selected.any():
        return int(np.flatnonzero(selected)[0])
    cursor = evaluate.inverse_world(obj) @ np.append(np.array(context.scene.cursor.location, np.float64), 1.0)
    return int(np.argmin(((rest - cursor[:3]) ** 2).sum(axis=1)))


def setup_controls(context, obj, entry, from_edit_mode=False):
    """Creates the controls a new entry of entry.type needs, placed around the object's rest shape."""
    rest = evaluate.rest_points(obj).astype(np.float64)
    lo, hi, size = _bounds(rest)
    centre = 0.5 * (lo + hi)
    t = entry.type
    if t == "slide":
        entry.vertex = _handle_vertex(context, obj, rest, from_edit_mode)
        at = _world(obj, rest[entry.vertex])
        entry.radius = float(0.25 * size.max())
        entry.start = _new_empty(context, obj, f"{obj.name}_{entry.name}_start", at, 'SPHERE', 0.05 * size.max())
        entry.end = _new_empty(context, obj, f"{obj.name}_{entry.name}_end", at, 'PLAIN_AXES', 0.1 * size.max())
    elif t in ("taper", "twist", "bend"):
        # The handle's Y axis along the object's longest side, its units half that side.
        axis = int(np.argmax(size))
        frame = _new_empty(context, obj, f"{obj.name}_{entry.name}_handle", (0.0, 0.0, 0.0), 'ARROWS', 1.0)
        rotation = [(0.0, 0.0, -np.pi / 2), (0.0, 0.0, 0.0), (np.pi / 2, 0.0, 0.0)][axis]
        units = 0.5 * float(size[axis])
        frame.matrix_world = obj.matrix_world @ (Matrix.Translation(Vector(centre)) @
                                                 Euler(rotation).to_matrix().to_4x4() @
                                                 Matrix.Diagonal((units, units, units, 1.0)))
        entry.frame = frame
        if t == "twist":
            entry.start_value, entry.end_value = 0.0, 1.0
        elif t == "taper":
            entry.start_value, entry.end_value = 1.0, 0.5
    elif t == "ffd":
        data = bpy.data.lattices.new(f"{obj.name}_{entry.name}")
        data.points_u = data.points_v = data.points_w = 3
        lattice = bpy.data.objects.new(f"{obj.name}_{entry.name}_lattice", data)
        # Blender spaces the points of a lattice resized before it has an object one unit apart, so 3 points
        # span 2 units, not 1: scale by what the points actually span, so the lattice fits the mesh's bounds
        # padded by 2% on every axis (a flat side gets 2% of the longest one: the lattice keeps a volume).
        points = np.array([p.co for p in data.points])
        span = points.max(axis=0) - points.min(axis=0)
        extent = np.maximum(1.02 * size, 0.02 * float(size.max()))
        scale = extent / np.where(span > 0.0, span, 1.0)
        lattice.matrix_world = obj.matrix_world @ (Matrix.Translation(Vector(centre)) @
                                                   Matrix.Diagonal((*scale, 1.0)))
        entry.lattice = _link(context, lattice, obj)
    elif t == "wires":
        # A wire along the object's longest side, and its hidden rest copy.
        axis = int(np.argmax(size))
        curve_data = bpy.data.curves.new(f"{obj.name}_{entry.name}", 'CURVE')
        curve_data.dimensions = '3D'
        spline = curve_data.splines.new('POLY')
        spline.points.add(4)
        for i, p in enumerate(spline.points):
            co = centre.copy()
            co[axis] = lo[axis] + size[axis] * i / 4.0
            p.co = (*co, 1.0)
        wire = _link(context, bpy.data.objects.new(f"{obj.name}_{entry.name}_wire", curve_data), obj)
        wire.matrix_world = obj.matrix_world.copy()
        rest_wire = _link(context, bpy.data.objects.new(f"{obj.name}_{entry.name}_wire_rest",
                                                        curve_data.copy()), obj)
        rest_wire.matrix_world = obj.matrix_world.copy()
        rest_wire.hide_set(True)
        entry.curve, entry.rest_curve = wire, rest_wire
        entry.dropoff = float(0.3 * size.max())
    elif t == "meshwarp":
        # A box cage a little larger than the object, and its hidden rest copy.
        cage_mesh = bpy.data.meshes.new(f"{obj.name}_{entry.name}_cage")
        pad = 0.05 * size.max()  # on every axis, so a flat object gets a cage with volume
        a, b = lo - pad, hi + pad
        corners = [(x, y, z) for z in (a[2], b[2]) for y in (a[1], b[1]) for x in (a[0], b[0])]
        faces = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
        cage_mesh.from_pydata(corners, [], faces)
        cage = _link(context, bpy.data.objects.new(f"{obj.name}_{entry.name}_cage", cage_mesh), obj)
        cage.matrix_world = obj.matrix_world.copy()
        cage.display_type = 'WIRE'
        rest_cage = _link(context, bpy.data.objects.new(f"{obj.name}_{entry.name}_cage_rest",
                                                        cage_mesh.copy()), obj)
        rest_cage.matrix_world = obj.matrix_world.copy()
        rest_cage.hide_set(True)
        entry.cage, entry.rest_cage = cage, rest_cage


def _output_folder(settings):
    """The UV warp's Output folder as an absolute path. A '//' path is relative to the .blend file; in a
    file never saved Blender would resolve it against its working directory, wherever that is."""
    if settings.uv_output.startswith("//") and not bpy.data.filepath:
        raise evaluate.DeformKitError(
            f"Output '{settings.uv_output}' is relative to the .blend file, which is not saved yet: save it, "
            "or choose an absolute folder")
    return bpy.path.abspath(settings.uv_output)


def _in_object_mode(obj, work):
    """`work()`'s result, run with `obj` in Object Mode: the rest shape lives on the mesh, whose positions
    Blender keeps apart in Edit Mode (they are written back on leaving it). Edit Mode is entered again after."""
    from_edit_mode = obj.mode == 'EDIT'
    if from_edit_mode:
        bpy.ops.object.mode_set(mode='OBJECT')
    try:
        return work()
    finally:
        if from_edit_mode:
            bpy.ops.object.mode_set(mode='EDIT')


class DEFORMKIT_OT_add(bpy.types.Operator):
    """Add a DeformKit deformer to the active mesh, with its controls"""
    bl_idname = "deformkit.add"
    bl_label = "Add DeformKit Deformer"
    bl_options = {'REGISTER', 'UNDO'}

    type: EnumProperty(name="Type", items=[t[:3] for t in DEFORMER_TYPES])

    @classmethod
    def poll(cls, context):
        return _mesh_object(context) is not None

    def execute(self, context):
        obj = _mesh_object(context)
        settings = obj.deformkit
        if len(obj.data.vertices) == 0 and obj.mode != 'EDIT':
            self.report({'ERROR'}, f"{obj.name}: the mesh has no vertices to deform")
            return {'CANCELLED'}
        # The rest shape and the handle's selection are read from the mesh, which Blender keeps apart in
        # Edit Mode: added from there, the deformer is set up in Object Mode and Edit Mode entered again.
        from_edit_mode = obj.mode == 'EDIT'
        if from_edit_mode:
            bpy.ops.object.mode_set(mode='OBJECT')
        try:
            if len(obj.data.vertices) == 0:
                raise evaluate.DeformKitError(f"{obj.name}: the mesh has no vertices to deform")
            # Before the rest shape is taken: on a linked duplicate's mesh it would be the other stack's
            # deformation, taken as the rest of both.
            evaluate.require_own_mesh(obj)
            if len(settings.entries) == 0 or not evaluate.has_rest(obj):
                # A first entry takes the mesh as it is: a rest shape already on the mesh without entries
                # came with its data from elsewhere (objects joined into this one) and is not this mesh's.
                evaluate.capture_rest(obj)
            entry = settings.entries.add()
            try:
                # Set the label and type before anything triggers an evaluation of a half-made entry.
                entry["name"] = _unique_label(settings, self.type)
                entry["type"] = [t[0] for t in DEFORMER_TYPES].index(self.type)
                entry["envelope"] = 0.0
                setup_controls(context, obj, entry, from_edit_mode)
                entry.envelope = 1.0
            except Exception:
                # No half-made entry stays behind (controls made before the failure stay in the scene).
                settings.entries.remove(len(settings.entries) - 1)
                raise
            settings.active_index = len(settings.entries) - 1
            message = evaluate.evaluate_safely(obj)
        except Exception as e:  # noqa: BLE001 - reported to the user
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        finally:
            if from_edit_mode:
                bpy.ops.object.mode_set(mode='EDIT')
        if message:
            self.report({'WARNING'}, message)
        return {'FINISHED'}


class DEFORMKIT_OT_remove(bpy.types.Operator):
    """Remove the active DeformKit deformer (its controls stay in the scene)"""
    bl_idname = "deformkit.remove"
    bl_label = "Remove DeformKit Deformer"
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context):
        obj = _mesh_object(context)
        return obj is not None and len(obj.deformkit.entries) > 0

    def execute(self, context):
        obj = _mesh_object(context)
        return _in_object_mode(obj, lambda: self._remove(obj))

    def _remove(self, obj):
        settings = obj.deformkit
        settings.entries.remove(settings.active_index)
        settings.active_index = max(0, min(settings.active_index, len(settings.entries) - 1))
        other = evaluate.other_stack_on_mesh(obj) if len(settings.entries) == 0 else None
        if other is not None:
            # A linked duplicate's last entry: the mesh and its rest shape are the other stack's too.
            settings.status = ""
            self.report({'WARNING'}, f"{obj.name}: its mesh is also '{other}''s, whose DeformKit stack keeps "
                                     "the mesh's rest shape")
            return {'FINISHED'}
        if len(settings.entries) == 0:
            # The mesh back to its rest shape, which is then forgotten: modelling done before the next
            # deformer is added is the rest shape that deformer takes. Polygons changed under the stack leave
            # new vertices without a rest position: the mesh then keeps the shape it shows.
            kept = evaluate.rest_topology_changed(obj)
            if not kept:
                evaluate.restore_rest(obj)
            evaluate.drop_rest(obj)
            evaluate.clear_cache()
            settings.status = ""
            if kept:
                self.report({'WARNING'}, f"{obj.name}: the mesh keeps the shape it shows (its polygons changed "
                                         "since its rest shape was taken, so the rest shape cannot be put back)")
            return {'FINISHED'}
        message = evaluate.evaluate_safely(obj)
        if message:
            self.report({'WARNING'}, message)
        return {'FINISHED'}


class DEFORMKIT_OT_move(bpy.types.Operator):
    """Move the active DeformKit deformer up or down the stack (the stack runs top to bottom)"""
    bl_idname = "deformkit.move"
    bl_label = "Move DeformKit Deformer"
    bl_options = {'REGISTER', 'UNDO'}

    direction: EnumProperty(items=[("UP", "Up", ""), ("DOWN", "Down", "")])

    @classmethod
    def poll(cls, context):
        obj = _mesh_object(context)
        return obj is not None and len(obj.deformkit.entries) > 1

    def execute(self, context):
        obj = _mesh_object(context)
        settings = obj.deformkit
        i = settings.active_index
        j = i - 1 if self.direction == 'UP' else i + 1
        if not 0 <= j < len(settings.entries):
            return {'CANCELLED'}
        settings.entries.move(i, j)
        settings.active_index = j
        message = evaluate.evaluate_safely(obj)
        if message:
            self.report({'WARNING'}, message)
        return {'FINISHED'}


class DEFORMKIT_OT_evaluate(bpy.types.Operator):
    """Evaluate the active object's DeformKit stack now"""
    bl_idname = "deformkit.evaluate"
    bl_label = "Evaluate DeformKit Stack"

    @classmethod
    def poll(cls, context):
        return _mesh_object(context) is not None

    def execute(self, context):
        obj = _mesh_object(context)
        evaluate.mark_weights_changed(obj)
        message = evaluate.evaluate_safely(obj, context.evaluated_depsgraph_get(), force=True)
        if message:
            self.report({'ERROR'}, message)
            return {'CANCELLED'}
        return {'FINISHED'}


class DEFORMKIT_OT_reset_rest(bpy.types.Operator):
    """Take the mesh's current shape as its rest shape (for modelling done with every entry disabled, an
    Armature applied, polygons added or deleted): the deformers rebind to it"""
    bl_idname = "deformkit.reset_rest"
    bl_label = "Reset Rest Shape"
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context):
        obj = _mesh_object(context)
        return obj is not None and evaluate.has_rest(obj)

    def execute(self, context):
        obj = _mesh_object(context)
        return _in_object_mode(obj, lambda: self._reset(obj))

    def _reset(self, obj):
        active = [e.name for e in obj.deformkit.entries if e.enabled and e.envelope != 0.0]
        if active:
            # The mesh shows their deformation: taken as the rest, it would be deformed twice.
            self.report({'ERROR'}, f"{obj.name}: disable every entry first (the mesh shows the deformation of "
                                   f"{', '.join(active)}, not a rest shape)")
            return {'CANCELLED'}
        if evaluate.shows_deformation(obj):
            # The entries were turned off, but the mesh was not put back to its rest shape yet (or could not
            # be: its polygons changed under the stack). Taken as the rest, the deformation would be doubled.
            evaluate.evaluate_safely(obj, force=True)
            if evaluate.shows_deformation(obj):
                self.report({'ERROR'}, f"{obj.name}: the mesh still shows its deformation, which cannot be taken "
                                       f"back ({obj.deformkit.status or 'its rest shape could not be restored'})")
                return {'CANCELLED'}
        evaluate.capture_rest(obj)
        evaluate.clear_cache()
        message = evaluate.evaluate_safely(obj)
        if message:
            self.report({'WARNING'}, message)
        return {'FINISHED'}


class DEFORMKIT_OT_apply(bpy.types.Operator):
    """Keep the stack's deformation at the current frame as the mesh and remove every entry (their controls
    stay in the scene)"""
    bl_idname = "deformkit.apply"
    bl_label = "Apply DeformKit Stack"
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context):
        obj = _mesh_object(context)
        return obj is not None and len(obj.deformkit.entries) > 0 and obj.mode != 'EDIT'

    def execute(self, context):
        obj = _mesh_object(context)
        settings = obj.deformkit
        message = evaluate.evaluate_safely(obj, context.evaluated_depsgraph_get(), force=True)
        if message:
            # The mesh does not hold this frame's deformation: applying it would keep something else.
            self.report({'ERROR'}, message)
            return {'CANCELLED'}
        settings.entries.clear()
        settings.active_index = 0
        evaluate.drop_rest(obj)
        evaluate.clear_cache()
        settings.status = ""
        return {'FINISHED'}


def _scene_range(operator, context):
    """The operator's frame range: the one it was given, else the scene's (a script calling the operator
    without frames bakes the scene's range, as the button does)."""
    for name, scene_value in (("frame_start", context.scene.frame_start), ("frame_end", context.scene.frame_end)):
        if not operator.properties.is_property_set(name):
            setattr(operator, name, scene_value)


class DEFORMKIT_OT_bake_redirect(bpy.types.Operator):
    """Solve the content-aware UV warp of the active mesh over a frame range and write its redirect maps"""
    bl_idname = "deformkit.bake_redirect"
    bl_label = "Bake DeformKit Redirect Maps"

    frame_start: IntProperty(name="Start", default=1, description="First frame (not given: the scene's)")
    frame_end: IntProperty(name="End", default=1, description="Last frame (not given: the scene's)")
    # Off by default: a rigger baking again after repainting expects new maps.
    resume: BoolProperty(name="Resume", default=False,
                         description="Keep the redirect maps that exist and bake only the missing ones (after an "
                                     "interrupted bake); off: write every map again")

    @classmethod
    def poll(cls, context):
        return _mesh_object(context) is not None

    def invoke(self, context, event):
        _scene_range(self, context)
        return self.execute(context)

    def execute(self, context):
        _scene_range(self, context)
        obj = _mesh_object(context)
        settings = obj.deformkit
        if self.frame_end < self.frame_start:
            self.report({'ERROR'}, f"frame range {self.frame_start}-{self.frame_end} is empty")
            return {'CANCELLED'}
        try:
            folder = _output_folder(settings)
        except evaluate.DeformKitError as e:
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        wm = context.window_manager
        frames = range(self.frame_start, self.frame_end + 1)
        wm.progress_begin(0.0, 1.0)
        try:
            report = uvwarp.bake_redirect_maps(context, obj, settings.uv_rigidity, settings.uv_mask, frames,
                                               folder, settings.uv_resolution,
                                               self.resume, lambda done, total, _: wm.progress_update(done / total),
                                               preset=settings.uv_preset)
        except Exception as e:  # noqa: BLE001 - reported to the user
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        finally:
            wm.progress_end()
        for tile, result in report.items():
            for note in result["notes"]:  # a tile left unwarped, a mask derived
                self.report({'WARNING'}, f"tile {tile}: {note}")
            m = result["metrics"]  # of the last map written, measured on the map itself
            if m is not None:
                bad = m["inverted_triangles"] + m["off_chart_texels"]
                self.report({'WARNING'} if bad else {'INFO'},
                            f"tile {tile}, frame {result['last_written_frame']}: "
                            f"{100 * m['rigid_stretch_removed']:.1f}% of the rigid stretch removed, "
                            f"{m['inverted_triangles']} inverted triangles, {m['off_chart_texels']} off-chart texels")
        written = sum(t["written"] for t in report.values())
        kept = sum(t["replayed"] + t["skipped"] for t in report.values())
        page = next((t["report"] for t in report.values() if "report" in t), "")
        settings.uv_report = page
        self.report({'INFO'}, f"wrote {written} redirect map{'' if written == 1 else 's'} to {folder}"
                              + (f", kept {kept} that exist" if kept else "")
                              + (f"; shot report {page} (Open Report in the UV Warp panel)" if page else ""))
        return {'FINISHED'}


class DEFORMKIT_OT_open_uvwarp_report(bpy.types.Operator):
    """Open the last bake's shot report (plots over frames, heatmaps at the worst frame) in the web browser"""
    bl_idname = "deformkit.open_uvwarp_report"
    bl_label = "Open DeformKit Shot Report"

    @classmethod
    def poll(cls, context):
        obj = _mesh_object(context)
        return obj is not None and bool(obj.deformkit.uv_report)

    def execute(self, context):
        page = _mesh_object(context).deformkit.uv_report
        if not os.path.isfile(page):
            self.report({'ERROR'}, f"no shot report {page}; bake the redirect maps again")
            return {'CANCELLED'}
        webbrowser.open(pathlib.Path(page).resolve().as_uri())
        self.report({'INFO'}, f"opened {page}")
        return {'FINISHED'}


def _report_skipped(operator, material, skipped):
    """Says which image textures the redirect leaves alone (read at other coordinates than UVs)."""
    if skipped:
        operator.report({'WARNING'}, f"material '{material.name}': image textures not read at UVs (through "
                                     f"a node group, object coordinates or a constant) are left alone: "
                                     f"{', '.join(skipped)}")


class DEFORMKIT_OT_redirect_material(bpy.types.Operator):
    """Read every image texture of the active material through the baked redirect maps (tile 1001)"""
    bl_idname = "deformkit.redirect_material"
    bl_label = "Add DeformKit Redirect Nodes"
    bl_options = {'REGISTER', 'UNDO'}

    frame_start: IntProperty(name="Start", default=1, description="First frame (not given: the scene's)")
    frame_end: IntProperty(name="End", default=1, description="Last frame (not given: the scene's)")

    @classmethod
    def poll(cls, context):
        obj = _mesh_object(context)
        return obj is not None and obj.active_material is not None

    def invoke(self, context, event):
        _scene_range(self, context)
        return self.execute(context)

    def execute(self, context):
        _scene_range(self, context)
        obj = _mesh_object(context)
        try:
            first = os.path.join(_output_folder(obj.deformkit), uvwarp.redirect_name(1001, self.frame_start))
        except evaluate.DeformKitError as e:
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        if not os.path.exists(first):
            self.report({'ERROR'}, f"no redirect map {first}; bake the redirect maps first")
            return {'CANCELLED'}
        skipped = []
        try:
            uvwarp.add_redirect_nodes(obj.active_material, obj, first, self.frame_start,
                                      self.frame_end - self.frame_start + 1, skipped)
        except uvwarp.UvWarpError as e:
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        _report_skipped(self, obj.active_material, skipped)
        return {'FINISHED'}


class DEFORMKIT_OT_uvwarp_live(bpy.types.Operator):
    """Solve the content-aware UV warp on every frame change and show it through the material's image
    textures (a warm-started solver, one iteration a frame; tile 1001)"""
    bl_idname = "deformkit.uvwarp_live"
    bl_label = "Live DeformKit UV Warp"

    @classmethod
    def poll(cls, context):
        return _mesh_object(context) is not None

    def execute(self, context):
        obj = _mesh_object(context)
        if uvwarp.live_active(obj):
            uvwarp.stop_live(obj)
            self.report({'INFO'}, f"{obj.name}: live UV warp off")
            return {'FINISHED'}
        settings = obj.deformkit
        try:
            uvwarp.check_material(obj.active_material, obj)
            image = uvwarp.start_live(obj, settings.uv_rigidity, settings.uv_mask, settings.uv_resolution)
            uvwarp.live_update(obj, context.evaluated_depsgraph_get())
            skipped = []
            if obj.active_material is not None:
                uvwarp.add_live_nodes(obj.active_material, obj, image, skipped)
        except Exception as e:  # noqa: BLE001 - reported to the user
            uvwarp.stop_live(obj)
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        _report_skipped(self, obj.active_material, skipped)
        self.report({'INFO'}, f"{obj.name}: live UV warp on, {image.size[0]}² redirect map '{image.name}'")
        return {'FINISHED'}


_classes = (DEFORMKIT_OT_uvwarp_live, DEFORMKIT_OT_bake_redirect, DEFORMKIT_OT_open_uvwarp_report,
            DEFORMKIT_OT_redirect_material, DEFORMKIT_OT_add, DEFORMKIT_OT_remove, DEFORMKIT_OT_move,
            DEFORMKIT_OT_evaluate, DEFORMKIT_OT_reset_rest, DEFORMKIT_OT_apply)

register, unregister = bpy.utils.register_classes_factory(_classes)
