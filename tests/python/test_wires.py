"""deformkit.wires and deformkit.Wires (paper §4.4 and §5.3), checked against numpy closed forms."""
import numpy as np
import pytest

import deformkit as dk


def falloff(t):
    t = np.minimum(np.asarray(t, dtype=np.float64), 1.0)
    return 1.0 - 3.0 * t**2 + 2.0 * t**3


def line(a, b, segments):
    t = np.linspace(0.0, 1.0, segments + 1)[:, None]
    return ((1 - t) * np.asarray(a, np.float64) + t * np.asarray(b, np.float64)).astype(np.float32)


def cloud(n, seed=0):
    return np.random.default_rng(seed).uniform(-0.5, 2.5, (n, 3)).astype(np.float32)


def test_identity_when_wire_equals_reference():
    ref = np.array([[0, 0, 0], [0.5, 0.4, 0], [1, 0, 0.3], [2, 0.2, 0]], np.float32)
    pts = cloud(2000)
    for variant in ("original", "smooth"):
        out = dk.wires(pts, [ref], [ref.copy()], radius=0.8, scale=1.0, m=1.0, variant=variant)
        assert out.dtype == np.float32 and out.shape == pts.shape
        assert np.abs(out - pts).max() <= 1e-6


def test_translation_closed_form_and_radius():
    ref = line([0, 0, 0], [4, 0, 0], 8)
    offset = np.array([0.1, 0.3, -0.2], np.float32)
    pts = np.array([[1.3 + 0.01 * i, 0.02 * i, -0.01 * i] for i in range(41)], np.float32)
    out = dk.wires(pts, [ref], [ref + offset], radius=0.6, scale=1.0, m=2.0)
    d = np.hypot(pts[:, 1], pts[:, 2])
    expected = pts + falloff(d / 0.6)[:, None] * offset
    np.testing.assert_allclose(out, expected, atol=1e-6)
    assert np.array_equal(out[d >= 0.6], pts[d >= 0.6])


def test_points_on_reference_map_onto_wire():
    ref = np.array([[0, 0, 0], [0.5, 0.3, 0], [1, 0, 0.2], [1.5, -0.2, 0.1], [2, 0, 0]], np.float32)
    wire = np.array([[0, 0.1, 0], [0.6, 0.6, 0.1], [1, 0.2, 0.6], [1.4, -0.5, 0.3], [2.2, 0, -0.2]], np.float32)
    t = np.array([0.0, 0.4, 0.8], np.float32)[:, None]
    on_ref = np.concatenate([(1 - t) * ref[j] + t * ref[j + 1] for j in range(4)])
    on_wire = np.concatenate([(1 - t) * wire[j] + t * wire[j + 1] for j in range(4)])
    out = dk.wires(on_ref, [ref], [wire], radius=0.5, scale=1.5, m=1.0)
    np.testing.assert_allclose(out, on_wire, atol=1e-5)


def test_bind_evaluate_class_matches_function_weights_and_envelope():
    ref = line([0, 0, 0], [2, 0.5, 0], 6)
    wire = ref + np.array([0, 0, 0.4], np.float32) * np.linspace(0, 1, 7, dtype=np.float32)[:, None]
    pts = cloud(3000, 2)
    for variant in ("original", "smooth"):
        w = dk.Wires([ref], radius=0.7, scale=1.2, m=1.0, variant=variant)
        assert w.num_wires == 1 and not w.is_bound
        w.bind(pts)
        assert w.is_bound and w.num_field_entries > 100
        # Wire curves start at the reference: only the scale x = 1.2 about C(v) acts.
        np.testing.assert_allclose(w.evaluate(pts), dk.wires(pts, [ref], [ref], 0.7, 1.2, 1.0, variant=variant),
                                   atol=1e-6)
        full = w.evaluate(pts, wire_curves=[wire])
        one_off = dk.wires(pts, [ref], [wire], 0.7, 1.2, 1.0, variant=variant)
        np.testing.assert_allclose(full, one_off, atol=1e-6)
        assert np.abs(full - pts).max() > 0.1
        half = w.evaluate(pts, envelope=0.5)
        np.testing.assert_allclose(half - pts, 0.5 * (full - pts), atol=1e-6)
        painted = np.linspace(0, 1, len(pts), dtype=np.float32)
        np.testing.assert_allclose(w.evaluate(pts, weights=painted) - pts, painted[:, None] * (full - pts), atol=1e-6)


def test_smooth_variant_is_continuous_across_the_medial_set():
    left = np.array([[-1, 2 - 0.25 * i, 0] for i in range(8)])
    a = np.pi + np.pi * np.arange(33) / 32
    arc = np.stack([np.cos(a), np.sin(a), np.zeros_like(a)], 1)
    right = np.array([[1, 0.25 * i, 0] for i in range(1, 9)])
    ref = np.concatenate([left, arc, right]).astype(np.float32)
    wire = ref.copy()
    wire[:, 2] = -0.5 * np.clip(ref[:, 0], -1, 1)
    pts = np.array([[-0.2 + 0.0005 + 1e-3 * i, 0.7, 0] for i in range(400)], np.float32)
    original = dk.wires(pts, [ref], [wire], 1.5, 1.0, 1.0, variant="original")
    smooth = dk.wires(pts, [ref], [wire], 1.5, 1.0, 1.0, variant="smooth")
    jump = lambda p: np.linalg.norm(np.diff(p, axis=0), axis=1).max()
    assert jump(original) == pytest.approx(2 * falloff(1 / 1.5) * 0.5, abs=2e-3)
    assert jump(smooth) < 3e-3


def test_two_wires_combine():
    a = line([0, 0, 0], [2, 0, 0], 4)
    b = line([0, 1, 0], [2, 1, 0], 4)
    t1, t2 = np.array([0, 0, 0.3], np.float32), np.array([0, 0, -0.1], np.float32)
    pts = np.array([[1.0, 0.05 * i, 0.0] for i in range(21)], np.float32)
    out = dk.wires(pts, [a, b], [a + t1, b + t2], radius=[0.9, 0.8], scale=1.0, m=1.0)
    y = pts[:, 1].astype(np.float64)
    d1 = falloff(y / 0.9)[:, None] * t1
    d2 = falloff((1 - y) / 0.8)[:, None] * t2
    w1, w2 = np.linalg.norm(d1, axis=1)[:, None], np.linalg.norm(d2, axis=1)[:, None]
    np.testing.assert_allclose(out, pts + (w1 * d1 + w2 * d2) / (w1 + w2), atol=1e-6)


def test_catmull_rom_curves_are_sampled_alike():
    controls = np.array([[0, 0, 0], [1, 1, 0], [2, 0, 0], [3, 1, 0]], np.float32)
    pts = cloud(500, 4)
    out = dk.wires(pts, [controls], [controls.copy()], 0.5, curve_type="catmull_rom", samples_per_span=6)
    np.testing.assert_allclose(out, pts, atol=1e-6)
    lifted = dk.wires(np.array([[1, 1, 0]], np.float32), [controls], [controls + [0, 0, 1]], 0.5,
                      curve_type="catmull_rom")
    np.testing.assert_allclose(lifted, [[1, 1, 1]], atol=1e-5)  # a control point lies on the curve


def test_bad_input_names_the_element():
    ref = line([0, 0, 0], [1, 0, 0], 2)
    pts = cloud(10)
    with pytest.raises(dk.InvalidInput, match="wire 0 wire curve"):
        dk.wires(pts, [ref], [ref[:2]], 0.5)
    with pytest.raises(dk.InvalidInput, match="wire 0 reference curve.*at least 2"):
        dk.wires(pts, [ref[:1]], [ref[:1]], 0.5)
    with pytest.raises(dk.InvalidInput, match="wire 0 radius"):
        dk.wires(pts, [ref], [ref], 0.0)
    with pytest.raises(dk.InvalidInput, match="wire 1 radius"):
        dk.wires(pts, [ref, ref], [ref, ref], [0.5, -1.0])
    bad = ref.copy()
    bad[1, 2] = np.nan
    with pytest.raises(dk.InvalidInput, match="wire 0 wire curve point 1"):
        dk.wires(pts, [ref], [bad], 0.5)
    nan_pts = pts.copy()
    nan_pts[3, 0] = np.nan
    with pytest.raises(dk.InvalidInput, match="rest point 3"):
        dk.wires(nan_pts, [ref], [ref], 0.5)
    with pytest.raises(dk.InvalidInput, match="reference_curves\\[0\\]"):
        dk.wires(pts, [np.zeros((3, 2), np.float32)], [ref], 0.5)
    with pytest.raises(dk.InvalidInput, match="variant"):
        dk.wires(pts, [ref], [ref], 0.5, variant="fancy")
    with pytest.raises(dk.InvalidInput, match="wire_curves"):
        dk.wires(pts, [ref], [ref, ref], 0.5)
    w = dk.Wires([ref], radius=0.5)
    with pytest.raises(dk.InvalidInput, match="before bind"):
        w.evaluate(pts)
    w.bind(pts)
    with pytest.raises(dk.InvalidInput, match="wire 0 wire curve"):
        w.evaluate(pts, wire_curves=[ref[:2]])
    with pytest.raises(dk.InvalidInput, match="weights"):
        w.evaluate(pts, weights=np.ones(3, np.float32))
