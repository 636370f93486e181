"""deformkit.mesh_warp and deformkit.MeshWarp (paper §6) against a numpy reference written from the paper."""
import numpy as np
import pytest

import deformkit as dk

OCTA_POINTS = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], dtype=np.float32)
OCTA_FACES = [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]]
OCTA_COUNTS = np.array([3] * 8, dtype=np.int32)
OCTA_INDICES = np.array(sum(OCTA_FACES, []), dtype=np.int32)


def falloff(t, a, b):
    x = np.clip((t - a) / (b - a), 0.0, 1.0)
    return 1.0 - (3 * x**2 - 2 * x**3)


def reference(points, cage, faces, target, alpha=0.0, beta=1.0, gamma=0.0, mu=1.0):
    """w_i = f_ab(|P-P_i|/|E_im|) prod_j f_gm((P-P_i).E_ij/|E_ij|^2); T_i P = P*_i + A^T (P - P_i), A = lstsq(E, E*)."""
    points, cage, target = (np.asarray(a, dtype=np.float64) for a in (points, cage, target))
    nbrs = [set() for _ in cage]
    for f in faces:
        for a, b in zip(f, f[1:] + f[:1]):
            nbrs[a].add(b)
            nbrs[b].add(a)
    disp = np.zeros_like(points)
    wsum = np.zeros(len(points))
    for i, nb in enumerate(nbrs):
        nb = sorted(nb)
        e = cage[nb] - cage[i]
        es = target[nb] - target[i]
        a = np.linalg.lstsq(e, es, rcond=None)[0]
        d = points - cage[i]
        w = falloff(np.linalg.norm(d, axis=1) / np.linalg.norm(e, axis=1).max(), alpha, beta)
        for ej in e:
            w = w * falloff(d @ ej / (ej @ ej), gamma, mu)
        moved = target[i] + d @ a
        disp += w[:, None] * (moved - points)
        wsum += w
    out = points.copy()
    hit = wsum > 0
    out[hit] += disp[hit] / wsum[hit, None]
    return out


def random_points(n, seed, lo=-1.2, hi=1.2):
    return np.random.default_rng(seed).uniform(lo, hi, size=(n, 3)).astype(np.float32)


def jittered_target(seed, amount=0.2):
    return (OCTA_POINTS + np.random.default_rng(seed).uniform(-amount, amount, size=OCTA_POINTS.shape)).astype(np.float32)


def test_identity_when_target_equals_cage():
    pts = random_points(2000, 1)
    out = dk.mesh_warp(pts, OCTA_POINTS, OCTA_COUNTS, OCTA_INDICES, OCTA_POINTS)
    assert out.dtype == np.float32 and out.shape == pts.shape
    np.testing.assert_allclose(out, pts, atol=1e-6)


def test_matches_numpy_reference():
    pts = random_points(3000, 2)
    target = jittered_target(3)
    out = dk.mesh_warp(pts, OCTA_POINTS, OCTA_COUNTS, OCTA_INDICES, target, 0.1, 1.1, -0.05, 0.95)
    ref = reference(pts, OCTA_POINTS, OCTA_FACES, target, 0.1, 1.1, -0.05, 0.95)
    assert np.abs(ref - pts).max() > 0.1  # the warp does something
    np.testing.assert_allclose(out, ref, atol=2e-5)


def test_interpolates_control_vertices():
    target = jittered_target(4, 0.3)
    out = dk.mesh_warp(OCTA_POINTS, OCTA_POINTS, OCTA_COUNTS, OCTA_INDICES, target)
    np.testing.assert_allclose(out, target, atol=1e-5)


def test_rigid_motion_of_the_cage_moves_the_surface_rigidly():
    angle = 0.8
    axis = np.array([1.0, -2.0, 0.5]) / np.linalg.norm([1.0, -2.0, 0.5])
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    rot = np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k  # Rodrigues
    shift = np.array([0.5, -1.0, 2.0])
    target = (OCTA_POINTS @ rot.T + shift).astype(np.float32)
    pts = random_points(3000, 5, -0.6, 0.6)
    pts = pts[np.abs(pts).sum(axis=1) < 0.95]  # inside the octahedron: every point is reached
    out = dk.mesh_warp(pts, OCTA_POINTS, OCTA_COUNTS, OCTA_INDICES, target)
    np.testing.assert_allclose(out, pts @ rot.T + shift, atol=1e-5)


def test_class_binds_once_and_evaluates_many_targets():
    pts = random_points(1500, 6)
    warp = dk.MeshWarp(OCTA_POINTS, OCTA_COUNTS, OCTA_INDICES)
    assert warp.num_control_vertices == 6 and not warp.is_bound
    with pytest.raises(dk.InvalidInput, match="before bind"):
        warp.evaluate(OCTA_POINTS)
    warp.bind(pts)
    assert warp.is_bound and warp.num_field_entries > len(pts)
    for seed in (7, 8):
        target = jittered_target(seed)
        np.testing.assert_allclose(warp.evaluate(target), reference(pts, OCTA_POINTS, OCTA_FACES, target), atol=2e-5)
    target = jittered_target(9)
    full = warp.evaluate(target)
    weights = np.full(len(pts), 0.5, dtype=np.float32)
    part = warp.evaluate(target, weights=weights, envelope=0.8)
    np.testing.assert_allclose(part, pts + 0.4 * (full - pts), atol=1e-6)
    one_off = dk.mesh_warp(pts, OCTA_POINTS, OCTA_COUNTS, OCTA_INDICES, target, weights=weights, envelope=0.8)
    np.testing.assert_allclose(one_off, part, atol=1e-6)


def test_bad_input_names_the_element():
    pts = random_points(10, 10)
    with pytest.raises(dk.InvalidInput, match="target cage.*has 3 points"):
        dk.mesh_warp(pts, OCTA_POINTS, OCTA_COUNTS, OCTA_INDICES, OCTA_POINTS[:3])
    with pytest.raises(dk.InvalidInput, match="alpha < beta"):
        dk.mesh_warp(pts, OCTA_POINTS, OCTA_COUNTS, OCTA_INDICES, OCTA_POINTS, alpha=1.0, beta=0.5)
    bad = OCTA_POINTS.copy()
    bad[2, 1] = np.nan
    with pytest.raises(dk.InvalidInput, match="target cage point 2"):
        dk.mesh_warp(pts, OCTA_POINTS, OCTA_COUNTS, OCTA_INDICES, bad)
    with pytest.raises(dk.InvalidInput, match="points.*\\(n, 3\\)"):
        dk.mesh_warp(pts[:, :2], OCTA_POINTS, OCTA_COUNTS, OCTA_INDICES, OCTA_POINTS)
    with pytest.raises(dk.InvalidInput, match="weights"):
        dk.mesh_warp(pts, OCTA_POINTS, OCTA_COUNTS, OCTA_INDICES, OCTA_POINTS, weights=np.ones(3, dtype=np.float32))
    fin = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1]], dtype=np.float32)
    with pytest.raises(dk.TopologyError, match="edge \\(0, 1\\)"):
        dk.MeshWarp(fin, np.array([3, 3, 3]), np.array([0, 1, 2, 1, 0, 3, 0, 1, 4]))
