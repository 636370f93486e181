"""Beier-Neely image warp from Python (paper 4.2, 5.2): maps and warped images checked against numpy
references written here (closed-form single-segment map, linear-image resampling)."""
import numpy as np
import pytest

import deformkit as dk


def lines(*segments):
    return np.array(segments, dtype=np.float32).reshape(-1, 2, 2)


def centres(w, h):
    ys, xs = np.mgrid[0:h, 0:w].astype(np.float64) + 0.5
    return np.stack([xs, ys], axis=-1)


def test_identity_map_when_lines_agree():
    dst = lines([[5, 5], [30, 10]], [[10, 25], [12, 3]])
    for variant in ("original", "global"):
        m = dk.beier_neely_map(40, 30, dst, dst, 1.0, 2.0, 0.5, variant=variant)
        assert m.shape == (30, 40, 2) and m.dtype == np.float32
        np.testing.assert_allclose(m, centres(40, 30), atol=1e-5)


def test_one_segment_is_rotation_and_stretch():
    # X' = P* + R (k (X-P)_par + (X-P)_perp): B&N's u normalised by length^2, v unnormalised.
    P, Q = np.array([10.0, 20.0]), np.array([40.0, 25.0])
    Ps, Qs = np.array([5.0, 8.0]), np.array([20.0, 40.0])
    d, e = Q - P, Qs - Ps
    theta = np.arctan2(e[1], e[0]) - np.arctan2(d[1], d[0])
    k = np.linalg.norm(e) / np.linalg.norm(d)
    dh = d / np.linalg.norm(d)
    r = centres(50, 40) - P
    par = (r @ dh)[..., None] * dh
    local = k * par + (r - par)
    rot = np.array([[np.cos(theta), -np.sin(theta)], [np.sin(theta), np.cos(theta)]])
    expected = Ps + local @ rot.T
    for variant in ("original", "global"):
        m = dk.beier_neely_map(50, 40, lines([Ps, Qs]), lines([P, Q]), 0.5, 1.0, 1.0, variant=variant)
        np.testing.assert_allclose(m, expected, atol=1e-4)


def test_global_removes_fold_over():
    t = 1.1
    dst = lines([[12, 44], [52, 44]], [[32, 40], [32, 12]])
    src = lines([[12, 44], [52, 44]], [[32, 40], [32 + 28 * np.sin(t), 40 - 28 * np.cos(t)]])

    def min_det(variant):
        # Jacobian by differences of the map sampled on a fine grid (a 4x larger image, step 0.25 px is
        # not available through pixel centres, so scale the whole configuration by 4 instead).
        m = dk.beier_neely_map(256, 256, src * 4, dst * 4, 4.0, 2.0, 0.5, variant=variant).astype(np.float64)
        jx = (m[1:-1, 2:] - m[1:-1, :-2]) / 2.0
        jy = (m[2:, 1:-1] - m[:-2, 1:-1]) / 2.0
        return (jx[..., 0] * jy[..., 1] - jx[..., 1] * jy[..., 0]).min()

    assert min_det("original") < -0.02
    assert min_det("global") > 0.05


def test_warp_linear_image_matches_map():
    h, w = 30, 40
    ys, xs = np.mgrid[0:h, 0:w].astype(np.float32)
    image = np.stack([0.01 * xs + 0.2, 0.02 * ys, 0.5 + 0.0 * xs], axis=-1).astype(np.float32)
    src = lines([[8, 6], [30, 12]])
    dst = lines([[10, 8], [31, 10]])
    m = dk.beier_neely_map(w, h, src, dst, 2.0, 2.0, 0.5).astype(np.float64)
    for interp, margin in (("bilinear", 0.5), ("bicubic", 1.5)):
        # Where every tap is inside the image (clamp-to-edge bends the linear ramp at the border).
        inside = (m[..., 0] >= margin) & (m[..., 0] <= w - margin) & (m[..., 1] >= margin) & (m[..., 1] <= h - margin)
        inside &= (m[..., 0] <= w - 2.5) | (interp == "bilinear")
        inside &= (m[..., 1] <= h - 2.5) | (interp == "bilinear")
        assert inside.sum() > 500
        out = dk.beier_neely(image, src, dst, 2.0, 2.0, 0.5, interp=interp)
        assert out.shape == image.shape and out.dtype == np.float32
        ref0 = 0.01 * (m[..., 0] - 0.5) + 0.2
        ref1 = 0.02 * (m[..., 1] - 0.5)
        np.testing.assert_allclose(out[..., 0][inside], ref0[inside], atol=1e-4)
        np.testing.assert_allclose(out[..., 1][inside], ref1[inside], atol=1e-4)
        np.testing.assert_allclose(out[..., 2], 0.5, atol=1e-6)
    gray = dk.beier_neely(image[..., 1], src, dst, 2.0, 2.0, 0.5)
    assert gray.shape == (h, w)


def test_class_matches_one_off_and_engine_path():
    dst = lines([[5, 5], [30, 10]], [[10, 25], [12, 3]])
    src = lines([[6, 4], [31, 12]], [[9, 26], [14, 2]])
    bn = dk.BeierNeely(dst, dst, 1.0, 2.0, 0.5, variant="global")
    pts = np.concatenate([centres(20, 15).reshape(-1, 2), np.full((300, 1), 3.0)], axis=1).astype(np.float32)
    bn.bind(pts)
    bn.set_src_lines(src)  # new controls, no rebind
    moved = bn.evaluate(pts)
    ref = dk.beier_neely_map(20, 15, src, dst, 1.0, 2.0, 0.5, variant="global").reshape(-1, 2)
    np.testing.assert_allclose(moved[:, :2], ref, atol=1e-4)
    np.testing.assert_array_equal(moved[:, 2], 3.0)
    np.testing.assert_array_equal(bn.map(20, 15), dk.beier_neely_map(20, 15, src, dst, 1.0, 2.0, 0.5, variant="global"))


def test_errors():
    good = lines([[0, 0], [10, 0]])
    with pytest.raises(dk.InvalidInput, match="segment pair 0.*zero length"):
        dk.beier_neely_map(8, 8, lines([[1, 1], [1, 1]]), good)
    with pytest.raises(dk.InvalidInput, match="src_lines.*has 2 lines"):
        dk.beier_neely_map(8, 8, lines([[0, 0], [1, 0]], [[0, 1], [1, 1]]), good)
    with pytest.raises(dk.InvalidInput, match="a > 0"):
        dk.beier_neely_map(8, 8, good, good, a=0.0)
    with pytest.raises(dk.InvalidInput, match="b >= 0"):
        dk.beier_neely_map(8, 8, good, good, b=-1.0)
    with pytest.raises(dk.InvalidInput, match="non-finite"):
        dk.beier_neely_map(8, 8, lines([[np.nan, 0], [1, 0]]), good)
    with pytest.raises(dk.InvalidInput, match="variant"):
        dk.beier_neely_map(8, 8, good, good, variant="fancy")
    with pytest.raises(dk.InvalidInput, match="interp"):
        dk.beier_neely(np.zeros((4, 4, 3), np.float32), good, good, interp="nearest")
    with pytest.raises(dk.InvalidInput, match="dst_lines.*\\(n, 2, 2\\)"):
        dk.beier_neely_map(8, 8, good, np.zeros((1, 3), np.float32))
    with pytest.raises(dk.InvalidInput, match="0 pixels"):
        dk.beier_neely(np.zeros((0, 4, 3), np.float32), good, good)
    # Sides beyond 65536 were allocated as asked (50000^2 pixels: 20 GB, an anonymous bad_alloc at best).
    for width, height in ((0, 8), (8, -1), (65537, 8), (8, 2**31 - 1)):
        with pytest.raises(dk.InvalidInput, match=r"width, height: are .* \(expected 1 to 65536 pixels per side\)"):
            dk.beier_neely_map(width, height, good, good)
        with pytest.raises(dk.InvalidInput, match="1 to 65536 pixels per side"):
            dk.BeierNeely(good, good).map(width, height)
    assert dk.beier_neely_map(65536, 1, good, good).shape == (1, 65536, 2)


def test_evaluate_names_the_class_and_a_point_as_it_came_in():
    # The engine-backed classes name themselves, and a point that came in not finite as it came in (not as a
    # result "once deformed"); the points are left as they were.
    dst = lines([[5, 5], [30, 10]])
    bn = dk.BeierNeely(dst, dst)
    pts = np.concatenate([centres(10, 8).reshape(-1, 2), np.zeros((80, 1))], axis=1).astype(np.float32)
    bn.bind(pts)
    bad = pts.copy()
    bad[40] = (np.nan, 0.5, 0.0)
    with pytest.raises(dk.InvalidInput, match=r"^beier_neely: point 40: is \(nan, 0.5, 0\) \(expected finite"):
        bn.evaluate(bad)
    with pytest.raises(dk.InvalidInput, match=r"^beier_neely: points: has 10 entries \(expected 80"):
        bn.evaluate(pts[:10])
