"""deformkit.UvWarpSolver, uv_warp and apply_redirect (the content-aware UV warp of Koniaris et al.) on a planar
UV-mapped grid whose positions equal its UVs: the identity warp's rigid stretch error has a closed form computed
here in numpy, an undeformed pose redirects every texel to its own centre, an identity redirect bakes the texture
unchanged and a one-texel shift moves it by one texel; bad input raises deformkit.InvalidInput naming it."""
import numpy as np
import pytest

import deformkit as dk

N = 32  # quads per side of the mesh
T = 64  # texels per side of the maps (and grid cells, by default)


def plane(n=N, tile_origin=(0.0, 0.0)):
    """n x n quads covering tile-local uv [0, 1]^2 of the tile at `tile_origin`; vertex (i, j) = j (n + 1) + i
    sits at (i / n, j / n, 0), so rest positions equal tile-local UVs."""
    j, i = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    local = np.stack([i.ravel() / n, j.ravel() / n], axis=1)
    uvs = (local + np.asarray(tile_origin)).astype(np.float32)
    points = np.concatenate([local, np.zeros((len(local), 1))], axis=1).astype(np.float32)
    a = (np.arange(n)[:, None] * (n + 1) + np.arange(n)[None, :]).ravel()
    faces = np.stack([a, a + 1, a + n + 2, a + n + 1], axis=1).astype(np.int32).ravel()
    return points, np.full(n * n, 4, dtype=np.int32), faces, uvs, faces.copy()


def texel_centres(t=T):
    """(T, T, 2) closed form: texel (x, y) is centred at u = (x + 0.5) / T, v = 1 - (y + 0.5) / T (row 0 at v = 1)."""
    y, x = np.meshgrid(np.arange(t), np.arange(t), indexing="ij")
    return np.stack([(x + 0.5) / t, 1.0 - (y + 0.5) / t], axis=2)


def disks(t=T):
    """Rigidity 1 in disks of radius 0.07 on a 3 x 3 lattice, 0 elsewhere, painted at texel centres."""
    c = texel_centres(t)
    rig = np.zeros((t, t), dtype=np.float32)
    for cu in (0.25, 0.5, 0.75):
        for cv in (0.25, 0.5, 0.75):
            rig[np.hypot(c[..., 0] - cu, c[..., 1] - cv) < 0.07] = 1.0
    return rig


def stretched(points, factor=1.5):
    out = points.copy()
    out[:, 0] *= factor
    return out


def identity_stretch_error(rig, n=T):
    """The issue's rigid stretch error of the identity warp under x -> 1.5 x, in closed form: grid point
    (i, j) rests at (i / n, j / n) and its rigidity is the bilinear sample of the map there (n = T: the
    mean of the 2 x 2 texels around it, clamped at the border); an edge is rigid when the larger rigidity of its
    ends is >= 0.5. Horizontal edges stretch by 1.5 (error 0.5), vertical ones not at all, diagonals by
    sqrt(1.5^2 + 1) / sqrt(2)."""
    padded = np.pad(rig, 1, mode="edge")
    # Point (i, j) sits between image rows T - j - 1 and T - j and columns i - 1 and i (unpadded).
    r = np.zeros((n + 1, n + 1))
    for j in range(n + 1):
        rows = padded[n - j : n - j + 2]  # padded rows (T - j - 1) + 1 and (T - j) + 1
        r[j] = 0.25 * (rows[0, :-1] + rows[0, 1:] + rows[1, :-1] + rows[1, 1:])
    diagonal = abs(np.sqrt(1.5**2 + 1.0) / np.sqrt(2.0) - 1.0)
    total, count = 0.0, 0
    for (di, dj), error in (((1, 0), 0.5), ((0, 1), 0.0), ((1, 1), diagonal), ((-1, 1), diagonal)):
        a = r[: n + 1 - dj, max(0, -di) : n + 1 - max(0, di)]
        b = r[dj:, max(0, di) : n + 1 - max(0, -di)]
        rigid = np.maximum(a, b) >= 0.5
        total += error * rigid.sum()
        count += rigid.sum()
    return total / count, count


def test_stretch_keeps_rigid_disks_and_metrics_match_the_closed_form():
    pts, counts, idx, uvs, uv_idx = plane()
    rig = disks()
    solver = dk.UvWarpSolver(pts, counts, idx, uvs, uv_idx, 1001, rig)
    assert (solver.tile, solver.texels, solver.cells, solver.num_vertices) == (1001, T, T, len(pts))
    grid = solver.solve(stretched(pts))
    assert grid.dtype == np.float32 and grid.shape == (T + 1, T + 1, 2)  # n cells: n + 1 points per side
    m = solver.metrics()
    expected, edges = identity_stretch_error(rig)
    assert m["rigid_edges"] == edges and m["skipped_edges"] == 0
    # The geometry images of a plane moved by a linear map are exact up to float32 rounding of positions ~1.
    assert m["identity_stretch_error"] == pytest.approx(expected, rel=1e-5)
    assert m["rigid_stretch_error"] <= 0.2 * m["identity_stretch_error"]  # the issue's >= 80% reduction
    assert m["fold_overs"] == 0 and m["remaining_folds"] == 0 and m["points_outside"] == 0
    assert m["max_border_displacement"] == 0.0 and m["max_masked_displacement"] == 0.0
    assert m["untangled_points"] == 0 and m["iterations"] > 0 and m["levels"] >= 1
    # The tile border does not move: grid[j, i] = (i / n, j / n) there, bit for bit in float32.
    rest = np.stack(np.meshgrid(np.arange(T + 1) / T, np.arange(T + 1) / T, indexing="xy"), axis=2)
    for edge in (np.s_[0, :], np.s_[-1, :], np.s_[:, 0], np.s_[:, -1]):
        np.testing.assert_array_equal(grid[edge], rest[edge].astype(np.float32))
    # Inside, the warp moved: rigid disks were pulled together (an identity would keep the error).
    assert np.abs(grid - rest).max() > 0.5 / T
    np.testing.assert_array_equal(solver.warp, grid)


def test_undeformed_pose_redirects_to_texel_centres():
    pts, counts, idx, uvs, uv_idx = plane()
    solver = dk.UvWarpSolver(dk.Mesh(pts, counts, idx, uvs, uv_idx), 1001, disks())
    centres = texel_centres()
    before = solver.redirect_map()  # the identity before any solve
    assert before.dtype == np.float32 and before.shape == (T, T, 2)
    # Float32 uv in [0, 1] after barycentric interpolation: a few ulps of 1 (6e-8 each).
    np.testing.assert_allclose(before, centres, atol=1e-5)
    solver.solve(pts)
    np.testing.assert_allclose(solver.redirect_map(), centres, atol=1e-5)
    m = solver.metrics()
    assert m["rigid_stretch_error"] == pytest.approx(0.0, abs=1e-5) and m["fold_overs"] == 0
    # After a stretch, reset() brings back the identity warp.
    solver.solve(stretched(pts))
    assert np.abs(solver.redirect_map() - centres).max() > 0.5 / T
    solver.reset()
    np.testing.assert_allclose(solver.redirect_map(), centres, atol=1e-5)


def test_one_off_matches_the_solver_and_the_mesh_overload():
    pts, counts, idx, uvs, uv_idx = plane(tile_origin=(1.0, 0.0))  # tile 1002
    rig = disks()
    mask = np.ones((T, T, 1), dtype=np.float32)
    deformed = stretched(pts)
    options = dict(iterations=8, smoothing=0.2, sweeps_per_level=[1, 2], border_width=2)
    solver = dk.UvWarpSolver(pts, counts, idx, uvs, uv_idx, 1002, rig, mask=mask, resolution=32, **options)
    assert solver.cells == 32 and solver.texels == T
    assert solver.solve(deformed).shape == (33, 33, 2)
    expected = solver.redirect_map()
    # The same computation from scratch gives the same bits, through arrays or a Mesh.
    one_off = dk.uv_warp(pts, counts, idx, uvs, uv_idx, 1002, rig, deformed, mask=mask, resolution=32, **options)
    np.testing.assert_array_equal(one_off, expected)
    mesh = dk.Mesh(pts, counts, idx, uvs, uv_idx)
    np.testing.assert_array_equal(dk.uv_warp(mesh, 1002, rig, deformed, mask=mask, resolution=32, **options),
                                  expected)
    assert np.abs(expected - texel_centres()).max() > 0.5 / T  # the warp did something


def test_apply_redirect_identity_and_one_texel_shift():
    rng = np.random.default_rng(7)
    tex = rng.uniform(0, 1, (T, T, 3)).astype(np.float32)
    identity = texel_centres().astype(np.float32)
    # Sampling at texel centres: bilinear weights (1, 0); Catmull-Rom weights (0, 1, 0, 0). Float32 texel
    # coordinates of values up to 64 round to ~4e-6 of a texel, times a texel contrast <= 1.
    for f in ("bilinear", "bicubic"):
        out = dk.apply_redirect(tex, identity, filter=f)
        assert out.dtype == np.float32 and out.shape == tex.shape
        np.testing.assert_allclose(out, tex, atol=1e-5)
    # A 2-D texture comes back 2-D.
    flat = dk.apply_redirect(tex[..., 0], identity)
    assert flat.shape == (T, T)
    np.testing.assert_allclose(flat, tex[..., 0], atol=1e-5)
    # Reading one texel to the right: out[:, x] = tex[:, x + 1], the last column clamped to the edge texel.
    shift = identity.copy()
    shift[..., 0] += 1.0 / T
    out = dk.apply_redirect(tex, shift)
    np.testing.assert_allclose(out[:, :-1], tex[:, 1:], atol=1e-5)
    np.testing.assert_allclose(out[:, -1], tex[:, -1], atol=1e-5)


def test_bad_input_names_what_is_wrong():
    pts, counts, idx, uvs, uv_idx = plane()
    rig = disks()
    with pytest.raises(dk.InvalidInput, match="has no UVs"):
        dk.UvWarpSolver(dk.Mesh(pts, counts, idx), 1001, rig)
    with pytest.raises(dk.InvalidInput, match="has no UVs"):
        dk.UvWarpSolver(pts, counts, idx, None, None, 1001, rig)
    with pytest.raises(dk.InvalidInput, match="uvs: given without uv_indices"):
        dk.UvWarpSolver(pts, counts, idx, uvs, None, 1001, rig)
    solver = dk.UvWarpSolver(pts, counts, idx, uvs, uv_idx, 1001, rig)
    with pytest.raises(dk.InvalidInput, match=r"deformed_points: has shape \(5, 3\) \(expected \(1089, 3\)"):
        solver.solve(pts[:5])
    with pytest.raises(dk.InvalidInput, match=r"uv_warp: deformed_points: has shape \(1089, 2\)"):
        dk.uv_warp(pts, counts, idx, uvs, uv_idx, 1001, rig, pts[:, :2])
    bad = rig.copy()
    bad[12, 13] = 1.5
    with pytest.raises(dk.InvalidInput, match=r"rigidity map, UDIM tile 1001: texel \(13, 12\)"):
        dk.UvWarpSolver(pts, counts, idx, uvs, uv_idx, 1001, bad)
    bad[12, 13] = np.nan
    with pytest.raises(dk.InvalidInput, match=r"texel \(13, 12\)"):
        dk.UvWarpSolver(pts, counts, idx, uvs, uv_idx, 1001, bad)
    bad[12, 13] = -0.1
    with pytest.raises(dk.InvalidInput, match=r"texel \(13, 12\)"):
        dk.UvWarpSolver(pts, counts, idx, uvs, uv_idx, 1001, bad)
    with pytest.raises(dk.InvalidInput, match=r"rigidity: has shape \(64, 64, 3\)"):
        dk.UvWarpSolver(pts, counts, idx, uvs, uv_idx, 1001, np.zeros((T, T, 3), np.float32))
    with pytest.raises(dk.InvalidInput, match="square"):
        dk.UvWarpSolver(pts, counts, idx, uvs, uv_idx, 1001, rig[:, :32])
    with pytest.raises(dk.InvalidInput, match="warp mask.*32 texels per side"):
        dk.UvWarpSolver(pts, counts, idx, uvs, uv_idx, 1001, rig, mask=np.ones((32, 32), np.float32))
    with pytest.raises(dk.InvalidInput, match="resolution: is 48"):
        dk.UvWarpSolver(pts, counts, idx, uvs, uv_idx, 1001, rig, resolution=48)
    with pytest.raises(dk.InvalidInput, match="UDIM tile 1002: holds no UV face"):
        dk.UvWarpSolver(pts, counts, idx, uvs, uv_idx, 1002, rig)
    for option, value, text in (("smoothing", 1.5, "smoothing: is 1.5"), ("damping", "x", "damping: is a str"),
                                ("iterations", 2.5, "iterations: is a float"), ("levels", -1, "levels: is -1"),
                                ("coarse_stiffness", 0.0, "coarse_stiffness: is 0.0"),
                                ("sweeps_per_level", [], "sweeps_per_level: is empty"),
                                ("sweeps_per_level", [1, -2], r"sweeps_per_level\[1\]: is -2"),
                                ("border_width", 0, "border_width: is 0"), ("bogus", 1, "bogus: is not an option")):
        with pytest.raises(dk.InvalidInput, match=text):
            dk.UvWarpSolver(pts, counts, idx, uvs, uv_idx, 1001, rig, **{option: value})
    identity = texel_centres().astype(np.float32)
    with pytest.raises(dk.InvalidInput, match="filter: is 'nearest'"):
        dk.apply_redirect(rig, identity, filter="nearest")
    with pytest.raises(dk.InvalidInput, match=r"redirect: has shape \(64, 64\)"):
        dk.apply_redirect(rig, identity[..., 0])
    nan = identity.copy()
    nan[3, 4, 1] = np.nan
    with pytest.raises(dk.InvalidInput, match=r"\(4, 3\)"):
        dk.apply_redirect(rig, nan)
