"""The DeformKit panel in the Properties editor's Modifiers tab: the stack, and the active entry's controls."""

import bpy

from . import uvwarp
from .props import DEFORMER_TYPES, TYPE_ICONS


class DEFORMKIT_UL_stack(bpy.types.UIList):
    def draw_item(self, context, layout, data, item, icon, active_data, active_propname, index):
        row = layout.row(align=True)
        row.prop(item, "enabled", text="")
        row.label(text=item.name, icon=TYPE_ICONS.get(item.type, 'MODIFIER'))
        row.prop(item, "envelope", text="", slider=True)


class DEFORMKIT_MT_add(bpy.types.Menu):
    bl_label = "Add DeformKit Deformer"
    bl_idname = "DEFORMKIT_MT_add"

    def draw(self, context):
        for identifier, label, _, icon in DEFORMER_TYPES:
            self.layout.operator("deformkit.add", text=label, icon=icon).type = identifier


def _draw_entry(layout, obj, entry):
    col = layout.column()
    col.prop(entry, "name")
    col.prop(entry, "envelope", slider=True)
    col.prop_search(entry, "vertex_group", obj, "vertex_groups")
    t = entry.type
    if t == "slide":
        col.prop(entry, "start")
        col.prop(entry, "end")
        col.prop(entry, "vertex")
        col.prop(entry, "radius")
        col.prop(entry, "geodesic")
        col.prop(entry, "falloff")
        col.prop(entry, "weights_are_falloff")
        col.prop(entry, "fold_limit")
    elif t in ("taper", "twist", "bend"):
        col.prop(entry, "frame")
        if t == "bend":
            col.prop(entry, "curvature")
        else:
            col.prop(entry, "start_value", text="Start Scale" if t == "taper" else "Start Angle")
            col.prop(entry, "end_value", text="End Scale" if t == "taper" else "End Angle")
        row = col.row(align=True)
        row.prop(entry, "low_bound")
        row.prop(entry, "high_bound")
    elif t == "ffd":
        col.prop(entry, "lattice")
        col.prop(entry, "basis")
    elif t == "wires":
        col.prop(entry, "curve")
        col.prop(entry, "rest_curve")
        col.prop(entry, "dropoff")
        col.prop(entry, "smooth")
    elif t == "meshwarp":
        col.prop(entry, "cage")
        col.prop(entry, "rest_cage")


class DEFORMKIT_PT_stack(bpy.types.Panel):
    bl_label = "DeformKit"
    bl_idname = "DEFORMKIT_PT_stack"
    bl_space_type = 'PROPERTIES'
    bl_region_type = 'WINDOW'
    bl_context = "modifier"

    @classmethod
    def poll(cls, context):
        return context.object is not None and context.object.type == 'MESH'

    def draw(self, context):
        obj = context.object
        settings = obj.deformkit
        layout = self.layout
        row = layout.row()
        row.template_list("DEFORMKIT_UL_stack", "", settings, "entries", settings, "active_index", rows=3)
        buttons = row.column(align=True)
        buttons.menu("DEFORMKIT_MT_add", icon='ADD', text="")
        buttons.operator("deformkit.remove", icon='REMOVE', text="")
        buttons.separator()
        buttons.operator("deformkit.move", icon='TRIA_UP', text="").direction = 'UP'
        buttons.operator("deformkit.move", icon='TRIA_DOWN', text="").direction = 'DOWN'
        if settings.status:
            box = layout.box()
            box.alert = True
            box.label(text=settings.status, icon='ERROR')
        if 0 <= settings.active_index < len(settings.entries):
            _draw_entry(layout.box(), obj, settings.entries[settings.active_index])
        row = layout.row(align=True)
        row.operator("deformkit.evaluate", icon='FILE_REFRESH', text="Evaluate")
        row.operator("deformkit.reset_rest", text="Reset Rest")
        row.operator("deformkit.apply", icon='CHECKMARK', text="Apply")

        box = layout.box()
        box.label(text="UV Warp", icon='UV')
        col = box.column()
        col.template_ID(settings, "uv_rigidity", open="image.open", text="Rigidity")
        col.template_ID(settings, "uv_mask", open="image.open", text="Mask")
        col.prop(settings, "uv_output")
        col.prop(settings, "uv_resolution")
        col.prop(settings, "uv_preset")
        row = col.row(align=True)
        row.operator("deformkit.bake_redirect", icon='RENDER_ANIMATION', text="Bake Redirect Maps")
        # Resume keeps the maps that exist (a bake that stopped) and writes the missing ones, with the bytes an
        # uninterrupted bake writes.
        row.operator("deformkit.bake_redirect", icon='FILE_REFRESH', text="Resume").resume = True
        if settings.uv_report:
            col.operator("deformkit.open_uvwarp_report", icon='URL', text="Open Report")
        live = uvwarp.live_active(obj)
        col.operator("deformkit.uvwarp_live", icon='PAUSE' if live else 'PLAY',
                     text="Stop Live UV Warp" if live else "Live UV Warp", depress=live)
        rate = uvwarp.live_rate(obj)
        if rate is not None:
            col.label(text=f"live: {rate[0]:.1f} frames/s ({rate[1]:.0f} ms a frame)")
        row.operator("deformkit.redirect_material", icon='NODETREE', text="Redirect Material")


_classes = (DEFORMKIT_UL_stack, DEFORMKIT_MT_add, DEFORMKIT_PT_stack)

register, unregister = bpy.utils.register_classes_factory(_classes)
