"""The content-aware UV warp in Blender: bake redirect maps over a frame range, and the material nodes that
read a texture through them ("DeformKit Redirect").

The bake is the module's shot job (`uvwarp_shot`, the library's uvwarp/shot_job.h), the one `deformkit uvwarp`
and `deformkit eval` run: per UDIM tile and frame a 2-channel float EXR whose texel holds the tile-local
(u', v') to read the texture at, named redirect.<tile>.<frame>.exr, written atomically with its provenance in
the header. Each tile's solver warm-starts frame after frame from a cold start at the first frame; a resumed
bake replays the warm start and so writes the maps an uninterrupted one would.
"""

import os
import time

import bpy
import numpy as np

from . import evaluate
from .core import dk

GROUP_NAME = "DeformKit Redirect"


class UvWarpError(Exception):
    """A problem with the object, its UVs or its maps: shown to the user."""


# The bake's output files in the output folder: redirect.1001.0007.exr (tile, frame padded to 4 digits),
# the shot's log and its page (deformkit.shot_report).
REDIRECT_PATTERN = "redirect.<UDIM>.####.exr"
LOG_NAME = "uvwarp.jsonl"
REPORT_NAME = "report.html"


def redirect_name(tile, frame):
    return dk.tile_frame_path(REDIRECT_PATTERN, tile, frame)


def solved_uv_map(obj):
    """The UV map the warp is solved on: the mesh's active one (the UV editor's)."""
    layer = obj.data.uv_layers.active
    if layer is None:
        raise UvWarpError(f"{obj.name}: the mesh has no UV map")
    return layer.name


def mesh_with_uvs(obj, points):
    """(points, counts, indices, uvs, uv_indices) of the object's mesh with its active UV map."""
    mesh = obj.data
    layer = mesh.uv_layers[solved_uv_map(obj)]
    counts, indices, order = evaluate.topology(obj)
    uvs = np.empty(len(mesh.loops) * 2, np.float32)
    layer.data.foreach_get("uv", uvs)
    # One UV per face corner: corner k of the list is loop order[k].
    return points, counts, indices, uvs.reshape(-1, 2), order


def image_map(image, role):
    """A Blender image as uvwarp_shot takes a map. A UDIM tiled image: its file pattern (saved first when
    painted), each tile read from its file. A single image: tile 1001, its pixels in memory as a (T, T)
    float32 map, row 0 at v = 1 (channel 0), labelled with the image's name for messages and headers."""
    if image.source == 'TILED':
        if not image.filepath:
            raise UvWarpError(f"{role} image '{image.name}' is a UDIM image without files; save it first")
        if image.is_dirty:
            image.save()
        return bpy.path.abspath(image.filepath)
    w, h = image.size
    if w == 0 or h == 0:
        raise UvWarpError(f"{role} image '{image.name}' has no pixels (is its file missing?)")
    pixels = np.empty(w * h * image.channels, np.float32)
    image.pixels.foreach_get(pixels)
    # Blender stores rows bottom-up; maps are row 0 at v = 1.
    return (f"{role} image '{image.name}'",
            {1001: np.ascontiguousarray(pixels.reshape(h, w, image.channels)[::-1, :, 0])})


def evaluated_points(obj, depsgraph, count):
    """The object's vertex positions after DeformKit and its modifiers, in object space."""
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    try:
        if len(mesh.vertices) != count:
            raise UvWarpError(f"{obj.name}: the evaluated mesh has {len(mesh.vertices)} vertices, the rest mesh "
                              f"{count}; modifiers that change the topology (Subdivision) must come after "
                              f"the bake or be disabled")
        points = np.empty(count * 3, np.float32)
        mesh.vertices.foreach_get("co", points)
    finally:
        evaluated.to_mesh_clear()
    return points.reshape(-1, 3)


def bake_redirect_maps(context, obj, rigidity, mask, frames, out_dir, resolution=0, resume=False, progress=None,
                       preset="shot"):
    """Solves every UDIM tile of the object's UVs over `frames` (ascending) with the module's shot job and
    writes REDIRECT_PATTERN's files into out_dir. Each frame is set once and the evaluated mesh read once for
    all tiles. With the shot preset each frame is solved from the identity, so resume keeps the maps that
    exist and sets only the frames of the missing ones; otherwise every map is written again. preset: the
    library's ('shot' or 'live'). progress(done, total, unit) is uvwarp_shot's. Also writes the shot's log
    (LOG_NAME) and its HTML page (REPORT_NAME) into out_dir. Returns the job's report, {tile: dict}, each with
    'report': the page's path."""
    if obj.mode == 'EDIT':
        raise UvWarpError(f"{obj.name}: is in Edit Mode, whose mesh Blender keeps apart; bake in Object Mode")
    scene = context.scene
    if evaluate.has_rest(obj):
        rest = evaluate.rest_points(obj)
    else:
        rest = np.empty(len(obj.data.vertices) * 3, np.float32)
        obj.data.vertices.foreach_get("co", rest)
        rest = rest.reshape(-1, 3)
    mesh = mesh_with_uvs(obj, rest)
    if rigidity is None:
        raise UvWarpError(f"{obj.name}: no rigidity map set")
    os.makedirs(out_dir, exist_ok=True)
    name = f"Blender object '{obj.name}'" + (f" in {bpy.data.filepath}" if bpy.data.filepath else "")

    def deformed(frame):
        scene.frame_set(frame)
        if len(obj.deformkit.entries) > 0 and obj.deformkit.status:
            # The deformers failed at this frame: the mesh does not hold the pose the maps would be of.
            raise UvWarpError(f"frame {frame}: {obj.deformkit.status}")
        points = evaluated_points(obj, context.evaluated_depsgraph_get(), len(rest))
        return points, f"{name} evaluated at frame {frame}"

    current = scene.frame_current
    log = os.path.join(out_dir, LOG_NAME)
    if not resume and os.path.exists(log):
        os.remove(log)  # every map is written again: the log tells this bake alone
    rigidity_map = image_map(rigidity, "rigidity")
    try:
        report = dk.uvwarp_shot(*mesh, list(frames), deformed, rigidity_map,
                                os.path.join(out_dir, REDIRECT_PATTERN),
                                mask=image_map(mask, "mask") if mask is not None else None,
                                resolution=resolution or None, skip_existing=resume, progress=progress,
                                rest_name=name, preset=preset, log=log)
        # The shot's page: the evaluated object and a painted rigidity image are not files, so they are
        # handed over; the report sets the worst frames again.
        page = dk.shot_report(log, os.path.join(out_dir, REPORT_NAME), title=f"{obj.name}: UV warp bake",
                              rest=dk.Mesh(*mesh), deformed=lambda frame: deformed(frame)[0],
                              rigidity=rigidity_map[1] if isinstance(rigidity_map, tuple) else None)
        for result in report.values():
            result["report"] = page["page"]
        return report
    finally:
        scene.frame_set(current)


def redirect_group():
    """The node group mapping a UV through a redirect map sample: UV' = floor(UV) + (R, G)."""
    group = bpy.data.node_groups.get(GROUP_NAME)
    if group is not None:
        return group
    group = bpy.data.node_groups.new(GROUP_NAME, 'ShaderNodeTree')
    group.inputs.new('NodeSocketVector', "UV")
    group.inputs.new('NodeSocketColor', "Redirect")
    group.outputs.new('NodeSocketVector', "UV")
    nodes, links = group.nodes, group.links
    inputs, outputs = nodes.new('NodeGroupInput'), nodes.new('NodeGroupOutput')
    tile = nodes.new('ShaderNodeVectorMath')
    tile.operation = 'FLOOR'
    colour = nodes.new('ShaderNodeSeparateColor')
    local = nodes.new('ShaderNodeCombineXYZ')
    add = nodes.new('ShaderNodeVectorMath')
    add.operation = 'ADD'
    links.new(inputs.outputs["UV"], tile.inputs[0])
    links.new(inputs.outputs["Redirect"], colour.inputs[0])
    links.new(colour.outputs[0], local.inputs[0])
    links.new(colour.outputs[1], local.inputs[1])
    links.new(tile.outputs[0], add.inputs[0])
    links.new(local.outputs[0], add.inputs[1])
    links.new(add.outputs[0], outputs.inputs["UV"])
    for i, node in enumerate((inputs, tile, colour, local, add, outputs)):
        node.location = (200 * i, 0)
    return group


# _uv_source of a texture that already reads through the redirect group (a bake's or live nodes).
_REDIRECTED = "redirected"


def _uv_source(texture):
    """Where an image texture's coordinates come from: (the input socket its UVs enter the chain at, the
    socket giving them or None for the default UV map, the UV map's name or '' for the render map), walking
    up through Reroutes, Mapping and vector nodes; _REDIRECTED at the redirect group; None when the texture
    is not read at UVs (object coordinates, a constant, a node group or another node this walk does not
    know)."""
    socket = texture.inputs["Vector"]
    if not socket.is_linked:
        return socket, None, ""  # an image texture's own unlinked Vector reads the render UV map
    while socket.is_linked:
        link = socket.links[0]
        node, output = link.from_node, link.from_socket
        if node.type == 'UVMAP':
            return socket, output, node.uv_map
        if node.type == 'TEX_COORD':
            return (socket, output, "") if output.name == "UV" else None
        if node.type == 'GROUP' and node.node_tree is not None and node.node_tree.name == GROUP_NAME:
            return _REDIRECTED
        if node.type == 'REROUTE':
            socket = node.inputs[0]
        elif node.type in ('MAPPING', 'VECTOR_ROTATE', 'VECT_TRANSFORM'):
            socket = node.inputs["Vector"]
        elif node.type == 'VECT_MATH':
            # The vector operand the UVs come through: the one input of the first two that is linked.
            linked = [i for i in node.inputs[:2] if i.is_linked]
            if len(linked) != 1:
                return None
            socket = linked[0]
        else:
            return None
    return None  # an unlinked input inside the chain holds a constant, not the UVs


def _uv_textures(material, obj, skipped=None):
    """The material's image textures read at UVs, each with its _uv_source; raises UvWarpError for one that
    reads another UV map than the warp is solved on. The names of textures read otherwise (object
    coordinates, through a node group) go to `skipped`."""
    solved = solved_uv_map(obj)
    render = next((layer.name for layer in obj.data.uv_layers if layer.active_render), solved)
    found = []
    for node in material.node_tree.nodes if material.use_nodes else ():
        if node.type != 'TEX_IMAGE' or node.label == GROUP_NAME:
            continue
        source = _uv_source(node)
        if source is None and skipped is not None:
            skipped.append(node.name)
        if source is None or source == _REDIRECTED:
            continue
        read = source[2] or render
        if read != solved:
            raise UvWarpError(f"material '{material.name}': image texture '{node.name}' reads UV map '{read}', "
                              f"but the warp is solved on the active UV map '{solved}': make '{read}' the "
                              f"active UV map and solve again")
        found.append((node, source))
    return found


def check_material(material, obj):
    """Raises UvWarpError when the material's textures cannot be read through the warp of obj's UVs."""
    if material is not None:
        _uv_textures(material, obj)


def _insert_redirect(material, image, obj, skipped=None):
    """Reads every image texture of `material` read at UVs through `image`: the redirect nodes it has are
    pointed at it, or a UV Map node of the solved map, the redirect image read there and the group are put
    where each texture's UVs enter its chain (its Mapping and vector nodes stay after the redirect). Returns
    the redirect image node. Textures not read at UVs are left alone, their names added to `skipped`."""
    material.use_nodes = True
    existing = _redirect_nodes(material)
    for node in existing:
        node.image = image
    if existing:
        return existing[0]
    tree = material.node_tree
    textures = _uv_textures(material, obj, skipped)
    uv = tree.nodes.new('ShaderNodeUVMap')
    uv.uv_map = solved_uv_map(obj)
    redirect = tree.nodes.new('ShaderNodeTexImage')
    redirect.label = GROUP_NAME
    redirect.image = image
    redirect.interpolation = 'Linear'
    redirect.extension = 'EXTEND'
    group = tree.nodes.new('ShaderNodeGroup')
    group.node_tree = redirect_group()
    tree.links.new(uv.outputs["UV"], redirect.inputs["Vector"])
    tree.links.new(uv.outputs["UV"], group.inputs["UV"])
    tree.links.new(redirect.outputs["Color"], group.inputs["Redirect"])
    for _, (entry, _, _) in textures:
        tree.links.new(group.outputs["UV"], entry)
    x = min((node.location.x for node, _ in textures), default=0.0) - 900
    uv.location, redirect.location, group.location = (x - 400, 0), (x - 200, -150), (x + 100, 0)
    return redirect


def _redirect_nodes(material):
    tree = material.node_tree if material.use_nodes else None
    return [n for n in tree.nodes if n.type == 'TEX_IMAGE' and n.label == GROUP_NAME] if tree else []


def add_redirect_nodes(material, obj, first_map, frame_start, frame_count, skipped=None):
    """Reads every image texture of `material` read at obj's UVs through the baked redirect map sequence
    (first file `first_map`); the names of those it leaves alone go to `skipped`. Returns the group node."""
    check_material(material, obj)
    image = bpy.data.images.load(first_map, check_existing=True)
    image.source = 'SEQUENCE'
    image.colorspace_settings.name = 'Non-Color'
    redirect = _insert_redirect(material, image, obj, skipped)
    redirect.image_user.frame_start = frame_start
    redirect.image_user.frame_duration = frame_count
    redirect.image_user.frame_offset = frame_start - 1
    redirect.image_user.use_auto_refresh = True
    return next(link.to_node for link in redirect.outputs["Color"].links)


# ---- live mode: the warp solved on every frame change, shown through the material -----------------------

LIVE_IMAGE = "DeformKit Live {}"

# Per object (its address, as evaluate.py keys stacks: a renamed object stays live): its tile's solver, the
# image it fills, the last frames' times.
_live = {}


def live_active(obj):
    return obj.as_pointer() in _live


def start_live(obj, rigidity, mask, resolution):
    """Binds a warm-started solver to the object's tile and makes the image its redirect map fills on
    every frame change. Layouts in one tile only (Blender 3.4's Python cannot fill the pixels of a UDIM
    image's other tiles); UDIM layouts bake. Returns the image."""
    if rigidity is None:
        raise UvWarpError(f"{obj.name}: no rigidity map set")
    if rigidity.source == 'TILED':
        raise UvWarpError(f"{obj.name}: live mode takes a single rigidity image (tile 1001); bake UDIM maps")
    rest = evaluate.rest_points(obj) if evaluate.has_rest(obj) else None
    if rest is None:
        rest = np.empty(len(obj.data.vertices) * 3, np.float32)
        obj.data.vertices.foreach_get("co", rest)
        rest = rest.reshape(-1, 3)
    points, counts, indices, uvs, order = mesh_with_uvs(obj, rest)
    tiles = dk.Mesh(points, counts, indices, uvs, order).udim_tiles()  # the library's rule (small overhangs)
    if tiles != [1001]:
        raise UvWarpError(f"{obj.name}: live mode shows layouts in tile 1001 only; the UVs use tiles {tiles}: "
                          f"bake the redirect maps instead")
    _, rigidity_maps = image_map(rigidity, "rigidity")
    mask_map = image_map(mask, "mask")[1][1001] if mask is not None else None
    # The library's live preset: one warm-started iteration a frame, its schedule by the grid's size
    # (docs/uvwarp.md, "Performance"; docs/decisions.md UV-30).
    solver = dk.UvWarpSolver(points, counts, indices, uvs, order, 1001, rigidity_maps[1001], mask=mask_map,
                             resolution=resolution or None, preset="live")
    texels = solver.texels
    name = LIVE_IMAGE.format(obj.name)
    image = bpy.data.images.get(name)
    if image is not None and any(state["image"] == name for key, state in _live.items() if key != obj.as_pointer()):
        image = None  # another object's live image (that object was renamed since): Blender names a new one
    elif image is not None and tuple(image.size) != (texels, texels):
        bpy.data.images.remove(image)
        image = None
    if image is None:
        image = bpy.data.images.new(name, texels, texels, alpha=True, float_buffer=True, is_data=True)
    image.colorspace_settings.name = 'Non-Color'
    _live[obj.as_pointer()] = {"solver": solver, "image": image.name, "times": [], "pixels": None}
    _fill(_live[obj.as_pointer()], image, solver.redirect_map())  # the identity until the first frame change
    return image


def stop_live(obj):
    _live.pop(obj.as_pointer(), None)


def clear_live():
    _live.clear()


def _fill(state, image, redirect):
    """The redirect map (T, T, 2), row 0 at v = 1, into the image's RGBA float pixels (rows bottom-up)."""
    texels = redirect.shape[0]
    if state["pixels"] is None:
        state["pixels"] = np.ones((texels, texels, 4), np.float32)
    state["pixels"][:, :, 0:2] = redirect[::-1]
    state["pixels"][:, :, 2] = 0.0
    image.pixels.foreach_set(state["pixels"].ravel())
    image.update()


def live_points(obj, depsgraph, count):
    """The deformed points the live warp follows: the mesh as DeformKit wrote it, or, with modifiers on
    the object, the evaluated mesh (the depsgraph is brought up to date first: the handler runs before
    Blender evaluates the written mesh again)."""
    if any(m.show_viewport for m in obj.modifiers):
        depsgraph.update()
        return evaluated_points(obj, depsgraph, count)
    points = np.empty(count * 3, np.float32)
    obj.data.vertices.foreach_get("co", points)
    return points.reshape(-1, 3)


def live_update(obj, depsgraph):
    """One live frame: the warm-started solve of the deformed mesh, its redirect map into the image.
    Returns the frame's time in ms, also kept for live_rate()."""
    state = _live.get(obj.as_pointer())
    if state is None:
        return None
    image = bpy.data.images.get(state["image"])
    if image is None:  # the image was deleted: live mode ends
        stop_live(obj)
        return None
    t0 = time.perf_counter()
    solver = state["solver"]
    solver.solve(live_points(obj, depsgraph, solver.num_vertices))
    _fill(state, image, solver.redirect_map())
    ms = (time.perf_counter() - t0) * 1e3
    state["times"] = (state["times"] + [ms])[-24:]
    return ms


def live_rate(obj):
    """(frames per second, median ms) over the last frames, or None before the first."""
    state = _live.get(obj.as_pointer())
    if state is None or not state["times"]:
        return None
    ms = float(np.median(state["times"]))
    return 1000.0 / ms, ms


def add_live_nodes(material, obj, image, skipped=None):
    """Reads every image texture of `material` read at obj's UVs through the live image: the redirect node
    the material has (a bake's) is pointed at it, or the nodes are inserted; the names of textures left
    alone go to `skipped`."""
    _insert_redirect(material, image, obj, skipped)
