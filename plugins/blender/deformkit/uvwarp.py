"""The content-aware UV warp in Blender: bake redirect maps over a frame range, and the material nodes that
read a texture through them ("DeformKit Redirect").

Maps are the `deformkit uvwarp` command's: per UDIM tile and frame a 2-channel float EXR whose texel holds
the tile-local (u', v') to read the texture at, named redirect.<tile>.<frame>.exr. Each tile's solver
warm-starts frame after frame from a cold start at the first frame, as the command-line host does.
"""

import os

import bpy
import numpy as np

from . import evaluate
from .core import dk

GROUP_NAME = "DeformKit Redirect"


class UvWarpError(Exception):
    """A problem with the object, its UVs or its maps: shown to the user."""


def redirect_name(tile, frame):
    return f"redirect.{tile}.{frame:04d}.exr"


def mesh_with_uvs(obj, points):
    """(points, counts, indices, uvs, uv_indices) of the object's mesh with its active UV map."""
    mesh = obj.data
    layer = mesh.uv_layers.active
    if layer is None:
        raise UvWarpError(f"{obj.name}: the mesh has no UV map")
    counts, indices, order = evaluate.topology(obj)
    uvs = np.empty(len(mesh.loops) * 2, np.float32)
    layer.data.foreach_get("uv", uvs)
    # One UV per face corner: corner k of the list is loop order[k].
    return points, counts, indices, uvs.reshape(-1, 2), order


def uv_tiles(counts, uvs, uv_indices):
    """The UDIM tiles the faces lie in (by UV centroid)."""
    ends = np.cumsum(counts)
    centroids = np.add.reduceat(uvs[uv_indices], ends - counts, axis=0) / counts[:, None]
    return sorted({int(1001 + np.floor(u) + 10 * np.floor(v)) for u, v in centroids})


def image_map(image, tile, role):
    """One tile of a Blender image as a (T, T) float32 map, row 0 at v = 1 (channel 0)."""
    if image.source == 'TILED':
        if image.is_dirty:
            if not image.filepath:
                raise UvWarpError(f"{role} image '{image.name}' is painted but not saved; save it first")
            image.save()
        path = bpy.path.abspath(image.filepath)
        if "<UDIM>" not in path:
            raise UvWarpError(f"{role} image '{image.name}': its file path has no <UDIM> token")
        path = path.replace("<UDIM>", str(tile))
        if not os.path.exists(path):
            raise UvWarpError(f"{role} image '{image.name}' has no tile {tile} ({path})")
        pixels = dk.read_image(path)
        return np.ascontiguousarray(pixels[:, :, 0])
    if tile != 1001:
        raise UvWarpError(f"{role} image '{image.name}' is a single image, used for tile 1001 only; the mesh "
                          f"has faces in tile {tile} (use a UDIM tiled image)")
    w, h = image.size
    if w != h or w == 0:
        raise UvWarpError(f"{role} image '{image.name}' is {w} x {h} pixels; expected a square map")
    pixels = np.empty(w * h * image.channels, np.float32)
    image.pixels.foreach_get(pixels)
    # Blender stores rows bottom-up; maps are row 0 at v = 1.
    return np.ascontiguousarray(pixels.reshape(h, w, image.channels)[::-1, :, 0])


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


def bake_redirect_maps(context, obj, rigidity, mask, frames, out_dir, resolution=0, progress=None):
    """Solves every tile over `frames` and writes the redirect maps; returns the files written."""
    scene = context.scene
    if evaluate.has_rest(obj):
        rest = evaluate.rest_points(obj)
    else:
        rest = np.empty(len(obj.data.vertices) * 3, np.float32)
        obj.data.vertices.foreach_get("co", rest)
        rest = rest.reshape(-1, 3)
    points, counts, indices, uvs, uv_indices = mesh_with_uvs(obj, rest)
    tiles = uv_tiles(counts, uvs, uv_indices)
    if rigidity is None:
        raise UvWarpError(f"{obj.name}: no rigidity map set")
    os.makedirs(out_dir, exist_ok=True)
    written = []
    current = scene.frame_current
    try:
        for t, tile in enumerate(tiles):
            solver = dk.UvWarpSolver(points, counts, indices, uvs, uv_indices, tile,
                                     image_map(rigidity, tile, "rigidity"),
                                     image_map(mask, tile, "mask") if mask is not None else None,
                                     resolution or None)
            for i, frame in enumerate(frames):
                scene.frame_set(frame)
                solver.solve(evaluated_points(obj, context.evaluated_depsgraph_get(), len(rest)))
                path = os.path.join(out_dir, redirect_name(tile, frame))
                dk.write_image(path, solver.redirect_map(), "float")
                written.append(path)
                if progress is not None:
                    progress((t * len(frames) + i + 1) / (len(tiles) * len(frames)))
    finally:
        scene.frame_set(current)
    return written


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


def add_redirect_nodes(material, first_map, frame_start, frame_count):
    """Inserts the redirect between the UVs and every image texture of `material`: a UV Map node, the
    redirect map sequence (first file `first_map`) read at the original UVs, and the group."""
    material.use_nodes = True
    tree = material.node_tree
    textures = [n for n in tree.nodes if n.type == 'TEX_IMAGE' and n.label != GROUP_NAME]
    image = bpy.data.images.load(first_map, check_existing=True)
    image.source = 'SEQUENCE'
    image.colorspace_settings.name = 'Non-Color'
    uv = tree.nodes.new('ShaderNodeUVMap')
    redirect = tree.nodes.new('ShaderNodeTexImage')
    redirect.label = GROUP_NAME
    redirect.image = image
    redirect.interpolation = 'Linear'
    redirect.extension = 'EXTEND'
    redirect.image_user.frame_start = frame_start
    redirect.image_user.frame_duration = frame_count
    redirect.image_user.frame_offset = frame_start - 1
    redirect.image_user.use_auto_refresh = True
    group = tree.nodes.new('ShaderNodeGroup')
    group.node_tree = redirect_group()
    tree.links.new(uv.outputs["UV"], redirect.inputs["Vector"])
    tree.links.new(uv.outputs["UV"], group.inputs["UV"])
    tree.links.new(redirect.outputs["Color"], group.inputs["Redirect"])
    for texture in textures:
        tree.links.new(group.outputs["UV"], texture.inputs["Vector"])
    x = min((n.location.x for n in textures), default=0.0) - 700
    uv.location, redirect.location, group.location = (x - 400, 0), (x - 200, -150), (x + 100, 0)
    return group
