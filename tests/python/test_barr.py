"""Barr taper, twist and bend from Python: closed forms written here in numpy, bind/evaluate classes,
host parameter conversions and errors."""
import math

import numpy as np
import pytest

import deformkit as dk

ORIGIN = np.array([1.0, -2.0, 0.5], dtype=np.float32)
AXIS = np.array([1.0, 2.0, 2.0]) / 3.0
E1 = np.array([2.0, -1.0, 0.0]) / math.sqrt(5.0)
E2 = np.cross(AXIS, E1)


def frame_points(a, b, z):
    return (ORIGIN + np.outer(a, E1) + np.outer(b, E2) + np.outer(z, AXIS)).astype(np.float32)


def random_abz(n=400, seed=1, extent=3.0):
    rng = np.random.default_rng(seed)
    return rng.uniform(-extent, extent, size=(3, n))


def test_taper_linear_profile_closed_form():
    a, b, z = random_abz()
    f = 1.0 + 0.25 * np.clip(z, -2.0, 2.0)
    out = dk.taper(frame_points(a, b, z), ORIGIN, 3 * AXIS, [-2.0, 0.5, 2.0], [0.5, 1.125, 1.5])
    assert out.dtype == np.float32 and out.shape == (400, 3)
    np.testing.assert_allclose(out, frame_points(f * a, f * b, z), atol=2e-5)


def test_twist_linear_angle_closed_form():
    a, b, z = random_abz(seed=2)
    t = 0.8 * z
    out = dk.twist(frame_points(a, b, z), ORIGIN, AXIS, [-4.0, 4.0], [-3.2, 3.2])
    expected = frame_points(a * np.cos(t) - b * np.sin(t), a * np.sin(t) + b * np.cos(t), z)
    np.testing.assert_allclose(out, expected, atol=2e-5)


def test_bend_maps_axis_segment_onto_arc():
    k, z0, lo, hi = 0.7, 0.5, -1.5, 2.0
    z = np.linspace(lo, hi, 51)
    out = dk.bend(frame_points(0 * z, 0 * z, z), ORIGIN, AXIS, E2, k, z0, lo, hi).astype(np.float64)
    centre = ORIGIN + E2 / k + z0 * AXIS
    np.testing.assert_allclose(np.linalg.norm(out - centre, axis=1), 1.0 / k, atol=1e-5)
    u = (out - centre) * k
    angles = np.arctan2(np.linalg.norm(np.cross(u[:-1], u[1:]), axis=1), np.sum(u[:-1] * u[1:], axis=1))
    np.testing.assert_allclose(angles, (z[1] - z[0]) * k, atol=2e-5)  # arc length preserved


def test_identity_and_envelope():
    a, b, z = random_abz(seed=3)
    pts = frame_points(a, b, z)
    np.testing.assert_allclose(dk.taper(pts, ORIGIN, AXIS, [0.0], [1.0]), pts, atol=1e-6)
    np.testing.assert_allclose(dk.twist(pts, ORIGIN, AXIS, [-1.0, 1.0], [0.0, 0.0]), pts, atol=1e-6)
    np.testing.assert_allclose(dk.bend(pts, ORIGIN, AXIS, E2, 0.0, 0.0, -1.0, 1.0), pts, atol=1e-6)
    full = dk.bend(pts, ORIGIN, AXIS, E2, 1.2, 0.0, -1.0, 1.0)
    weights = np.linspace(0.0, 1.0, len(pts), dtype=np.float32)
    half = dk.bend(pts, ORIGIN, AXIS, E2, 1.2, 0.0, -1.0, 1.0, weights=weights, envelope=0.5)
    np.testing.assert_allclose(half, pts + (0.5 * weights)[:, None] * (full - pts), atol=1e-5)


def test_classes_bind_once_and_change_controls():
    a, b, z = random_abz(seed=4)
    rest = frame_points(a, b, z)
    twist = dk.Twist(rest, ORIGIN, AXIS, [-3.0, 3.0], [0.0, 0.0])
    np.testing.assert_allclose(twist.evaluate(rest), rest, atol=1e-6)
    twist.set_profile([-3.0, 3.0], [-1.5, 1.5])
    np.testing.assert_allclose(twist.evaluate(rest), dk.twist(rest, ORIGIN, AXIS, [-3.0, 3.0], [-1.5, 1.5]), atol=1e-6)
    bend = dk.Bend(rest, ORIGIN, AXIS, E2, 0.0, 0.0, -1.0, 1.0)
    bend.set_params(0.9, 0.0, -1.0, 1.0)
    np.testing.assert_allclose(bend.evaluate(rest), dk.bend(rest, ORIGIN, AXIS, E2, 0.9, 0.0, -1.0, 1.0), atol=1e-6)
    taper = dk.Taper(rest, ORIGIN, AXIS, [0.0], [2.0])
    out = taper.evaluate(rest)
    np.testing.assert_allclose(out, frame_points(2 * a, 2 * b, z), atol=2e-5)


def test_host_parameterisations():
    # Maya: handle scaled by 2 with X along world z; curvature 0.5 rad per handle unit.
    p = dk.maya_bend_params([1, 0, 0], [0, 0, 2], [0, 2, 0], 0.5, -1.0, 2.0)
    assert p["rate"] == pytest.approx(0.25) and p["lo"] == pytest.approx(-2.0) and p["hi"] == pytest.approx(4.0)
    out = dk.bend(np.array([[1, 2, 0]], dtype=np.float32), **p)
    np.testing.assert_allclose(out[0], [1.0, 4 * math.sin(0.5), 4 * (1 - math.cos(0.5))], atol=1e-5)
    # Blender twist about Z, angle pi/2 over the middle half of z in [0, 4].
    mesh = np.array([[0, 0, 0], [0, 0, 4]], dtype=np.float32)
    t = dk.blender_simple_deform_params("TWIST", mesh, angle=math.pi / 2, limits=(0.25, 0.75))
    out = dk.twist(np.array([[1, 0, 2]], dtype=np.float32), **t)
    np.testing.assert_allclose(out[0], [0, 1, 2], atol=1e-6)
    # A scaled or sheared origin basis would change the mapping silently: refused, naming the axis.
    with pytest.raises(dk.InvalidInput, match=r"basis x axis: has length 2 \(expected unit, orthogonal axes"):
        dk.blender_simple_deform_params("TWIST", mesh, angle=1.0, basis=np.diag([2, 1, 1]).astype(np.float32))
    sheared = np.array([[1, 0, 0], [0.5, 0.8660254, 0], [0, 0, 1]], dtype=np.float32)
    with pytest.raises(dk.InvalidInput, match=r"basis x and y axes: are not orthogonal"):
        dk.blender_simple_deform_params("TWIST", mesh, angle=1.0, basis=sheared)
    # A NaN origin is named as the origin (the finite points were blamed).
    with pytest.raises(dk.InvalidInput, match=r"Blender twist: origin: is \(nan, 0, 0\) \(expected finite"):
        dk.blender_simple_deform_params("TWIST", mesh, angle=1.0, origin=np.float32([np.nan, 0, 0]))
    b = dk.blender_simple_deform_params("BEND", np.array([[-1, 0, 0], [1, 0, 0]], dtype=np.float32), angle=math.pi)
    out = dk.bend(np.array([[2, 0, 0]], dtype=np.float32), **b)
    np.testing.assert_allclose(out[0], [2 / math.pi, 2 / math.pi + 1, 0], atol=1e-6)


def test_bad_input_names_the_element():
    pts = np.zeros((4, 3), dtype=np.float32)
    with pytest.raises(dk.InvalidInput, match=r"z_samples\[2\]"):
        dk.taper(pts, ORIGIN, AXIS, [0.0, 1.0, 0.5], [1.0, 1.0, 1.0])
    with pytest.raises(dk.InvalidInput, match="value_samples"):
        dk.twist(pts, ORIGIN, AXIS, [0.0, 1.0], [1.0])
    with pytest.raises(dk.InvalidInput, match="axis_dir"):
        dk.taper(pts, ORIGIN, [0, 0, 0], [0.0], [1.0])
    with pytest.raises(dk.InvalidInput, match="up_dir"):
        dk.bend(pts, ORIGIN, AXIS, 2 * AXIS, 1.0, 0.0, -1.0, 1.0)
    with pytest.raises(dk.InvalidInput, match="lo <= hi"):
        dk.bend(pts, ORIGIN, AXIS, E2, 1.0, 0.0, 1.0, -1.0)
    with pytest.raises(dk.InvalidInput, match="rate"):
        dk.bend(pts, ORIGIN, AXIS, E2, float("nan"), 0.0, -1.0, 1.0)
    bad = pts.copy()
    bad[2, 1] = np.nan
    with pytest.raises(dk.InvalidInput, match="point 2"):
        dk.twist(bad, ORIGIN, AXIS, [0.0], [1.0])
    with pytest.raises(dk.InvalidInput, match="weights"):
        dk.taper(pts, ORIGIN, AXIS, [0.0], [1.0], weights=np.ones(3, dtype=np.float32))
    with pytest.raises(dk.InvalidInput, match="points"):
        dk.taper(np.zeros((4, 2), dtype=np.float32), ORIGIN, AXIS, [0.0], [1.0])
    with pytest.raises(dk.Error):
        dk.Bend(pts, ORIGIN, AXIS, E2, 1.0, 0.0, -1.0, 1.0).evaluate(np.zeros((5, 3), dtype=np.float32))
