"""Blender data -> DeformKit host-layer parameters, and the evaluation of an object's stack.

The rest shape of a deformed object is kept in a point attribute of its mesh (`REST_ATTRIBUTE`), captured
when its first entry is added; each evaluation starts from it and writes the result into the mesh's vertex
positions. Modifiers (an Armature, say) therefore run after DeformKit, on its result.

Controls are read in the deformed object's local space (its inverse world matrix times theirs), so moving the
object moves its controls' effect with it, as Blender's own deformers behave.
"""

import hashlib

import bpy
import numpy as np

from .core import dk

REST_ATTRIBUTE = "deformkit_rest"
# The polygons the rest shape was taken on (a digest of their vertex counts and indices), kept on the mesh
# beside it: a topology edit under a stack gives new vertices no rest position, so it is refused, not read.
REST_TOPOLOGY = "deformkit_rest_topology"
# True on the mesh while its positions show a deformation (the last evaluation moved a vertex off its rest
# position): Reset Rest must not take them as the rest, and removing the stack cannot always put the rest back.
SHOWS_DEFORMATION = "deformkit_shows_deformation"

# Per object name: the stack, the entry signature it was built for, and the last weights set per entry.
_cache = {}
_pending = set()  # objects whose evaluation Edit Mode put off


class DeformKitError(Exception):
    """A problem with the Blender data (a missing control, a lattice too small): shown to the user."""


def clear_cache():
    _cache.clear()
    _pending.clear()


# ---- mesh data ----------------------------------------------------------------------------------------

def has_rest(obj):
    return REST_ATTRIBUTE in obj.data.attributes


def topology_digest(obj):
    """The mesh's polygons as a short text: vertex and polygon counts and a digest of every polygon's
    vertex indices."""
    counts, indices, _ = topology(obj)
    digest = hashlib.blake2b(counts.tobytes() + b"/" + indices.tobytes(), digest_size=16).hexdigest()
    return f"{len(obj.data.vertices)} vertices, {len(counts)} polygons, {digest}"


def capture_rest(obj):
    """Stores the mesh's current vertex positions as the rest shape, with the polygons they belong to."""
    mesh = obj.data
    points = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("co", points)
    attribute = mesh.attributes.get(REST_ATTRIBUTE)
    if attribute is None:
        attribute = mesh.attributes.new(REST_ATTRIBUTE, 'FLOAT_VECTOR', 'POINT')
    attribute.data.foreach_set("vector", points)
    mesh[REST_TOPOLOGY] = topology_digest(obj)


def drop_rest(obj):
    """Forgets the rest shape (the stack's last entry removed, or the stack applied): the next first entry
    takes the mesh as it is then, with the modelling done in between."""
    mesh = obj.data
    attribute = mesh.attributes.get(REST_ATTRIBUTE)
    if attribute is not None:
        mesh.attributes.remove(attribute)
    for key in (REST_TOPOLOGY, SHOWS_DEFORMATION):
        if key in mesh:
            del mesh[key]


def rest_topology_changed(obj):
    """True when the mesh's polygons are not those its rest shape was taken on."""
    then = obj.data.get(REST_TOPOLOGY)
    return then is not None and then != topology_digest(obj)


def shows_deformation(obj):
    """True while the mesh's positions are a deformation of its rest shape, as the last evaluation wrote them."""
    return bool(obj.data.get(SHOWS_DEFORMATION, False))


def require_rest_topology(obj):
    """Raises DeformKitError when the mesh's polygons are not those its rest shape was taken on (vertices
    added, deleted or joined under the stack). A rest shape stored without its polygons is taken as it is."""
    then = obj.data.get(REST_TOPOLOGY)
    if then is None:
        return
    now = topology_digest(obj)
    if now != then:
        before, after = then.split(',')[0], now.split(',')[0]
        counts = f"the same {after}" if before == after else f"{before} then, {after} now"
        raise DeformKitError(
            f"{obj.name}: the mesh's polygons changed since its rest shape was taken ({counts}): new vertices "
            f"have no rest position. Undo the change, disable the entries (the mesh goes back to its rest "
            f"shape), make the change and press Reset Rest; or remove every entry to keep the mesh as it is")


def require_writable_mesh(obj):
    """Raises DeformKitError for a mesh linked from a library: Blender ignores writes to its positions, so the
    object would keep the shape it was saved with."""
    library = obj.data.library
    if library is not None:
        raise DeformKitError(
            f"{obj.name}: its mesh '{obj.data.name}' is linked from '{library.filepath}', whose vertex "
            f"positions Blender does not let DeformKit write. Make the object and its mesh local (Object > "
            f"Relations > Make Local > Selected Objects and Data) or append it")


def other_stack_on_mesh(obj):
    """The name of another object with DeformKit entries that uses this object's mesh (a linked duplicate),
    or None."""
    if obj.data.users < 2:
        return None
    for other in bpy.data.objects:
        if other is not obj and other.data == obj.data and len(other.deformkit.entries) > 0:
            return other.name
    return None


def require_own_mesh(obj):
    """Raises DeformKitError when another object with DeformKit entries uses this object's mesh (a linked
    duplicate): each stack writes the mesh's positions, and the last one evaluated would win."""
    other = other_stack_on_mesh(obj)
    if other is not None:
        raise DeformKitError(
            f"{obj.name}: its mesh '{obj.data.name}' is also '{other}''s, which has DeformKit deformers "
            f"too (a linked duplicate): each stack writes the mesh's positions. Make the mesh single-user "
            f"(Object > Relations > Make Single User > Object & Data)")


def rest_points(obj):
    mesh = obj.data
    attribute = mesh.attributes.get(REST_ATTRIBUTE)
    if attribute is None:
        raise DeformKitError(f"{obj.name}: no rest shape; add a DeformKit deformer to capture it")
    points = np.empty(len(mesh.vertices) * 3, np.float32)
    attribute.data.foreach_get("vector", points)
    return points.reshape(-1, 3)


def restore_rest(obj):
    """Writes the rest shape back into the vertex positions."""
    obj.data.vertices.foreach_set("co", rest_points(obj).ravel())
    obj.data.update()


def topology(obj):
    """(face counts, vertex indices face by face, the loop index of each face corner) of the object's mesh."""
    mesh = obj.data
    counts = np.empty(len(mesh.polygons), np.int32)
    starts = np.empty(len(mesh.polygons), np.int32)
    mesh.polygons.foreach_get("loop_total", counts)
    mesh.polygons.foreach_get("loop_start", starts)
    loops = np.empty(len(mesh.loops), np.int32)
    mesh.loops.foreach_get("vertex_index", loops)
    if len(counts) == 0:
        raise DeformKitError(f"{obj.name}: the mesh has no faces")
    if np.array_equal(starts, np.concatenate(([0], np.cumsum(counts)[:-1]))):
        order = np.arange(len(loops), dtype=np.int32)  # polygons' loops in order, as usual
    else:
        order = np.concatenate([np.arange(s, s + c) for s, c in zip(starts, counts)]).astype(np.int32)
    return counts, loops[order], order


def vertex_group_weights(obj, name):
    group = obj.vertex_groups.get(name)
    if group is None:
        raise DeformKitError(f"{obj.name}: vertex group '{name}' does not exist")
    weights = np.zeros(len(obj.data.vertices), np.float32)
    index = group.index
    for vertex in obj.data.vertices:
        for element in vertex.groups:
            if element.group == index:
                weights[vertex.index] = element.weight
                break
    return weights


# ---- controls -> parameters ---------------------------------------------------------------------------

def _matrix(m):
    return np.array(m, dtype=np.float64)


def inverse_world(obj):
    """The inverse of `obj`'s world matrix; DeformKitError naming the object when it has none (a scale of 0 on
    some axis), not numpy's bare "Singular matrix"."""
    try:
        return np.linalg.inv(_matrix(obj.matrix_world))
    except np.linalg.LinAlgError:
        raise DeformKitError(f"{obj.name}: its transform has no inverse (a scale of 0 on some axis), so the "
                             "deformers' controls cannot be placed in its space") from None


def local_matrix(obj, control, depsgraph=None):
    """The control's world matrix in `obj`'s local space (evaluated when a depsgraph is given)."""
    if depsgraph is not None:
        control = control.evaluated_get(depsgraph)
        obj = obj.evaluated_get(depsgraph)
    return inverse_world(obj) @ _matrix(control.matrix_world)


def _apply(m, points):
    points = np.asarray(points, np.float64).reshape(-1, 3)
    return points @ m[:3, :3].T + m[:3, 3]


def _need(entry, attribute, what):
    control = getattr(entry, attribute)
    if control is None:
        raise DeformKitError(f"{entry.name}: no {what} set")
    if not control.original.users_scene:
        # Deleted from the scene: the entry's pointer keeps it in the file, hidden, but it is gone for the user.
        raise DeformKitError(f"{entry.name}: its {what} '{control.name}' was deleted (it is in no scene); pick "
                             f"another or add the entry again")
    return control


def mesh_points(obj):
    """A mesh object's vertex positions in its object space: from its edit mesh while it is in Edit Mode
    (Blender keeps them apart there, and its evaluated copy then lists no vertices)."""
    original = obj.original
    if original.mode == 'EDIT':
        import bmesh  # noqa: PLC0415 - Blender's module, needed only here
        edit = bmesh.from_edit_mesh(original.data)
        return np.array([v.co[:] for v in edit.verts], np.float64).reshape(-1, 3)
    return np.array([v.co[:] for v in obj.data.vertices], np.float64).reshape(-1, 3)


def curve_points(obj, curve):
    """A curve object's control points (the first spline), in object space of `curve`."""
    if not curve.data.splines:
        raise DeformKitError(f"{obj}: curve '{curve.name}' has no spline")
    spline = curve.data.splines[0]
    if spline.type == 'BEZIER':
        points = [p.co[:] for p in spline.bezier_points]
    else:
        points = [p.co[:3] for p in spline.points]
    if len(points) < 2:
        raise DeformKitError(f"{obj}: curve '{curve.name}' has fewer than 2 points")
    return np.array(points, np.float64)


# Each lattice's rest points (`co`) as last read outside Edit Mode, by its data and resolution.
_lattice_rest = {}


def lattice_points(lattice, deformed):
    """The lattice's deformed points (`co_deform`) or its rest points (`co`), u fastest. In Edit Mode Blender's
    `co` is garbage (it is computed from the point's index in the lattice's own array, and Edit Mode's points
    are another array): the rest points are then the ones last read outside Edit Mode."""
    data = lattice.data
    n = len(data.points)
    key = (data.as_pointer(), data.points_u, data.points_v, data.points_w)
    if not deformed and lattice.mode == 'EDIT':
        if key not in _lattice_rest:
            raise DeformKitError(f"lattice '{lattice.name}': its rest points cannot be read in Edit Mode; leave "
                                 "Edit Mode once so that they are")
        return _lattice_rest[key]
    points = np.empty(n * 3, np.float32)
    data.points.foreach_get("co_deform" if deformed else "co", points)
    points = points.reshape(-1, 3).astype(np.float64)
    if not deformed:
        _lattice_rest[key] = points
    return points


# Blender's lattice interpolation types as the FFD's basis codes.
_LATTICE_BASES = {"KEY_BSPLINE": 1, "KEY_LINEAR": 2, "KEY_CARDINAL": 3, "KEY_CATMULL_ROM": 4}


def entry_parameters(obj, entry, depsgraph=None):
    """The host-layer parameters of one entry, bind-time ones first (the order hosts set them in)."""
    t = entry.type
    if t == "slide":
        start = _need(entry, "start", "start locator")
        end = _need(entry, "end", "end locator")
        if entry.vertex >= len(obj.data.vertices):
            raise DeformKitError(f"{entry.name}: handle vertex {entry.vertex} is not a vertex of {obj.name}")
        a = local_matrix(obj, start, depsgraph)[:3, 3]
        b = local_matrix(obj, end, depsgraph)[:3, 3]
        return [("vertex", entry.vertex), ("radius", entry.radius), ("geodesic", int(entry.geodesic)),
                ("paintedWeights", int(entry.weights_are_falloff)), ("foldLimit", int(entry.fold_limit)),
                ("falloff", int(entry.falloff)), ("displacement", b - a)]
    if t in ("taper", "twist", "bend"):
        m = local_matrix(obj, _need(entry, "frame", "handle Empty"), depsgraph)
        params = [("handleOrigin", m[:3, 3])]
        if t == "bend":
            params.append(("handleX", m[:3, 0]))
        params.append(("handleY", m[:3, 1]))
        if t == "taper":
            params += [("startScale", entry.start_value), ("endScale", entry.end_value)]
        elif t == "twist":
            params += [("startAngle", entry.start_value), ("endAngle", entry.end_value)]
        else:
            params.append(("curvature", entry.curvature))
        return params + [("lowBound", entry.low_bound), ("highBound", entry.high_bound)]
    if t == "ffd":
        lattice = _need(entry, "lattice", "Lattice object")
        data = lattice.data
        sizes = (data.points_u, data.points_v, data.points_w)
        if min(sizes) < 2:
            raise DeformKitError(f"{entry.name}: lattice '{lattice.name}' has {sizes[0]} x {sizes[1]} x "
                                 f"{sizes[2]} points; the FFD needs at least 2 along each axis")
        m = local_matrix(obj, lattice, depsgraph)
        # The rest lattice is the regular grid of the points' `co` (u fastest in Blender's order): its corner
        # is point 0 and its edges reach the last point along each axis. Ours lists k (z) fastest.
        rest = _apply(m, lattice_points(lattice, False))
        last = [sizes[0] - 1, (sizes[1] - 1) * sizes[0], (sizes[2] - 1) * sizes[0] * sizes[1]]
        origin = rest[0]
        axes = np.concatenate([rest[i] - origin for i in last])
        deformed = _apply(m, lattice_points(lattice, True))
        deformed = deformed.reshape(sizes[2], sizes[1], sizes[0], 3).transpose(2, 1, 0, 3)
        if entry.basis == "LATTICE":
            # Blender's interpolation per axis, its repeated end controls, and every point deformed.
            bases = [_LATTICE_BASES[t] for t in (data.interpolation_type_u, data.interpolation_type_v,
                                                  data.interpolation_type_w)]
            # The lattice coordinates of the incoming points (after the entries above), every evaluation.
            options = [("basis", bases), ("outside", 1), ("ends", 1), ("evaluateAt", 1)]
        else:
            options = [("basis", int(entry.basis)), ("outside", 0), ("ends", 0), ("evaluateAt", 0)]
        return options + [("divisions", [s - 1 for s in sizes]), ("origin", origin), ("axes", axes),
                          ("points", deformed.ravel())]
    if t == "wires":
        curve = _need(entry, "curve", "wire curve")
        rest = _need(entry, "rest_curve", "rest wire curve")
        rest_points_ = _apply(local_matrix(obj, rest, depsgraph), curve_points(entry.name, rest))
        points = _apply(local_matrix(obj, curve, depsgraph), curve_points(entry.name, curve))
        if len(points) != len(rest_points_):
            raise DeformKitError(f"{entry.name}: wire '{curve.name}' has {len(points)} points, its rest "
                                 f"'{rest.name}' {len(rest_points_)}")
        return [("smooth", int(entry.smooth)), ("restCurve", rest_points_.ravel()), ("curveSizes", [0]),
                ("dropoff", [entry.dropoff]), ("curve", points.ravel())]
    if t == "meshwarp":
        cage = _need(entry, "cage", "cage mesh")
        rest = _need(entry, "rest_cage", "rest cage mesh")
        cage_points, rest_points_ = mesh_points(cage), mesh_points(rest)
        if len(cage_points) != len(rest_points_):
            raise DeformKitError(f"{entry.name}: cage '{cage.name}' has {len(cage_points)} vertices, "
                                 f"its rest '{rest.name}' {len(rest_points_)}")
        counts = [len(p.vertices) for p in rest.data.polygons]
        indices = [i for p in rest.data.polygons for i in p.vertices]
        rest_co = _apply(local_matrix(obj, rest, depsgraph), rest_points_)
        cage_co = _apply(local_matrix(obj, cage, depsgraph), cage_points)
        return [("restCage", rest_co.ravel()), ("cageFaceCounts", counts), ("cageFaceIndices", indices),
                ("cage", cage_co.ravel())]
    raise DeformKitError(f"{entry.name}: unknown deformer type '{t}'")


def controls(obj):
    """The objects whose edits change `obj`'s deformation."""
    found = set()
    for entry in obj.deformkit.entries:
        for attribute in ("start", "end", "frame", "lattice", "curve", "rest_curve", "cage", "rest_cage"):
            control = getattr(entry, attribute)
            if control is not None:
                found.add(control.name)
    return found


# ---- evaluation ---------------------------------------------------------------------------------------

def _key(obj):
    # The object itself, not its name: names are swapped and reused while objects live on.
    return obj.as_pointer()


def _shape(obj):
    # The mesh datablock (an object can be given another), its counts and three of its rest points (an
    # object made where a deleted one was may have its address, and its mesh too): a change rebuilds the
    # stack. Reading three points costs nothing; the whole rest shape is read only then.
    mesh = obj.data
    n = len(mesh.vertices)
    attribute = mesh.attributes.get(REST_ATTRIBUTE)
    samples = ()
    if attribute is not None and n > 0 and len(attribute.data) == n:
        samples = tuple(tuple(attribute.data[i].vector) for i in (0, n // 2, n - 1))
    # Three corners' vertices too: polygons edited without changing the counts (every normal flipped) are
    # noticed when such a corner changes; leaving Edit Mode rebuilds the stack, which checks every polygon
    # (put_off), as a reopened file does.
    loops = len(mesh.loops)
    corners = tuple(mesh.loops[i].vertex_index for i in (0, loops // 2, loops - 1)) if loops > 0 else ()
    return (mesh.as_pointer(), n, len(mesh.polygons), loops, samples, corners)


def put_off(obj):
    """`obj` is in Edit Mode, where Blender keeps its mesh apart: its evaluation waits for Object Mode, and
    the stack is built again then (its polygons checked against the rest shape's)."""
    _pending.add(_key(obj))


def take_pending(obj):
    """True once after an evaluation of `obj` was put off because it was in Edit Mode; its cached stack is
    dropped, so the next evaluation checks the mesh's polygons again."""
    if _key(obj) in _pending:
        _pending.discard(_key(obj))
        _cache.pop(_key(obj), None)
        return True
    return False


def _stack_for(obj):
    """The object's DeformerStack, built again only when its entries' types or labels, its mesh or the
    mesh's counts change; the rest shape is read from the mesh once, with it (Reset Rest and undo clear
    the cache)."""
    signature = tuple((e.type, e.name) for e in obj.deformkit.entries)
    cached = _cache.get(_key(obj))
    if cached is None or cached["signature"] != signature or cached["shape"] != _shape(obj):
        require_rest_topology(obj)
        stack = dk.DeformerStack()
        counts, indices, _ = topology(obj)
        rest = rest_points(obj)  # kept: reading the attribute again every frame costs 14 ms at 1M vertices
        stack.set_rest(dk.Mesh(rest, counts, indices))
        for entry in obj.deformkit.entries:
            stack.add(entry.type, entry.name)
        cached = {"signature": signature, "stack": stack, "weights": {}, "group_weights": {}, "stale_weights": {},
                  "shape": _shape(obj), "rest": rest}
        _cache[_key(obj)] = cached
    return cached


_following = set()  # objects whose entries are being renamed (their update callbacks wait)


def _follow_renamed_groups(obj, cached):
    """Entries follow a vertex group renamed since the last evaluation, as Blender's own modifiers do: the
    same groups in the same order, a name changed at its index and the old one gone. Earlier renames stay
    known to this evaluation (its evaluated entries may still hold the old name)."""
    names = [group.name for group in obj.vertex_groups]
    before = cached.get("group_names")
    cached["group_names"] = names
    if before is None or len(before) != len(names):
        return
    renamed = {old: new for old, new in zip(before, names) if old != new and old not in names}
    if not renamed:
        return
    for old, new in list(cached.setdefault("renamed", {}).items()):
        cached["renamed"][old] = renamed.get(new, new)
    cached["renamed"].update(renamed)
    _following.add(_key(obj))
    try:
        for entry in obj.deformkit.entries:
            if entry.vertex_group in renamed:
                entry.vertex_group = renamed[entry.vertex_group]
    finally:
        _following.discard(_key(obj))


def mark_weights_changed(obj):
    """Vertex-group weights are read again at the next evaluation (after weight painting)."""
    cached = _cache.get(_key(obj))
    if cached is not None:
        cached["stale_weights"] = dict(cached["group_weights"])
        cached["group_weights"].clear()


def _weights(obj, cached, name):
    # Reading a vertex group walks every vertex in Python: done once per group until the weights are
    # marked changed (the handlers do when the object is edited in Weight Paint mode).
    name = cached.get("renamed", {}).get(name, name)
    if name not in cached["group_weights"]:
        weights = vertex_group_weights(obj, name)
        stale = cached["stale_weights"].get(name)
        # Unchanged weights keep their array, so the evaluation sees no change and writes nothing.
        cached["group_weights"][name] = stale if stale is not None and np.array_equal(stale, weights) else weights
    return cached["group_weights"][name]


def _same(a, b):
    return a is not None and b is not None and len(a) == len(b) and all(
        x[0] == y[0] and x[1] == y[1] and np.array_equal(x[2], y[2]) for x, y in zip(a, b))


def evaluated_entries(obj, depsgraph=None):
    """`obj`'s entries as `depsgraph` evaluated them (the original entries without one).

    Blender writes a frame's animated values (a keyed twist angle, envelope or falloff) back into the
    original data only for the active depsgraph, the viewport's. A render's depsgraph, or another scene's,
    holds them only in its evaluated copies, whose entries also point to the evaluated controls (an Empty's
    matrix, a lattice's keyed points, a cage's evaluated mesh at that frame)."""
    if depsgraph is None:
        return obj.deformkit.entries
    return obj.evaluated_get(depsgraph).deformkit.entries


def evaluate_object(obj, depsgraph=None, force=False):
    """Evaluates `obj`'s stack on its rest shape, with every setting and control as `depsgraph` evaluated
    them, and writes the result into its vertex positions; does nothing when no input changed since the
    last evaluation (a frame change that moves no control).

    Raises DeformKitError for a problem with the Blender data and the module's errors (ValueError and its
    kind) for bad parameter values, each naming the entry."""
    if len(obj.deformkit.entries) == 0:
        return
    if obj.mode == 'EDIT':
        # Blender keeps an Edit Mode mesh apart and writes it back on leaving: positions written now
        # would be lost. The evaluation waits for Object Mode (take_pending).
        put_off(obj)
        return
    if obj.data.shape_keys is not None:
        raise DeformKitError(f"{obj.name}: the mesh has shape keys, which Blender shows in place of the vertex "
                             "positions DeformKit writes (apply or remove them, or deform a copy without them)")
    require_writable_mesh(obj)
    require_own_mesh(obj)
    cached = _stack_for(obj)
    _follow_renamed_groups(obj, cached)
    entries = evaluated_entries(obj, depsgraph)
    stack = cached["stack"]
    inputs = []
    for i, entry in enumerate(entries):
        inputs.append((i, "envelope", np.array([entry.envelope if entry.enabled else 0.0])))
        if not entry.enabled or entry.envelope == 0.0:
            continue  # a skipped entry needs no controls
        for name, value in entry_parameters(obj, entry, depsgraph):
            inputs.append((i, name, np.asarray(value, np.float64).ravel()))
        inputs.append((i, "weights", np.array([id(_weights(obj, cached, entry.vertex_group))])
                       if entry.vertex_group else np.zeros(0)))
    if not force and _same(inputs, cached.get("inputs")):
        return
    for i, entry in enumerate(entries):
        stack.set_envelope(i, entry.envelope if entry.enabled else 0.0)
    for i, name, value in inputs:
        if name == "weights":
            # Set only on a change: new weights rebind the entry.
            entry = entries[i]
            weights = _weights(obj, cached, entry.vertex_group) if entry.vertex_group else None
            previous = cached["weights"].get(i)
            if weights is not previous:
                stack.set_weights(i, weights)
                cached["weights"][i] = weights
        elif name != "envelope":
            stack.set(i, name, value)
    active = any(entry.enabled and entry.envelope != 0.0 for entry in entries)
    if not active and not shows_deformation(obj):
        # Every entry off and the mesh not showing a deformation: it shows its rest shape, or modelling done
        # on it since (the documented way to change a stacked mesh, then Reset Rest). Writing the stored
        # rest shape would throw that modelling away on leaving Edit Mode.
        cached["inputs"] = inputs
        return
    out = stack.evaluate(cached["rest"])
    obj.data.vertices.foreach_set("co", out.ravel())
    obj.data.update()
    rest = cached["rest"]
    # A sample first: a deformed mesh nearly always shows it there, without comparing every point.
    deformed = active and (not np.array_equal(out[::61], rest[::61]) or not np.array_equal(out, rest))
    if shows_deformation(obj) != deformed:
        obj.data[SHOWS_DEFORMATION] = deformed
    cached["inputs"] = inputs


def evaluate_safely(obj, depsgraph=None, force=False):
    """evaluate_object for handlers and property updates: a failure is kept in the stack's status line
    (shown in the panel) instead of raising; returns the message, or an empty string."""
    if _key(obj) in _following:
        return ""  # an entry renamed by the evaluation under way, which goes on with the new name
    try:
        evaluate_object(obj, depsgraph, force)
        message = ""
    except Exception as e:  # noqa: BLE001 - every failure reaches the panel, never only the console
        message = str(e)
    if obj.deformkit.status != message:
        obj.deformkit.status = message
    return message
