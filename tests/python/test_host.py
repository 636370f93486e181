"""The host layer from Python (DeformerStack, read_scene, SceneEvaluator): a twist-then-bend stack against the
direct twist/bend calls and a numpy closed form, Maya's weight rule in numpy, bind counts, errors naming the
entry and parameter, in-place evaluation, and a scene file against a stack driven by hand."""
import json

import numpy as np
import pytest

import deformkit as dk

# A handle scaled by S (its X and Y axes as long, as the bend needs): bounds and curvature are in handle
# units, so the direct calls below take them times S (bounds) or divided by S (curvature).
S = 1.25
ORIGIN = [0.1, -0.2, 0.05]
HANDLE_X = [0.0, 0.0, -S]  # the bend's direction, perpendicular to HANDLE_Y
HANDLE_Y = [0.0, S, 0.0]
TWIST = {"startAngle": -0.4, "endAngle": 1.1, "lowBound": -0.8, "highBound": 1.0}
BEND = {"curvature": 0.6, "lowBound": -0.5, "highBound": 0.9}


def grid_mesh(nx=8, ny=12):
    """A (nx x ny)-quad sheet over x in [-0.6, 0.6], y in [-1.5, 1.5], bent out of plane by z = 0.3 x y."""
    x, y = np.meshgrid(np.linspace(-0.6, 0.6, nx + 1), np.linspace(-1.5, 1.5, ny + 1), indexing="ij")
    points = np.stack([x, y, 0.3 * x * y], axis=-1).reshape(-1, 3).astype(np.float32)
    i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
    v = (i * (ny + 1) + j).ravel()
    quads = np.stack([v, v + ny + 1, v + ny + 2, v + 1], axis=-1).ravel().astype(np.int32)
    return dk.Mesh(points, np.full(nx * ny, 4, np.int32), quads)


def twist_bend_stack(mesh, twist=TWIST, bend=BEND):
    st = dk.DeformerStack()
    st.set_rest(mesh)
    assert st.add("twist", "tw") == 0
    assert st.add("bend", "bd") == 1
    for name, value in [("handleOrigin", ORIGIN), ("handleY", HANDLE_Y), *twist.items()]:
        st.set(0, name, value)
    for name, value in [("handleOrigin", ORIGIN), ("handleX", HANDLE_X), ("handleY", HANDLE_Y), *bend.items()]:
        st.set(1, name, value)
    return st


def direct_twist(points, twist=TWIST):
    return dk.twist(points, ORIGIN, HANDLE_Y, [twist["lowBound"] * S, twist["highBound"] * S],
                    [twist["startAngle"], twist["endAngle"]])


def direct_bend(points, bend=BEND):
    return dk.bend(points, ORIGIN, HANDLE_Y, HANDLE_X, bend["curvature"] / S, 0.0, bend["lowBound"] * S,
                   bend["highBound"] * S)


def closed_form_twist(points, twist=TWIST):
    """Maya's twist as host/deformers.h documents it, in float64: the angle linear in the handle-unit
    coordinate t along handle Y from startAngle at lowBound to endAngle at highBound, held beyond, a
    right-handed rotation about handle +Y through the handle origin (Rodrigues' formula)."""
    k = np.array(HANDLE_Y) / S
    q = points.astype(np.float64) - ORIGIN
    t = np.clip(q @ k / S, twist["lowBound"], twist["highBound"])
    theta = twist["startAngle"] + (twist["endAngle"] - twist["startAngle"]) * (t - twist["lowBound"]) / (
        twist["highBound"] - twist["lowBound"])
    c, s = np.cos(theta)[:, None], np.sin(theta)[:, None]
    return ORIGIN + q * c + np.cross(k, q) * s + np.outer(q @ k, k) * (1.0 - c)


def test_deformer_types():
    assert dk.deformer_types() == sorted(dk.deformer_types())
    assert {"twist", "bend", "ffd", "slide"} <= set(dk.deformer_types())


def test_twist_then_bend_equals_the_direct_calls_in_sequence():
    mesh = grid_mesh()
    rest = mesh.points.copy()
    st = twist_bend_stack(mesh)
    assert len(st) == 2 and st.size == 2 and st.labels() == ["tw", "bd"] and st.find("bd") == 1
    out = st.evaluate(rest)
    assert out.dtype == np.float32 and out.shape == rest.shape
    twisted = direct_twist(rest)
    # Both run the same float32 kernels; they differ only by rounding: the host converts handle units in
    # double from the parameters (the direct calls get float32 samples converted here), and the host's
    # bend takes each vertex's axis coordinate from the rest mesh where the direct call takes it from the
    # twisted points (equal up to rounding: a twist about handle Y keeps the Y coordinate). Coordinates
    # are below 3 in size, so 1e-6 is about 4 float32 ulps there.
    np.testing.assert_allclose(out, direct_bend(twisted), rtol=0, atol=1e-6)
    assert np.abs(out - rest).max() > 0.3  # the deformation is not small: the comparison means something
    # The twist alone against its closed form: float32 kernels (axis coordinate, angle profile, sin/cos,
    # rotation) on coordinates below 2 in size, each off by a few ulps.
    np.testing.assert_allclose(twisted, closed_form_twist(rest), rtol=0, atol=2e-6)
    only_twist = dk.DeformerStack()
    only_twist.set_rest(mesh)
    only_twist.add("twist", "tw")
    for name, value in [("handleOrigin", ORIGIN), ("handleY", HANDLE_Y), *TWIST.items()]:
        only_twist.set(0, name, value)
    np.testing.assert_allclose(only_twist.evaluate(rest), closed_form_twist(rest), rtol=0, atol=2e-6)


def test_envelope_and_weights_follow_mayas_rule():
    mesh = grid_mesh()
    rest = mesh.points.copy()
    full = twist_bend_stack(mesh).evaluate(rest)
    rng = np.random.default_rng(5)
    w = rng.uniform(0.0, 1.0, size=len(rest)).astype(np.float32)

    st = twist_bend_stack(mesh)
    st.set_weights(1, w)
    st.set_envelope(1, 0.5)
    assert st.envelope(1) == 0.5 and st.get(1, "envelope") == [0.5]
    np.testing.assert_array_equal(st.weights(1), w)
    assert st.weights(0).shape == (0,)
    out = st.evaluate(rest)
    # The bend entry's input is the twist's output (the full stack's first stage): out = in + 0.5 w
    # (deformed - in). The host computes it in double and rounds to float once, as numpy does here from
    # the same float32 inputs, so at most 1 ulp apart.
    twist_out = st_twist_only(mesh).evaluate(rest)
    expected = twist_out.astype(np.float64) + (0.5 * w.astype(np.float64))[:, None] * (
        full.astype(np.float64) - twist_out)
    np.testing.assert_array_max_ulp(out, expected.astype(np.float32), maxulp=1)

    st.set(1, "envelope", 0.0)
    assert not st.is_active(1) and st.is_active(0)
    np.testing.assert_array_equal(st.evaluate(rest), twist_out)  # a skipped entry passes its input on
    st.set_envelope(1, 1.0)
    st.set_weights(1, np.zeros(len(rest), np.float32))
    assert not st.is_active(1)
    st.set_weights(1, None)
    assert st.is_active(1)
    np.testing.assert_array_equal(st.evaluate(rest), full)


def st_twist_only(mesh):
    st = twist_bend_stack(mesh)
    st.set_envelope(1, 0.0)
    return st


def test_animatable_changes_never_rebind_and_bind_changes_rebind_once():
    mesh = grid_mesh()
    rest = mesh.points.copy()
    st = twist_bend_stack(mesh)
    infos = {p["name"]: p for p in st.parameters(0)}
    assert st.parameters(0)[0]["name"] == "envelope"
    assert infos["handleY"]["rebinds"] and infos["handleY"]["components"] == 3
    assert not infos["endAngle"]["rebinds"] and infos["endAngle"]["components"] == 1
    assert set(infos["endAngle"]) == {"name", "components", "rebinds", "doc", "stride"}
    assert st.bind_count == 0
    st.evaluate(rest)
    assert (st.bind_count, st.bind_count_of(0), st.bind_count_of(1)) == (2, 1, 1)

    before = st.evaluate(rest)
    st.set(0, "endAngle", 0.3)
    st.set(1, "curvature", np.float32(0.2))
    after = st.evaluate(rest)
    assert st.bind_count == 2  # animatable: no bind
    np.testing.assert_array_equal(after, twist_bend_stack(mesh, {**TWIST, "endAngle": 0.3},
                                                          {**BEND, "curvature": np.float32(0.2)}).evaluate(rest))
    assert np.abs(after - before).max() > 0.1

    st.set(0, "handleY", np.array(HANDLE_Y))  # the value it has: nothing changes
    st.evaluate(rest)
    assert st.bind_count == 2
    st.set(0, "handleOrigin", [0.0, 0.0, 0.0])  # [bind]: that entry rebinds, once
    st.evaluate(rest)
    st.evaluate(rest)
    assert (st.bind_count, st.bind_count_of(0), st.bind_count_of(1)) == (3, 2, 1)
    assert st.get(0, "handleOrigin") == [0.0, 0.0, 0.0]
    st.set_rest(mesh)  # a new rest mesh rebinds every entry
    st.bind()
    st.bind()
    assert (st.bind_count, st.bind_count_of(0), st.bind_count_of(1)) == (5, 3, 2)


def test_errors_name_the_entry_and_parameter():
    mesh = grid_mesh()
    n = mesh.num_vertices
    st = twist_bend_stack(mesh)
    with pytest.raises(dk.InvalidInput, match=r"stack entry 2: deformer 'tw2': type 'twirl': is unknown.*twist"):
        st.add("twirl", "tw2")
    with pytest.raises(dk.InvalidInput, match=r"stack entry 2: label 'tw': is already used by stack entry 0"):
        st.add("taper", "tw")
    assert st.add("taper") == 2 and st.labels()[2] == "taper3"  # the scene's default label
    with pytest.raises(dk.InvalidInput, match=r"stack entry 0 \(twist 'tw'\): parameter 'endAngel': does not exist"):
        st.set(0, "endAngel", 1.0)
    with pytest.raises(dk.InvalidInput, match=r"stack entry 1 \(bend 'bd'\): parameter 'curvatur': does not exist"):
        st.get(1, "curvatur")
    with pytest.raises(dk.InvalidInput, match=r"stack entry 0 \(twist 'tw'\): parameter 'handleY': .*2 values"):
        st.set(0, "handleY", [1.0, 2.0])
    with pytest.raises(dk.InvalidInput, match=r"stack entry 0 \(twist 'tw'\): parameter 'endAngle': is a str"):
        st.set(0, "endAngle", "1.5")
    with pytest.raises(dk.InvalidInput, match=r"stack entry 0 \(twist 'tw'\): parameter 'endAngle': is a NoneType"):
        st.set(0, "endAngle", None)
    with pytest.raises(dk.InvalidInput, match=r"stack entry 0 \(twist 'tw'\): parameter 'endAngle': value 0 is nan"):
        st.set(0, "endAngle", float("nan"))
    with pytest.raises(dk.InvalidInput,
                       match=rf"stack entry 1 \(bend 'bd'\): weights: has {n - 1} values \(expected {n}, one per rest vertex\)"):
        st.set_weights(1, np.ones(n - 1, np.float32))
    with pytest.raises(dk.InvalidInput, match=r"stack entry 1 \(bend 'bd'\): weights: has shape \(2, 3\)"):
        st.set_weights(1, np.ones((2, 3), np.float32))
    with pytest.raises(dk.InvalidInput, match=r"stack entry 1 \(bend 'bd'\): weight of vertex 3: is inf"):
        st.set_weights(1, [1.0] * 3 + [float("inf")] + [1.0] * (n - 4))
    with pytest.raises(dk.InvalidInput, match=r"stack entry 0 \(twist 'tw'\): parameter 'envelope': is nan"):
        st.set_envelope(0, float("nan"))
    with pytest.raises(dk.InvalidInput, match=r"stack: entry 7: does not exist"):
        st.set(7, "endAngle", 1.0)
    # Python's from-the-end indices are not the stack's: named, not a TypeError of the int conversion.
    for call in (lambda: st.set(-1, "endAngle", 1.0), lambda: st.is_active(-1), lambda: st.weights(-1),
                 lambda: st.envelope(-1), lambda: st.type(-2)):
        with pytest.raises(dk.InvalidInput, match=r"stack: entry -\d: does not exist"):
            call()
    with pytest.raises(dk.InvalidInput, match=r"stack: deformer 'nope': does not exist.*'tw', 'bd'"):
        st.find("nope")
    with pytest.raises(dk.InvalidInput, match=r"stack: points: has 5 positions \(expected %d" % n):
        st.evaluate(np.zeros((5, 3), np.float32))
    with pytest.raises(dk.InvalidInput, match=r"DeformerStack.evaluate: points: has shape \(%d, 2\)" % n):
        st.evaluate(np.zeros((n, 2), np.float32))
    # A constraint between parameters surfaces when used, naming the entry and the parameter.
    st.set(0, "lowBound", 2.0)
    with pytest.raises(dk.InvalidInput, match=r"stack entry 0 \(twist 'tw'\): parameter 'lowBound': is 2, highBound is 1"):
        st.evaluate(mesh.points)
    with pytest.raises(dk.InvalidInput, match=r"rest mesh: is not set"):
        dk.DeformerStack().bind()


def test_evaluate_inplace_modifies_the_buffer_and_equals_evaluate():
    mesh = grid_mesh()
    rest = mesh.points.copy()
    st = twist_bend_stack(mesh)
    st.set_weights(0, np.linspace(0.0, 1.0, len(rest), dtype=np.float32))
    keep = rest.copy()
    expected = st.evaluate(rest)
    np.testing.assert_array_equal(rest, keep)  # evaluate leaves its input alone
    # Any (n, 3) array convertible to float32 goes to evaluate: float64 and nested lists of the same values.
    np.testing.assert_array_equal(st.evaluate(rest.astype(np.float64)), expected)
    np.testing.assert_array_equal(st.evaluate(rest.tolist()), expected)

    flat = rest.ravel().copy()  # a DCC's foreach_get buffer, seen as (n, 3) through a view
    buffer = flat.reshape(-1, 3)
    assert st.evaluate_inplace(buffer) is None
    np.testing.assert_array_equal(buffer, expected)
    np.testing.assert_array_equal(flat.reshape(-1, 3), expected)
    assert np.abs(buffer - rest).max() > 0.3

    for bad, problem in [(rest.astype(np.float64), "has dtype float64"), (np.asfortranarray(rest), "is not C-contiguous"),
                         (rest.tolist(), "is a list"), (rest[:, :2].copy(), r"has shape \(\d+, 2\)")]:
        with pytest.raises(dk.InvalidInput, match=r"DeformerStack.evaluate_inplace: points: " + problem):
            st.evaluate_inplace(bad)
    readonly = rest.copy()
    readonly.setflags(write=False)
    with pytest.raises(dk.InvalidInput, match="read-only"):
        st.evaluate_inplace(readonly)
    # An error at evaluation leaves the buffer as it was.
    st.set(1, "lowBound", 5.0)
    buffer[:] = rest
    with pytest.raises(dk.InvalidInput, match=r"stack entry 1 \(bend 'bd'\): parameter 'lowBound'"):
        st.evaluate_inplace(buffer)
    np.testing.assert_array_equal(buffer, rest)


def write_scene(tmp_path, mesh, weights):
    dk.write_mesh(tmp_path / "grid.obj", mesh)
    (tmp_path / "w.json").write_text(json.dumps([float(x) for x in weights]))
    scene = {
        "deformkit_scene": 1,
        "frames": [1, 11],
        "objects": [{
            "name": "grid",
            "mesh": "grid.obj",
            "stack": [
                {"type": "twist", "label": "tw", "weights": "w.json",
                 "params": {"handleOrigin": ORIGIN, "handleY": HANDLE_Y, "startAngle": TWIST["startAngle"],
                            "lowBound": TWIST["lowBound"], "highBound": TWIST["highBound"],
                            "endAngle": {"keys": [{"frame": 1, "value": 0.0, "interpolation": "linear"},
                                                  {"frame": 11, "value": 1.2}]}}},
                {"type": "bend", "label": "bd",
                 "envelope": {"keys": [{"frame": 1, "value": 0.0, "interpolation": "linear"},
                                       {"frame": 11, "value": 1.0}]},
                 "params": {"handleOrigin": ORIGIN, "handleX": HANDLE_X, "handleY": HANDLE_Y, **BEND}},
            ],
        }],
    }
    path = tmp_path / "shot.json"
    path.write_text(json.dumps(scene))
    return path


def test_scene_evaluator_matches_a_stack_driven_by_hand(tmp_path):
    mesh = grid_mesh()
    rng = np.random.default_rng(9)
    w = rng.uniform(0.2, 1.0, size=mesh.num_vertices).astype(np.float32)
    path = write_scene(tmp_path, mesh, w)

    scene = dk.read_scene(path)
    assert (scene.num_objects, scene.object_names(), scene.first_frame, scene.last_frame) == (1, ["grid"], 1, 11)
    assert [(e["type"], e["label"], e["path"]) for e in scene.entries(0)] == [
        ("twist", "tw", "objects[0].stack[0]"), ("bend", "bd", "objects[0].stack[1]")]
    np.testing.assert_array_equal(scene.rest_mesh(0).points, mesh.points)

    ev = dk.SceneEvaluator(path)
    assert ev.num_objects == 1 and ev.object_names() == ["grid"]
    assert dk.SceneEvaluator(scene).num_objects == 1
    rest = dk.read_mesh(tmp_path / "grid.obj").points.copy()  # what the scene binds to
    results = {}
    for frame in (6.0, 8.5):
        out = ev.evaluate(0, frame)
        assert out.dtype == np.float32 and out.shape == rest.shape
        # By hand: the linear keys give endAngle = 1.2 (frame - 1) / 10 and the bend's envelope (frame - 1) / 10.
        st = twist_bend_stack(mesh, {**TWIST, "endAngle": 1.2 * (frame - 1) / 10}, BEND)
        st.set_rest(dk.read_mesh(tmp_path / "grid.obj"))
        st.set_weights(0, w)
        st.set_envelope(1, (frame - 1) / 10)
        # The same kernels on the same inputs; the scene interpolates its keys in its own double arithmetic,
        # which may differ from the values computed here in the last bit of a double, far below a float32
        # ulp of the result (coordinates below 3: 1e-6 is about 4 ulps).
        np.testing.assert_allclose(out, st.evaluate(rest), rtol=0, atol=1e-6)
        assert np.abs(out - rest).max() > 0.2
        results[frame] = out
    assert ev.bind_count(0) == 2  # bound once; animated envelopes and angles never rebind
    # A frame's result does not depend on the frames evaluated before it.
    np.testing.assert_array_equal(ev.evaluate(0, 6.0), results[6.0])
    assert ev.bind_count(0) == 2

    with pytest.raises(dk.InvalidInput, match=r"shot.json: object 3: does not exist"):
        ev.evaluate(3, 1.0)
    # A frame that is no frame: named as the frame (NaN reached the curves as a bad value, inf their ends).
    for frame, text in ((float("nan"), "nan"), (float("inf"), "inf"), (-2e9, "-2e\\+09")):
        with pytest.raises(dk.InvalidInput, match=rf"shot.json: frame: is {text} \(expected a frame from -1000000000"):
            ev.evaluate(0, frame)
    with pytest.raises(dk.IoError, match="missing.json"):
        dk.SceneEvaluator(tmp_path / "missing.json")
    text = path.read_text().replace('"startAngle": -0.4', '"startAngle": "a"')
    (tmp_path / "bad.json").write_text(text)
    with pytest.raises(dk.InvalidInput, match=r"bad.json: objects\[0\].stack\[0\].params.startAngle"):
        dk.read_scene(tmp_path / "bad.json")
