"""Per-object DeformKit stack: an ordered list of deformer entries with their controls and settings."""

import bpy
from bpy.props import (BoolProperty, CollectionProperty, EnumProperty, FloatProperty, IntProperty,
                       PointerProperty, StringProperty)

# (identifier = the host layer's deformer type, label, description, icon)
DEFORMER_TYPES = [
    ("slide", "Slide", "Slide the surface under a handle vertex: drag the end Empty", "EMPTY_ARROWS"),
    ("ffd", "FFD", "Free-form deformation driven by a Lattice object's points", "LATTICE_DATA"),
    ("taper", "Taper", "Barr taper along an Empty's Y axis", "MOD_SIMPLEDEFORM"),
    ("twist", "Twist", "Barr twist about an Empty's Y axis", "MOD_SIMPLEDEFORM"),
    ("bend", "Bend", "Barr bend along an Empty's Y axis towards its X axis", "MOD_SIMPLEDEFORM"),
    ("wires", "Wire", "Wires: a curve object pulls the surface near its rest copy", "CURVE_DATA"),
    ("meshwarp", "Mesh Warp", "A coarse cage mesh deforms the surface inside it", "MOD_MESHDEFORM"),
]
TYPE_ICONS = {t[0]: t[3] for t in DEFORMER_TYPES}


def _evaluate(self, context):
    # Any setting change re-evaluates the object that owns the stack (errors go to its status line).
    from . import evaluate
    obj = self.id_data
    if isinstance(obj, bpy.types.Object):
        evaluate.evaluate_safely(obj)


def _poll_empty(self, obj):
    return obj.type == 'EMPTY'


def _poll_lattice(self, obj):
    return obj.type == 'LATTICE'


def _poll_curve(self, obj):
    return obj.type == 'CURVE'


def _poll_mesh(self, obj):
    return obj.type == 'MESH' and obj != self.id_data


class DeformKitEntry(bpy.types.PropertyGroup):
    name: StringProperty(name="Label", description="Unique label of the entry in the stack", update=_evaluate)
    type: EnumProperty(name="Type", items=[t[:3] for t in DEFORMER_TYPES], update=_evaluate)
    enabled: BoolProperty(name="Enabled", default=True, update=_evaluate)
    envelope: FloatProperty(name="Envelope", description="Blend of the entry's result: 0 off, 1 full",
                            default=1.0, min=0.0, max=1.0, update=_evaluate)
    vertex_group: StringProperty(name="Weights", description="Vertex group painting the entry's weights "
                                 "(none: every vertex 1)", update=_evaluate)

    # slide
    vertex: IntProperty(name="Handle Vertex", description="The vertex the slide is centred on", min=0,
                        update=_evaluate)
    radius: FloatProperty(name="Radius", description="Support radius of the slide, scene units", default=1.0,
                          min=1e-6, update=_evaluate)
    geodesic: BoolProperty(name="Geodesic", description="Measure the region over the surface", default=True,
                           update=_evaluate)
    falloff: EnumProperty(name="Falloff", items=[("0", "Smooth", ""), ("1", "Linear", "")], update=_evaluate)
    weights_are_falloff: BoolProperty(name="Weights Are Falloff", default=False, update=_evaluate,
                                      description="The painted weights are the falloff (the paper's rule; the "
                                      "radius only bounds the region) instead of scaling it")
    fold_limit: BoolProperty(name="Fold Limit", default=False, update=_evaluate,
                             description="Scale the drag down so that no triangle of the region flips")
    start: PointerProperty(name="Start", type=bpy.types.Object, poll=_poll_empty, update=_evaluate,
                           description="Start locator (the handle's rest position)")
    end: PointerProperty(name="End", type=bpy.types.Object, poll=_poll_empty, update=_evaluate,
                         description="End locator: the slide moves the handle by end - start")

    # ffd
    lattice: PointerProperty(name="Lattice", type=bpy.types.Object, poll=_poll_lattice, update=_evaluate)
    basis: EnumProperty(name="Basis", default="LATTICE", update=_evaluate, items=[
        ("LATTICE", "As the Lattice", "The lattice's own interpolation on each axis (Linear, Cardinal, "
         "Catmull-Rom, B-Spline) with Blender's end conditions: deforms as Blender's Lattice modifier does"),
        ("0", "Bernstein", "Sederberg and Parry's polynomials; points outside the lattice stay put"),
        ("1", "B-Spline", "Uniform cubic B-spline reaching the lattice's faces; points outside stay put")])

    # taper, twist, bend
    frame: PointerProperty(name="Handle", type=bpy.types.Object, poll=_poll_empty, update=_evaluate,
                           description="Empty whose position and axes are the deformation's frame")
    start_value: FloatProperty(name="Start", description="Scale (taper) or angle (twist) at the low bound",
                               default=1.0, update=_evaluate)
    end_value: FloatProperty(name="End", description="Scale (taper) or angle (twist) at the high bound",
                             default=1.0, update=_evaluate)
    curvature: FloatProperty(name="Curvature", default=0.5, update=_evaluate,
                             description="Bend radians per handle unit: towards the Empty's X when positive, "
                             "away from it when negative, straight at 0")
    low_bound: FloatProperty(name="Low", description="Handle units along the Empty's Y axis", default=-1.0,
                             update=_evaluate)
    high_bound: FloatProperty(name="High", description="Handle units along the Empty's Y axis", default=1.0,
                              update=_evaluate)

    # wires
    curve: PointerProperty(name="Wire", type=bpy.types.Object, poll=_poll_curve, update=_evaluate)
    rest_curve: PointerProperty(name="Rest Wire", type=bpy.types.Object, poll=_poll_curve, update=_evaluate)
    dropoff: FloatProperty(name="Dropoff", description="Radius of the wire's influence", default=1.0,
                           min=1e-6, update=_evaluate)
    smooth: BoolProperty(name="Smooth", description="The smooth variant of Wires", default=True,
                         update=_evaluate)

    # mesh warp
    cage: PointerProperty(name="Cage", type=bpy.types.Object, poll=_poll_mesh, update=_evaluate)
    rest_cage: PointerProperty(name="Rest Cage", type=bpy.types.Object, poll=_poll_mesh, update=_evaluate)


class DeformKitStack(bpy.types.PropertyGroup):
    entries: CollectionProperty(type=DeformKitEntry)
    active_index: IntProperty(name="Active Entry", default=0)
    status: StringProperty(name="Status", description="The last evaluation's error, empty when it succeeded")
    # The UV warp (texture space, after the stack and the object's modifiers)
    uv_rigidity: PointerProperty(name="Rigidity", type=bpy.types.Image,
                                 description="Painted rigidity map: 1 keeps the detail at its rest size")
    uv_mask: PointerProperty(name="Mask", type=bpy.types.Image,
                             description="Warp mask: 1 may warp (none: derived from the UV charts)")
    uv_output: StringProperty(name="Output", subtype='DIR_PATH', default="//deformkit_redirect/",
                              description="Folder of the redirect maps (redirect.<tile>.<frame>.exr)")
    uv_resolution: IntProperty(name="Resolution", default=0, min=0,
                               description="Solver grid cells per side, a power of two (0: the map's texels)")
    uv_report: StringProperty(name="Shot Report", subtype='FILE_PATH',
                              description="The last bake's shot report (report.html in the output folder)")
    uv_preset: EnumProperty(name="Preset", default='shot',
                            items=(('shot', "Shot", "The default schedule, each frame from the identity: the bake"),
                                   ('live', "Live", "One warm-started iteration a frame, by grid size")),
                            description="The library's options for the bake (the live mode always runs live)")


_classes = (DeformKitEntry, DeformKitStack)


def register():
    for cls in _classes:
        bpy.utils.register_class(cls)
    bpy.types.Object.deformkit = PointerProperty(type=DeformKitStack)


def unregister():
    del bpy.types.Object.deformkit
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
