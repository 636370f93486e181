"""Evaluation on frame change and on edits of controls (an Empty dragged, a lattice point moved)."""

import bpy
from bpy.app.handlers import persistent

from . import evaluate, uvwarp

_busy = False  # writing a mesh triggers another depsgraph update: do not react to our own writes


def _stacked_objects(scene):
    return [o for o in scene.objects if o.type == 'MESH' and len(o.deformkit.entries) > 0]


@persistent
def on_frame_change(scene, depsgraph=None):
    global _busy
    if _busy:
        return
    _busy = True
    try:
        for obj in _stacked_objects(scene):
            evaluate.evaluate_safely(obj, depsgraph)
        # The live UV warp follows the viewport (a render evaluates its own depsgraph and reads baked maps).
        if depsgraph is not None and depsgraph.mode == 'VIEWPORT':
            for obj in scene.objects:
                if uvwarp.live_active(obj):
                    _live_frame(obj, depsgraph)
    finally:
        _busy = False


def _live_frame(obj, depsgraph):
    try:
        uvwarp.live_update(obj, depsgraph)
    except Exception as e:  # noqa: BLE001 - the panel shows why live mode stopped
        uvwarp.stop_live(obj)
        obj.deformkit.status = f"live UV warp stopped: {e}"


@persistent
def on_depsgraph_update(scene, depsgraph):
    global _busy
    if _busy:
        return
    objects = {u.id.original.name for u in depsgraph.updates if isinstance(u.id, bpy.types.Object)}
    data = {u.id.original.name for u in depsgraph.updates
            if isinstance(u.id, (bpy.types.Lattice, bpy.types.Curve, bpy.types.Mesh))}
    # Objects whose transform changed (not only their mesh: writing the deformed positions updates that).
    moved = {u.id.original.name for u in depsgraph.updates
             if isinstance(u.id, bpy.types.Object) and u.is_updated_transform}
    if not objects and not data:
        return
    _busy = True
    try:
        for obj in _stacked_objects(scene):
            if obj.mode == 'EDIT':
                evaluate.put_off(obj)  # edited apart: evaluated, its polygons checked, on leaving
                continue
            if evaluate.take_pending(obj):
                # Back from Edit Mode, which wrote its own positions: the current frame, evaluated again.
                evaluate.evaluate_safely(obj, depsgraph, force=True)
                continue
            if obj.mode == 'WEIGHT_PAINT' and obj.name in objects:
                evaluate.mark_weights_changed(obj)
                evaluate.evaluate_safely(obj, depsgraph)
                continue
            controls = evaluate.controls(obj)
            control_data = {bpy.data.objects[c].data.name for c in controls
                            if c in bpy.data.objects and bpy.data.objects[c].data is not None}
            # A control moved, or the object itself (controls are read in its space, as Blender's
            # modifiers read theirs): evaluated again, which writes nothing when no input changed.
            if controls & objects or control_data & data or obj.name in moved:
                evaluate.evaluate_safely(obj, depsgraph)
    finally:
        _busy = False


@persistent
def on_load(*_):
    # A loaded file, an undo or a redo brings other data: the cached stacks, inputs and live solvers no
    # longer apply.
    evaluate.clear_cache()
    uvwarp.clear_live()


def register():
    bpy.app.handlers.frame_change_post.append(on_frame_change)
    bpy.app.handlers.depsgraph_update_post.append(on_depsgraph_update)
    bpy.app.handlers.load_post.append(on_load)
    bpy.app.handlers.undo_post.append(on_load)
    bpy.app.handlers.redo_post.append(on_load)


def unregister():
    for handlers, function in ((bpy.app.handlers.frame_change_post, on_frame_change),
                               (bpy.app.handlers.depsgraph_update_post, on_depsgraph_update),
                               (bpy.app.handlers.load_post, on_load), (bpy.app.handlers.undo_post, on_load),
                               (bpy.app.handlers.redo_post, on_load)):
        if function in handlers:
            handlers.remove(function)
