"""Commands that create each DeformKit set-up on the selection, and the DeformKit menu.

    import deformkit_maya as dk
    dk.create_slide()                 # select a mesh vertex: dkSlide with start/end locators at it
    dk.create_barr("twist")           # select meshes: dkBarr with a handle locator at their centre
    dk.create_frame_lattice((2,2,2))  # select meshes: dkFrameLattice with a locator per lattice point
    dk.create_wire()                  # select meshes, then a NURBS curve: dkWire with a rest copy
    dk.create_mesh_warp()             # select meshes, then the cage mesh: dkMeshWarp with a rest copy
    dk.create_redirect("rig.<UDIM>.exr", "maps/redirect.<UDIM>.####.exr")  # select the mesh; its file
                                      # texture <node>Map reads each frame's map

Each returns the created node. Painting: the deformers' weights are paintable (Paint Attributes tool).
"""

import maya.cmds as cmds

MENU = "deformKitMenu"


def _selected_meshes():
    shapes = cmds.ls(selection=True, dag=True, type="mesh", noIntermediate=True) or []
    if not shapes:
        cmds.error("DeformKit: select one or more meshes")
    return shapes


def create_slide(radius=1.0):
    vertices = cmds.filterExpand(selectionMask=31) or []
    if len(vertices) != 1:
        cmds.error("DeformKit: select exactly one mesh vertex as the slide's handle")
    mesh = vertices[0].split(".")[0]
    index = int(vertices[0].split("[")[-1].rstrip("]"))
    position = cmds.pointPosition(vertices[0], world=True)
    node = cmds.deformer(mesh, type="dkSlide")[0]
    cmds.setAttr(node + ".vertex", index)
    cmds.setAttr(node + ".radius", radius)
    for plug in ("startMatrix", "endMatrix"):
        source = cmds.listConnections(node + "." + plug, source=True, destination=False) or []
        for locator in source:
            cmds.xform(locator, worldSpace=True, translation=position)
    return node


def create_barr(kind="twist"):
    kinds = {"taper": 0, "twist": 1, "bend": 2}
    if kind not in kinds:
        cmds.error("DeformKit: kind must be taper, twist or bend, not %r" % kind)
    meshes = _selected_meshes()
    node = cmds.deformer(meshes, type="dkBarr")[0]
    cmds.setAttr(node + ".kind", kinds[kind])
    box = cmds.exactWorldBoundingBox(meshes)
    centre = [(box[i] + box[i + 3]) / 2.0 for i in range(3)]
    half = max((box[i + 3] - box[i]) / 2.0 for i in range(3))
    for locator in cmds.listConnections(node + ".handleMatrix", source=True, destination=False) or []:
        cmds.xform(locator, worldSpace=True, translation=centre, scale=(half, half, half))
    return node


def create_frame_lattice(divisions=(2, 2, 2)):
    meshes = _selected_meshes()
    node = cmds.deformer(meshes, type="dkFrameLattice")[0]
    cmds.setAttr(node + ".divisions", *divisions)
    box = cmds.exactWorldBoundingBox(meshes)
    size = [max(box[i + 3] - box[i], 1e-3) * 1.02 for i in range(3)]
    centre = [(box[i] + box[i + 3]) / 2.0 for i in range(3)]
    base = cmds.spaceLocator(name=node + "Base")[0]
    cmds.xform(base, worldSpace=True, translation=centre, scale=size)
    cmds.connectAttr(base + ".worldMatrix[0]", node + ".baseMatrix")
    l, m, n = divisions
    index = 0
    for i in range(l + 1):  # the host's order: (i (m + 1) + j) (n + 1) + k
        for j in range(m + 1):
            for k in range(n + 1):
                at = [centre[a] + size[a] * (t / float(d) - 0.5) for a, (t, d) in enumerate(((i, l), (j, m), (k, n)))]
                control = cmds.spaceLocator(name="%sControl%d" % (node, index))[0]
                cmds.xform(control, worldSpace=True, translation=at)
                cmds.connectAttr(control + ".worldMatrix[0]", "%s.controlMatrix[%d]" % (node, index))
                index += 1
    return node


def create_wire():
    selection = cmds.ls(selection=True) or []
    curves = [s for s in selection if cmds.listRelatives(s, shapes=True, type="nurbsCurve")]
    if not curves:
        cmds.error("DeformKit: select the meshes, then the wire curve")
    meshes = [s for s in selection if s not in curves]
    node = cmds.deformer(meshes, type="dkWire")[0]
    for i, curve in enumerate(curves):
        rest = cmds.duplicate(curve, name=curve + "Rest")[0]
        cmds.hide(rest)
        cmds.connectAttr(rest + ".worldSpace[0]", "%s.restCurve[%d]" % (node, i))
        cmds.connectAttr(curve + ".worldSpace[0]", "%s.curve[%d]" % (node, i))
    return node


def create_mesh_warp():
    selection = cmds.ls(selection=True) or []
    if len(selection) < 2:
        cmds.error("DeformKit: select the meshes, then the cage mesh")
    cage, meshes = selection[-1], selection[:-1]
    node = cmds.deformer(meshes, type="dkMeshWarp")[0]
    rest = cmds.duplicate(cage, name=cage + "Rest")[0]
    cmds.hide(rest)
    cmds.connectAttr(rest + ".worldMesh[0]", node + ".restCage")
    cmds.connectAttr(cage + ".worldMesh[0]", node + ".cage")
    return node


def create_redirect(rigidity, output, tile=1001, mask="", resolution=0, preset=""):
    """dkUvRedirect on the selected mesh's tile, and the file texture `<node>Map` that reads its map. Maya
    computes an output only when something reads it: the texture reads outFile, so the shading network (the
    renderer, a viewport material) asks for each frame's map. Connect the texture where the map is used."""
    shape = _selected_meshes()[0]
    node = cmds.createNode("dkUvRedirect")
    rest = cmds.duplicate(shape, name=shape + "UvRest")[0]
    cmds.hide(rest)
    cmds.connectAttr(cmds.listRelatives(rest, shapes=True)[0] + ".outMesh", node + ".restMesh")
    cmds.connectAttr(shape + ".outMesh", node + ".inMesh")
    cmds.connectAttr("time1.outTime", node + ".time")
    cmds.setAttr(node + ".rigidity", rigidity, type="string")
    cmds.setAttr(node + ".mask", mask, type="string")
    cmds.setAttr(node + ".output", output, type="string")
    cmds.setAttr(node + ".tile", tile)
    cmds.setAttr(node + ".resolution", resolution)
    cmds.setAttr(node + ".preset", preset, type="string")
    texture = cmds.shadingNode("file", asTexture=True, name=node + "Map")
    cmds.connectAttr(node + ".outFile", texture + ".fileTextureName")
    return node


def install_menu():
    if cmds.about(batch=True):
        return
    remove_menu()
    cmds.menu(MENU, label="DeformKit", parent="MayaWindow", tearOff=True)
    cmds.menuItem(label="Slide (select a vertex)", command=lambda *_: create_slide())
    for kind in ("taper", "twist", "bend"):
        cmds.menuItem(label=kind.title(), command=lambda *_, k=kind: create_barr(k))
    cmds.menuItem(label="Frame Lattice", command=lambda *_: create_frame_lattice())
    cmds.menuItem(label="Wire (meshes, then curve)", command=lambda *_: create_wire())
    cmds.menuItem(label="Mesh Warp (meshes, then cage)", command=lambda *_: create_mesh_warp())


def remove_menu():
    if cmds.menu(MENU, exists=True):
        cmds.deleteUI(MENU)
