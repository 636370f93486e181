"""deformkit.slide and deformkit.Slider (Pinskiy, "Sliding deformation") against closed forms written here in
numpy: on a plane the slide is the in-plane translation d * falloff(|P - P0| / r); landings reproduce the
points; several handles add; bad input raises deformkit.InvalidInput naming the argument."""
import re
import threading

import numpy as np
import pytest

import deformkit as dk

# Float32 positions on a plane about 2 units wide: a few float ulps (the core's own plane test uses 2e-6).
TOL = 2e-6


def plane(n=40, h=0.05, rotation=np.eye(3), offset=(0.0, 0.0, 0.0)):
    """n x n quads at z = 0 (before `rotation`, then `offset`); vertex (i, j) = j (n + 1) + i."""
    j, i = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    flat = np.stack([i.ravel() * h, j.ravel() * h, np.zeros(i.size)], axis=1)
    points = (flat @ np.asarray(rotation).T + np.asarray(offset)).astype(np.float32)
    a = (np.arange(n)[:, None] * (n + 1) + np.arange(n)[None, :]).ravel()
    faces = np.stack([a, a + 1, a + n + 2, a + n + 1], axis=1).astype(np.int32)
    return points, np.full(n * n, 4, dtype=np.int32), faces.ravel()


def rotation(angle=0.7, axis=(0.3, -0.5, 0.8)):
    k = np.asarray(axis, dtype=np.float64)
    k /= np.linalg.norm(k)
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * kx + (1 - np.cos(angle)) * kx @ kx  # Rodrigues


def smoothstep_falloff(x):
    x = np.asarray(x, dtype=np.float64)
    return np.where(x < 1.0, 1.0 - x * x * (3.0 - 2.0 * x), 0.0)


def distances(points, handle):
    return np.linalg.norm(points.astype(np.float64) - points[handle].astype(np.float64), axis=1)


def check_moved_set(moved, *normalized):
    """Vertices clearly inside a region (x < 1 - 1e-6) move and none clearly outside (x > 1 + 1e-6) does; the
    core keeps x in float32, so a vertex within rounding of the edge (where the falloff is ~0) may go either way."""
    inside = np.logical_or.reduce([x < 1 - 1e-6 for x in normalized])
    near = np.logical_or.reduce([x <= 1 + 1e-6 for x in normalized])
    moved_mask = np.zeros(len(inside), dtype=bool)
    moved_mask[moved] = True
    assert np.all(moved_mask[inside]) and not np.any(moved_mask & ~near)
    assert inside.sum() > 100


ROT = rotation()
HANDLE = 20 * 41 + 20


def test_plane_translation_is_d_times_smoothstep():
    pts, counts, idx = plane(rotation=ROT, offset=(0.3, -1.2, 0.5))
    d = ROT @ np.array([0.07, 0.04, 0.0])
    out = dk.slide(pts, counts, idx, HANDLE, d.astype(np.float32), 0.6)
    assert out.dtype == np.float32 and out.shape == pts.shape
    f = smoothstep_falloff(distances(pts, HANDLE) / 0.6)
    expected = pts + f[:, None] * d.astype(np.float32).astype(np.float64)
    assert (f > 0).sum() > 300  # the region covers many vertices
    np.testing.assert_allclose(out, expected, atol=TOL)
    np.testing.assert_array_equal(out[f == 0], pts[f == 0])  # outside the radius: untouched bits


def test_linear_falloff_weights_and_envelope():
    pts, counts, idx = plane(30, 0.05)
    handle = 15 * 31 + 15
    d = np.array([0.05, -0.03, 0.0], dtype=np.float32)
    w = np.random.default_rng(3).uniform(0, 1, len(pts)).astype(np.float32)
    out = dk.slide(pts, counts, idx, handle, d, 0.5, falloff="linear", weights=w, envelope=0.5)
    x = distances(pts, handle) / 0.5
    f = np.where(x < 1, 1 - x, 0) * w * 0.5
    np.testing.assert_allclose(out, pts + f[:, None] * d, atol=TOL)


def test_falloff_samples_are_a_linear_ramp_over_distance_by_radius():
    pts, counts, idx = plane(30, 0.05)
    handle = 15 * 31 + 15
    d = np.array([0.04, 0.02, 0.0], dtype=np.float32)
    samples = [1.0, 1.0, 0.5, 0.0]  # at x = 0, 1/3, 2/3, 1: flat top, then down to zero
    x = distances(pts, handle) / 0.6
    f = np.interp(x, [0, 1 / 3, 2 / 3, 1], samples, right=0.0)
    for given in (samples, np.array(samples, dtype=np.float32), tuple(samples)):
        out = dk.slide(pts, counts, idx, handle, d, 0.6, falloff=given)
        np.testing.assert_allclose(out, pts + f[:, None] * d, atol=TOL)
    with pytest.raises(dk.InvalidInput, match="^slide: falloff: sample 1: is 1.5"):
        dk.slide(pts, counts, idx, handle, d, 0.6, falloff=[1.0, 1.5, 0.0])  # a sample above 1
    with pytest.raises(dk.InvalidInput, match="falloff"):
        dk.slide(pts, counts, idx, handle, d, 0.6, falloff=[1.0])  # one sample is no ramp
    with pytest.raises(dk.InvalidInput, match="falloff.*'cubic'"):
        dk.slide(pts, counts, idx, handle, d, 0.6, falloff="cubic")
    with pytest.raises(dk.InvalidInput, match=r"falloff: has shape \(2, 2\)"):
        dk.slide(pts, counts, idx, handle, d, 0.6, falloff=[[1.0, 0.0], [1.0, 0.0]])
    with pytest.raises(dk.InvalidInput, match="falloff: is a NoneType"):
        dk.slide(pts, counts, idx, handle, d, 0.6, falloff=None)
    with pytest.raises(dk.InvalidInput, match="falloff: is a list that is not numeric"):
        dk.slide(pts, counts, idx, handle, d, 0.6, falloff=["a", "b"])


def test_slider_result_fields_are_consistent():
    pts, counts, idx = plane(rotation=ROT)
    slider = dk.Slider(pts, counts, idx, handle=HANDLE, radius=0.6)
    d = (ROT @ np.array([0.06, -0.05, 0.0])).astype(np.float32)
    r = slider.evaluate(d)
    f = smoothstep_falloff(distances(pts, HANDLE) / 0.6)
    check_moved_set(r.vertices, distances(pts, HANDLE) / 0.6)
    assert r.points.dtype == np.float32 and r.points.shape == pts.shape
    np.testing.assert_allclose(r.points, pts + f[:, None] * d.astype(np.float64), atol=TOL)
    assert r.vertices.dtype == np.int32 and r.faces.dtype == np.int32 and r.triangles.dtype == np.int32
    assert r.barycentric.dtype == np.float64
    m = r.moved
    assert r.vertices.shape == (m,) and r.faces.shape == (m,) and r.triangles.shape == (m, 3)
    assert r.barycentric.shape == (m, 3)
    assert np.all(np.diff(r.vertices) > 0)  # ascending
    assert (r.moved, r.boundary_stopped, r.walk_limit_stopped, r.unreachable) == (m, 0, 0, 0)
    assert (r.degenerate_triangles, r.without_tangent_plane) == (0, 0)
    # The slid point is the barycentric combination of its triangle's rest corners (double here).
    rebuilt = np.einsum("mk,mkc->mc", r.barycentric, pts[r.triangles].astype(np.float64))
    np.testing.assert_allclose(rebuilt, r.points[r.vertices], atol=1e-6)
    np.testing.assert_allclose(r.barycentric.sum(axis=1), 1.0, atol=1e-12)
    assert np.all(r.barycentric >= -1e-12)
    # Each triangle belongs to its face: its three vertices are corners of that polygon.
    poly = idx.reshape(-1, 4)
    assert all(set(t) <= set(poly[fc]) for t, fc in zip(r.triangles.tolist(), r.faces.tolist()))
    # Bind data: the active vertices are those within the radius, and the region says so too.
    np.testing.assert_array_equal(slider.active_vertices, np.flatnonzero(distances(pts, HANDLE) <= 0.6))
    region = slider.region(0)
    assert region["vertex"] == HANDLE and region["radius"] == 0.6 and region["region"] == "euclidean"
    assert region["vertices"][0] == HANDLE
    np.testing.assert_allclose(region["normalized_distance"], distances(pts, HANDLE)[region["vertices"]] / 0.6,
                               atol=1e-6)
    assert slider.num_vertices == len(pts) and slider.num_handles == 1
    assert slider.handles == [{"vertex": HANDLE, "radius": 0.6, "region": "euclidean"}]


def test_slider_evaluates_again_and_moves_given_points():
    pts, counts, idx = plane()
    slider = dk.Slider(pts, counts, idx, handle=HANDLE, radius=0.6)
    d1 = np.array([0.05, 0.0, 0.0], dtype=np.float32)
    d2 = np.array([0.0, -0.04, 0.0], dtype=np.float32)
    f = smoothstep_falloff(distances(pts, HANDLE) / 0.6)
    np.testing.assert_allclose(slider.evaluate(d1).points, pts + f[:, None] * d1, atol=TOL)
    np.testing.assert_allclose(slider.evaluate(d2, envelope=0.5).points, pts + 0.5 * f[:, None] * d2, atol=TOL)
    # points: the surface to slide over, e.g. the output of an earlier deformer; lifted, it slides lifted.
    lifted = pts + np.float32([0, 0, 1])
    np.testing.assert_allclose(slider.evaluate(d1, points=lifted).points, lifted + f[:, None] * d1, atol=TOL)
    np.testing.assert_array_equal(slider.evaluate(np.zeros(3, np.float32)).points, pts)
    np.testing.assert_allclose(dk.slide(pts, counts, idx, HANDLE, d1, 0.6), slider.evaluate(d1).points, atol=0)


def test_slider_slides_over_the_points_it_is_given():
    """Equivariance: over the rest plane turned by R and moved by t, a drag d slides like R^T d at rest, turned
    and moved: the drag is read in the space of the given points and the result lies on them."""
    pts, counts, idx = plane()
    slider = dk.Slider(pts, counts, idx, handle=HANDLE, radius=0.6)
    t = np.array([0.4, -1.0, 2.0])
    moved = (pts.astype(np.float64) @ ROT.T + t).astype(np.float32)
    d = ROT @ np.array([0.05, 0.03, 0.0])
    over = slider.evaluate(d.astype(np.float32), points=moved)
    at_rest = slider.evaluate((ROT.T @ d).astype(np.float32))
    np.testing.assert_allclose(over.points, at_rest.points.astype(np.float64) @ ROT.T + t, atol=5e-6)
    # On the given surface: the landing's barycentric combination of the given points.
    rebuilt = np.einsum("mk,mkc->mc", over.barycentric, moved[over.triangles].astype(np.float64))
    np.testing.assert_allclose(rebuilt, over.points[over.vertices], atol=1e-6)


def test_painted_weights_rule_fold_count_and_fold_limit():
    pts, counts, idx = plane()
    w = np.clip(0.2 + 0.3 * pts[:, 0], 0, 1).astype(np.float32)
    d = np.array([0.05, 0.03, 0.0], dtype=np.float32)
    inside = distances(pts, HANDLE) <= 0.6
    # The paper's rule: the weight is the falloff inside the radius.
    out = dk.slide(pts, counts, idx, HANDLE, d, 0.6, weights=w, painted_weights="falloff")
    np.testing.assert_allclose(out, pts + (w * inside)[:, None] * d, atol=TOL)
    out = dk.slide(pts, counts, idx, HANDLE, d, 0.6, weights=w)  # default: weight x falloff
    np.testing.assert_allclose(out, pts + (w * smoothstep_falloff(distances(pts, HANDLE) / 0.6))[:, None] * d,
                               atol=TOL)
    with pytest.raises(dk.InvalidInput, match="painted_weights"):
        dk.slide(pts, counts, idx, HANDLE, d, 0.6, painted_weights="paper")
    # A drag of 0.8 r folds the smooth falloff (it folds past r / 1.5); the fold limit scales it to about 0.833.
    big = np.array([0.48, 0.0, 0.0], dtype=np.float32)
    r = dk.Slider(pts, counts, idx, handle=HANDLE, radius=0.6).evaluate(big)
    assert r.flipped_triangles > 0 and r.limited == 0
    np.testing.assert_array_equal(r.fold_scale, [1.0])
    r = dk.Slider(pts, counts, idx, handle=HANDLE, radius=0.6, fold_limit=True).evaluate(big)
    assert r.flipped_triangles == 0
    assert r.fold_scale.shape == (1,) and abs(r.fold_scale[0] - 0.4 / 0.48) < 0.04


def test_several_handles_add_their_slides():
    pts, counts, idx = plane(rotation=ROT)
    h1, h2 = 15 * 41 + 12, 22 * 41 + 25
    d = (np.array([[0.04, 0.0, 0.0], [-0.01, 0.05, 0.0]]) @ ROT.T).astype(np.float32)
    slider = dk.Slider(pts, counts, idx, handles=[{"vertex": h1, "radius": 0.5},
                                                  {"vertex": h2, "radius": 0.4, "region": "euclidean"}])
    r = slider.evaluate(d, falloff=["smooth", "linear"])
    f1 = smoothstep_falloff(distances(pts, h1) / 0.5)
    x2 = distances(pts, h2) / 0.4
    f2 = np.where(x2 < 1, 1 - x2, 0)
    np.testing.assert_allclose(r.points, pts + f1[:, None] * d[0] + f2[:, None] * d[1], atol=TOL)
    assert r.moved == len(r.vertices)
    check_moved_set(r.vertices, distances(pts, h1) / 0.5, x2)
    np.testing.assert_array_equal(slider.active_vertices,
                                  np.flatnonzero((distances(pts, h1) <= 0.5) | (distances(pts, h2) <= 0.4)))
    # One falloff for both: a ramp given once applies to every handle.
    ramp = [1.0, 0.0]  # = linear
    r = slider.evaluate(d, falloff=ramp)
    x1 = distances(pts, h1) / 0.5
    f1 = np.where(x1 < 1, 1 - x1, 0)
    np.testing.assert_allclose(r.points, pts + f1[:, None] * d[0] + f2[:, None] * d[1], atol=TOL)
    with pytest.raises(dk.InvalidInput, match=r"displacement.*\(2, 3\)"):
        slider.evaluate(d[0])
    with pytest.raises(dk.InvalidInput, match="falloff.*one per handle"):
        slider.evaluate(d, falloff=["smooth", "linear", "smooth"])


def test_geodesic_region_and_boundary_stops():
    pts, counts, idx = plane(20, 0.05)  # the unit square
    handle = 10 * 21 + 15  # (0.75, 0.5)
    d = np.array([0.6, 0.0, 0.0], dtype=np.float32)  # pushes the region over x = 1
    r = dk.Slider(pts, counts, idx, handle=handle, radius=0.5, region="geodesic").evaluate(d)
    f = smoothstep_falloff(distances(pts, handle) / 0.5)  # on a plane the geodesic distance is Euclidean
    expected = pts + f[:, None] * d.astype(np.float64)
    over = (f > 0) & (expected[:, 0] > 1.0)
    expected[over, 0] = 1.0  # stops where its straight path meets the boundary
    assert over.sum() > 10
    assert r.boundary_stopped == over.sum()
    np.testing.assert_allclose(r.points, expected, atol=TOL)


def test_limit_surface_keeps_a_flat_grid_flat():
    # The Catmull-Clark limit of a flat grid is its plane (bilinear inside): a slide on it stays in z = 0
    # and, away from the boundary's influence, is the same translation.
    pts, counts, idx = plane(30, 0.1)
    handle = 15 * 31 + 15
    d = np.array([0.1, 0.05, 0.0], dtype=np.float32)
    out = dk.slide(pts, counts, idx, handle, d, 0.8, surface="limit")
    f = smoothstep_falloff(distances(pts, handle) / 0.8)
    np.testing.assert_allclose(out[:, 2], 0.0, atol=1e-6)
    np.testing.assert_allclose(out, pts + f[:, None] * d, atol=1e-5)


def test_bad_input_names_the_argument():
    pts, counts, idx = plane(4, 0.25)
    d = np.array([0.1, 0.0, 0.0], dtype=np.float32)
    with pytest.raises(dk.InvalidInput, match=r"handle 0 \(vertex 25\).*out of range"):
        dk.slide(pts, counts, idx, 25, d, 0.5)
    with pytest.raises(dk.InvalidInput, match="out of range"):
        dk.slide(pts, counts, idx, 2**40, d, 0.5)
    with pytest.raises(dk.InvalidInput, match=r"weights.*\(3,\).*\(25,\)"):
        dk.slide(pts, counts, idx, 12, d, 0.5, weights=np.ones(3, dtype=np.float32))
    with pytest.raises(dk.InvalidInput, match="region.*'manhattan'.*'euclidean' or 'geodesic'"):
        dk.slide(pts, counts, idx, 12, d, 0.5, region="manhattan")
    with pytest.raises(dk.InvalidInput, match="surface.*'smooth'"):
        dk.slide(pts, counts, idx, 12, d, 0.5, surface="smooth")
    with pytest.raises(dk.InvalidInput, match="radius"):
        dk.slide(pts, counts, idx, 12, d, 0.0)
    with pytest.raises(dk.InvalidInput, match=r"displacement.*\(2,\)"):
        dk.slide(pts, counts, idx, 12, d[:2], 0.5)
    with pytest.raises(dk.InvalidInput, match="displacement.*not finite"):
        dk.slide(pts, counts, idx, 12, np.float32([np.inf, 0, 0]), 0.5)
    with pytest.raises(dk.InvalidInput, match="points"):
        dk.slide(pts[:, :2], counts, idx, 12, d, 0.5)
    with pytest.raises(dk.Error):
        dk.slide(pts, counts, idx[:-1], 12, d, 0.5)  # the faces want one more index

    with pytest.raises(dk.InvalidInput, match=r"Slider: radius: is missing \(expected a radius with handle 5\)"):
        dk.Slider(pts, counts, idx, handle=5)
    with pytest.raises(dk.InvalidInput, match=r"Slider: handle: is missing \(expected a handle vertex"):
        dk.Slider(pts, counts, idx, radius=0.5)
    with pytest.raises(dk.InvalidInput, match=r"Slider.evaluate: points: has 3 rows \(expected 25, one per vertex\)"):
        dk.Slider(pts, counts, idx, handle=5, radius=0.5).evaluate(d, points=pts[:3])
    with pytest.raises(dk.InvalidInput, match="handles\\[1\\].radius.*missing"):
        dk.Slider(pts, counts, idx, handles=[{"vertex": 1, "radius": 0.5}, {"vertex": 2}])
    with pytest.raises(dk.InvalidInput, match="handles\\[0\\].*'radious'"):
        dk.Slider(pts, counts, idx, handles=[{"vertex": 1, "radious": 0.5}])
    # Each value named by its path (all were "handles[0]: has a value of the wrong type"); bools are not
    # numbers; numpy scalars are.
    for handle, where in (({"vertex": 40.7, "radius": 0.5}, r"handles\[0\]\.vertex: is a float \(expected an int\)"),
                          ({"vertex": True, "radius": 0.5}, r"handles\[0\]\.vertex: is a bool"),
                          ({"vertex": 1, "radius": True}, r"handles\[0\]\.radius: is a bool \(expected a number\)"),
                          ({"vertex": 1, "radius": "0.5"}, r"handles\[0\]\.radius: is a str"),
                          ({"vertex": 1, "radius": 0.5, "region": 3}, r"handles\[0\]\.region: is an int")):
        with pytest.raises(dk.InvalidInput, match=where):
            dk.Slider(pts, counts, idx, handles=[handle])
    numpy_handle = dk.Slider(pts, counts, idx, handles=[{"vertex": np.int64(5), "radius": np.float32(0.5)}])
    assert numpy_handle.num_handles == 1
    with pytest.raises(dk.InvalidInput, match="handles\\[0\\].region.*'sphere'"):
        dk.Slider(pts, counts, idx, handles=[{"vertex": 1, "radius": 0.5, "region": "sphere"}])
    with pytest.raises(dk.InvalidInput, match=r"handle 1 \(vertex -3\)"):
        dk.Slider(pts, counts, idx, handles=[{"vertex": 1, "radius": 0.5}, {"vertex": -3, "radius": 0.5}])
    with pytest.raises(dk.InvalidInput, match="no handle"):
        dk.Slider(pts, counts, idx)
    with pytest.raises(dk.InvalidInput, match="no handle"):
        dk.Slider(pts, counts, idx, handles=[])
    with pytest.raises(dk.InvalidInput, match="either handle and radius, or handles"):
        dk.Slider(pts, counts, idx, handle=1, radius=0.5, handles=[{"vertex": 1, "radius": 0.5}])
    with pytest.raises(dk.InvalidInput, match="max_walk_triangles"):
        dk.Slider(pts, counts, idx, handle=1, radius=0.5, max_walk_triangles=0)

    slider = dk.Slider(pts, counts, idx, handle=12, radius=0.5)
    with pytest.raises(dk.InvalidInput, match=r"weights.*\(24,\)"):
        slider.evaluate(d, weights=np.ones(24, dtype=np.float32))
    with pytest.raises(dk.InvalidInput, match="weight of vertex 3"):
        slider.evaluate(d, weights=np.float32([1, 1, 1, np.nan] + [1] * 21))
    with pytest.raises(dk.InvalidInput, match=r"Slider.evaluate: points: has 24 rows \(expected 25, one per vertex\)"):
        slider.evaluate(d, points=pts[:24])
    with pytest.raises(dk.InvalidInput, match=r"region.*handle.*\[0, 1\)"):
        slider.region(1)
    # Values beyond float range are named as given, not as the infinity a float32 copy would make of them.
    with pytest.raises(dk.InvalidInput, match=re.escape("handle 0 displacement: has length 4e+38 (expected a "
                                                        "length within float range")):
        slider.evaluate([4e38, 0.0, 0.0])
    with pytest.raises(dk.InvalidInput, match=re.escape("envelope: is 1e+39 (expected a finite envelope within "
                                                        "float range")):
        slider.evaluate(d, envelope=1e39)
    with pytest.raises(dk.InvalidInput, match=re.escape("handle 0 (vertex 12): radius -1e-09 (expected")):
        dk.Slider(pts, counts, idx, handle=12, radius=-1e-9)
    # A rejected call changes nothing: the next one gives the plain result.
    x = distances(pts, 12) / 0.5
    np.testing.assert_allclose(slider.evaluate(d).points, pts + smoothstep_falloff(x)[:, None] * d, atol=TOL)


def test_concurrent_evaluations_agree():
    # Two threads evaluating one slider both finish with the same, correct result (calls are serialised in
    # the core; the GIL is released so the Python side is not blocked meanwhile).
    pts, counts, idx = plane(60, 0.02)
    handle = 30 * 61 + 30
    slider = dk.Slider(pts, counts, idx, handle=handle, radius=0.5)
    d = np.array([0.05, 0.03, 0.0], dtype=np.float32)
    out = [None, None]

    def run(k):
        out[k] = slider.evaluate(d).points

    threads = [threading.Thread(target=run, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    np.testing.assert_array_equal(out[0], out[1])
    f = smoothstep_falloff(distances(pts, handle) / 0.5)
    np.testing.assert_allclose(out[0], pts + f[:, None] * d, atol=TOL)


def test_slide_in_a_stack_slides_over_the_bent_surface():
    """In a DeformerStack after a bend, the slide moves over the bent plane: its result is the Slider's over the
    bent points, every slid vertex lies on a bent triangle, and the handle follows the drag given in bent
    space (to the bend's change of stretch across the handle's ring)."""
    pts, counts, idx = plane()
    mesh = dk.Mesh(pts, counts, idx)
    stack = dk.DeformerStack()
    stack.set_rest(mesh)
    stack.add("bend", "bd")
    for name, value in [("handleOrigin", [0, 0, 0]), ("handleX", [0, 0, 2]), ("handleY", [2, 0, 0]),
                        ("curvature", 0.8), ("lowBound", 0), ("highBound", 1)]:
        stack.set(0, name, value)
    bent = stack.evaluate(pts)
    assert np.abs(bent[:, 2]).max() > 0.3  # really bent
    stack.add("slide", "sl")
    d = np.array([0.06, 0.04, -0.02])
    for name, value in [("vertex", HANDLE), ("radius", 0.6), ("displacement", d)]:
        stack.set(1, name, value)
    out = stack.evaluate(pts)
    r = dk.Slider(pts, counts, idx, handle=HANDLE, radius=0.6).evaluate(d.astype(np.float32), points=bent)
    np.testing.assert_allclose(out, r.points, atol=2e-7)  # one float ulp: the stack's blend runs in double
    rebuilt = np.einsum("mk,mkc->mc", r.barycentric, bent[r.triangles].astype(np.float64))
    np.testing.assert_allclose(rebuilt, out[r.vertices], atol=1e-6)
    moved = out[HANDLE].astype(np.float64) - bent[HANDLE]
    # The drag's part along the bent surface: d without its component along the bent normal at the handle.
    ring = bent[[HANDLE + 1, HANDLE + 41, HANDLE - 1, HANDLE - 41]].astype(np.float64) - bent[HANDLE]
    normal = np.cross(ring[0] - ring[2], ring[1] - ring[3])
    normal /= np.linalg.norm(normal)
    tangent = d - d.dot(normal) * normal
    np.testing.assert_allclose(moved, tangent, atol=0.02 * np.linalg.norm(tangent))


def test_stack_slide_parameters_painted_weights_and_fold_limit():
    """The host deformer's paintedWeights and foldLimit (what scenes, Blender and Maya set): on a plane the
    paper's rule moves each vertex inside the radius by its weight times d; the fold limit leaves no flip."""
    pts, counts, idx = plane()
    w = np.clip(0.2 + 0.3 * pts[:, 0], 0, 1).astype(np.float32)
    stack = dk.DeformerStack()
    stack.set_rest(dk.Mesh(pts, counts, idx))
    stack.add("slide", "s")
    d = np.array([0.05, 0.03, 0.0])
    for name, value in [("vertex", HANDLE), ("radius", 0.6), ("paintedWeights", 1), ("displacement", d)]:
        stack.set(0, name, value)
    stack.set_weights(0, w)
    inside = distances(pts, HANDLE) <= 0.6
    np.testing.assert_allclose(stack.evaluate(pts), pts + (w * inside)[:, None] * d, atol=TOL)
    stack.set_weights(0, None)
    stack.set(0, "paintedWeights", 0)
    stack.set(0, "foldLimit", 1)
    stack.set(0, "displacement", [0.48, 0.0, 0.0])  # 0.8 r: folds without the limit
    out = stack.evaluate(pts)
    limited = dk.Slider(pts, counts, idx, handle=HANDLE, radius=0.6, fold_limit=True).evaluate(
        np.float32([0.48, 0, 0]))
    assert limited.flipped_triangles == 0
    np.testing.assert_allclose(out, limited.points, atol=2e-7)
    with pytest.raises(dk.InvalidInput, match="paintedWeights"):
        stack.set(0, "paintedWeights", 2)
