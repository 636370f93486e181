"""DeformKit for Blender: DeformKit's deformer stack on mesh objects, driven by Empties, Lattices, curves and
cage meshes, with weights from vertex groups.

A thin adapter over the `deformkit` Python module's host layer (`DeformerStack`): the add-on turns Blender
data into stack parameters and writes the result back into the mesh; every deformation, envelope, weight
and rebind rule is the host layer's, the same code the command-line host and the Maya plugin run.
"""

bl_info = {
    "name": "DeformKit",
    "author": "DeformKit",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Properties > Modifiers > DeformKit",
    "description": "Slide, FFD, taper/twist/bend, wires and mesh warp deformers driven by scene objects",
    "category": "Rigging",
}

from . import evaluate, handlers, ops, props, ui, uvwarp  # noqa: E402,F401

_modules = (props, ops, ui, handlers)


def register():
    for module in _modules:
        module.register()


def unregister():
    for module in reversed(_modules):
        module.unregister()
    evaluate.clear_cache()
