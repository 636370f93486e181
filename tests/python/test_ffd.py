"""Free-form deformation and FFD with frames from Python, against a direct Bernstein sum written here in
numpy; bind/evaluate classes; outside options; errors naming the argument."""
import math

import numpy as np
import pytest

import deformkit as dk

ORIGIN = np.array([-0.5, 0.2, 1.0], dtype=np.float32)
AXES = np.array([[2.0, 0.3, -0.1], [0.2, 1.5, 0.2], [-0.3, 0.1, 1.8]], dtype=np.float32)  # rows X, Y, Z


def control_points(div):
    l, m, n = div
    i, j, k = np.meshgrid(np.arange(l + 1) / l, np.arange(m + 1) / m, np.arange(n + 1) / n, indexing="ij")
    st = np.stack([i, j, k], axis=-1)
    return (ORIGIN + st @ AXES).astype(np.float32)


def points_at(local):
    return (ORIGIN + local @ AXES).astype(np.float32)


def bernstein(d, t):
    """B^d_i(t) for t in [0, 1]; beyond it continued from the end with the value and derivative there
    (outside="extrapolate"), B_i(e) + (t - e) d (B^(d-1)_(i-1)(e) - B^(d-1)_i(e))."""
    i = np.arange(d + 1)
    coef = np.array([math.comb(d, int(k)) for k in i], dtype=np.float64)
    t = np.asarray(t, dtype=np.float64)[:, None]
    e = np.clip(t, 0.0, 1.0)
    value = coef * e**i * (1.0 - e) ** (d - i)
    lower = np.zeros_like(value)  # B^(d-1)_k(e) at column k, 0 past d - 1
    lower[:, :d] = np.array([math.comb(d - 1, int(k)) for k in range(d)]) * e ** np.arange(d) * (
        1.0 - e
    ) ** (d - 1 - np.arange(d))
    shifted = np.zeros_like(value)  # B^(d-1)_(i-1)(e)
    shifted[:, 1:] = lower[:, :d]
    return value + (t - e) * d * (shifted - lower)


def ffd_reference(points, div, target):
    local = np.linalg.solve(AXES.T.astype(np.float64), (points - ORIGIN).T.astype(np.float64)).T
    bx, by, bz = (bernstein(div[a], local[:, a]) for a in range(3))
    disp = (target - control_points(div)).astype(np.float64)
    return points + np.einsum("pi,pj,pk,ijkc->pc", bx, by, bz, disp)


def random_target(div, seed, amount=0.3):
    rng = np.random.default_rng(seed)
    cp = control_points(div)
    return (cp + rng.uniform(-amount, amount, size=cp.shape)).astype(np.float32)


def test_ffd_matches_direct_bernstein_sum():
    div = (3, 2, 4)
    rng = np.random.default_rng(1)
    pts = points_at(rng.uniform(0, 1, size=(500, 3)))
    target = random_target(div, 2)
    out = dk.ffd(pts, ORIGIN, AXES, div, target)
    assert out.dtype == np.float32 and out.shape == (500, 3)
    np.testing.assert_allclose(out, ffd_reference(pts, div, target), atol=1e-5)


def test_identity_and_linear_precision():
    div = (2, 3, 3)
    rng = np.random.default_rng(3)
    pts = points_at(rng.uniform(0, 1, size=(400, 3)))
    for basis in ("bernstein", "bspline"):
        out = dk.ffd(pts, ORIGIN, AXES, div, control_points(div), basis=basis)
        np.testing.assert_allclose(out, pts, atol=1e-6)
        a = np.array([[1.1, 0.2, 0.0], [-0.1, 0.9, 0.3], [0.05, 0.0, 1.2]], dtype=np.float32)
        b = np.array([0.3, -0.2, 0.5], dtype=np.float32)
        out = dk.ffd(pts, ORIGIN, AXES, div, control_points(div) @ a.T + b, basis=basis)
        np.testing.assert_allclose(out, pts @ a.T + b, atol=1e-5)


def test_outside_none_and_extrapolate():
    div = (3, 3, 3)
    rng = np.random.default_rng(4)
    local = rng.uniform(-0.5, 1.5, size=(400, 3))
    outside = np.any((local < 0) | (local > 1), axis=1)
    assert 50 < outside.sum() < 400
    pts = points_at(local)
    target = random_target(div, 5)
    none = dk.ffd(pts, ORIGIN, AXES, div, target)
    np.testing.assert_array_equal(none[outside], pts[outside])
    ref = ffd_reference(pts, div, target)
    np.testing.assert_allclose(none[~outside], ref[~outside], atol=1e-5)
    extra = dk.ffd(pts, ORIGIN, AXES, div, target, outside="extrapolate")
    np.testing.assert_allclose(extra, ref, atol=3e-5)


def test_weights_and_envelope_scale_the_displacement():
    div = (3, 3, 3)
    rng = np.random.default_rng(6)
    pts = points_at(rng.uniform(0, 1, size=(200, 3)))
    target = random_target(div, 7)
    w = rng.uniform(0, 1, size=200).astype(np.float32)
    out = dk.ffd(pts, ORIGIN, AXES, div, target, weights=w, envelope=0.5)
    expected = pts + (0.5 * w)[:, None] * (ffd_reference(pts, div, target) - pts)
    np.testing.assert_allclose(out, expected, atol=1e-5)


def test_bound_class_moves_controls_without_rebinding():
    div = (4, 4, 4)
    rng = np.random.default_rng(8)
    pts = points_at(rng.uniform(0, 1, size=(300, 3)))
    ffd = dk.Ffd(ORIGIN, AXES, div, basis="bspline")
    ffd.bind(pts)
    np.testing.assert_allclose(ffd.source_points, control_points(div), atol=1e-6)
    np.testing.assert_allclose(ffd.evaluate(), pts, atol=1e-6)
    for seed in (9, 10):
        target = random_target(div, seed)
        ffd.set_target(target)
        once = dk.ffd(pts, ORIGIN, AXES, div, target, basis="bspline")
        np.testing.assert_allclose(ffd.evaluate(), once, atol=1e-6)
        np.testing.assert_allclose(ffd.target, target)


def test_ffd_frames_translation_only_equals_ffd_and_rotation_is_local():
    div = (2, 2, 2)
    rng = np.random.default_rng(11)
    pts = points_at(rng.uniform(0, 1, size=(300, 3)))
    target = random_target(div, 12)
    identity = np.broadcast_to(np.eye(3, dtype=np.float32), (3, 3, 3, 3, 3)).copy()
    frames = dk.ffd_frames(pts, ORIGIN, AXES, div, target, identity)
    np.testing.assert_allclose(frames, dk.ffd(pts, ORIGIN, AXES, div, target), atol=1e-5)

    # Rotate only the centre frame about z: points near it turn about it; the centre stays put.
    c, s = math.cos(0.5), math.sin(0.5)
    bases = identity.copy()
    bases[1, 1, 1] = np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]], dtype=np.float32)  # rows: rotated basis vectors
    centre = control_points(div)[1, 1, 1]
    ring = np.array([centre + 0.1 * np.array([math.cos(a), math.sin(a), 0.0]) for a in np.linspace(0, 6, 12)],
                    dtype=np.float32)
    out = dk.ffd_frames(np.vstack([ring, centre[None]]), ORIGIN, AXES, div, control_points(div), bases)
    np.testing.assert_allclose(out[-1], centre, atol=1e-6)
    d = out[:-1] - ring
    r = ring - centre
    tangential = r[:, 0] * d[:, 1] - r[:, 1] * d[:, 0]  # z of r x d: > 0 for a counter-clockwise turn
    assert np.all(tangential > 0)

    cls = dk.FfdFrames(ORIGIN, AXES, div)
    cls.bind(ring)
    cls.set_target_frames(control_points(div), bases)
    np.testing.assert_allclose(cls.evaluate(), out[:-1], atol=1e-6)


def test_bad_input_names_the_argument():
    pts = np.zeros((4, 3), dtype=np.float32)
    div = (3, 3, 3)
    with pytest.raises(dk.InvalidInput, match=r"divisions\[1\] \(m\)"):
        dk.ffd(pts, ORIGIN, AXES, (3, 0, 3), control_points((3, 1, 3)))
    with pytest.raises(dk.InvalidInput, match="coplanar"):
        dk.ffd(pts, ORIGIN, np.array([[1, 0, 0], [0, 1, 0], [1, 1, 0]], dtype=np.float32), div, control_points(div))
    with pytest.raises(dk.InvalidInput, match=r"target.*\(4, 4, 4, 3\)"):
        dk.ffd(pts, ORIGIN, AXES, div, control_points((2, 3, 3)))
    bad = control_points(div)
    bad[0, 1, 2, 0] = np.nan
    with pytest.raises(dk.InvalidInput, match=r"target 6 \(i=0, j=1, k=2\)"):
        dk.ffd(pts, ORIGIN, AXES, div, bad)
    nan_pts = pts.copy()
    nan_pts[2, 1] = np.nan
    with pytest.raises(dk.InvalidInput, match="point 2"):
        dk.ffd(nan_pts, ORIGIN, AXES, div, control_points(div))
    with pytest.raises(dk.InvalidInput, match="basis"):
        dk.ffd(pts, ORIGIN, AXES, div, control_points(div), basis="nurbs")
    with pytest.raises(dk.InvalidInput, match="outside"):
        dk.ffd(pts, ORIGIN, AXES, div, control_points(div), outside="clamp")
    with pytest.raises(dk.InvalidInput, match=r"'linear,bspline' is not a basis"):
        dk.ffd(pts, ORIGIN, AXES, div, control_points(div), basis="linear,bspline")
    with pytest.raises(dk.InvalidInput, match=r"ends.*'clamp' is not an option \(expected extrapolate or repeat\)"):
        dk.ffd(pts, ORIGIN, AXES, div, control_points(div), ends="clamp")
    with pytest.raises(dk.InvalidInput, match="weights"):
        dk.ffd(pts, ORIGIN, AXES, div, control_points(div), weights=np.ones(3, dtype=np.float32))
    singular = np.broadcast_to(np.eye(3, dtype=np.float32), (4, 4, 4, 3, 3)).copy()
    singular[1, 0, 0, 2] = 0
    with pytest.raises(dk.InvalidInput, match=r"control 16 \(i=1, j=0, k=0\)"):
        dk.ffd_frames(pts, ORIGIN, AXES, div, control_points(div), singular[..., :, :], source_bases=singular)


def test_blender_linear_lattice_is_trilinear_interpolation_with_clamped_cells():
    # Blender's "Linear" lattice with its end conditions (repeated end controls; every point deformed):
    # inside, trilinear interpolation of the controls' displacements; outside, the displacement of the
    # nearest point of the lattice. Written here with numpy's own interpolation, axis by axis.
    div = (3, 2, 4)
    target = random_target(div, 7)
    rng = np.random.default_rng(8)
    local = rng.uniform(-0.5, 1.5, size=(400, 3))
    pts = points_at(local)
    out = dk.ffd(pts, ORIGIN, AXES, div, target, basis="linear", outside="extrapolate", ends="repeat")
    disp = (target - control_points(div)).astype(np.float64)
    ref = np.empty_like(disp, shape=(len(pts), 3))
    solved = np.linalg.solve(AXES.T.astype(np.float64), (pts - ORIGIN).T.astype(np.float64)).T
    for p, s in enumerate(solved):
        d = disp
        for a in range(3):  # np.interp clamps beyond the ends, as repeated end controls do
            grid = np.arange(div[a] + 1) / div[a]
            d = np.apply_along_axis(lambda column: np.interp(s[a], grid, column), 0, d)
        ref[p] = pts[p] + d
    np.testing.assert_allclose(out, ref, atol=1e-5)
    # Three names set the axes one by one: linear along all three is the same as "linear".
    same = dk.ffd(pts, ORIGIN, AXES, div, target, basis="linear,linear,linear", outside="extrapolate",
                  ends="repeat")
    np.testing.assert_array_equal(same, out)
    # Extrapolated ends and outside points left alone: a different result outside.
    left = dk.ffd(pts, ORIGIN, AXES, div, target, basis="linear")
    outside = (local < 0).any(axis=1) | (local > 1).any(axis=1)
    np.testing.assert_array_equal(left[outside], pts[outside])
