"""deformkit.UvWarpSolver, uv_warp and apply_redirect (the content-aware UV warp of Koniaris et al.) on a planar
UV-mapped grid whose positions equal its UVs: the identity warp's rigid stretch error has a closed form computed
here in numpy, an undeformed pose redirects every texel to its own centre, an identity redirect bakes the texture
unchanged and a one-texel shift moves it by one texel; bad input raises deformkit.InvalidInput naming it.
uvwarp_shot (the shot job) on two tiles against UvWarpSolver driven frame by frame, its resume, cancellation and
provenance headers."""
import json
import os

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


def disks(t=T, at=(0.25, 0.5, 0.75)):
    """Rigidity 1 in disks of radius 0.07 on a 3 x 3 lattice (u and v in `at`), 0 elsewhere, painted at texel
    centres."""
    c = texel_centres(t)
    rig = np.zeros((t, t), dtype=np.float32)
    for cu in at:
        for cv in at:
            rig[np.hypot(c[..., 0] - cu, c[..., 1] - cv) < 0.07] = 1.0
    return rig


def stretched(points, factor=1.5):
    out = points.copy()
    out[:, 0] *= factor
    return out


def identity_stretch_error(rig, n=T):
    """The rigid stretch error of the identity warp under x -> 1.5 x, in closed form: grid point
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
    # The solver's grid figures (diagnostics).
    expected, edges = identity_stretch_error(rig)
    assert m["grid_rigid_edges"] == edges and m["grid_skipped_edges"] == 0
    # The geometry images of a plane moved by a linear map are exact up to float32 rounding of positions ~1.
    assert m["grid_identity_stretch_error"] == pytest.approx(expected, rel=1e-5)
    assert m["grid_rigid_stretch_error"] <= 0.2 * m["grid_identity_stretch_error"]  # at least 80% removed
    assert m["grid_fold_overs"] == 0 and m["remaining_folds"] == 0 and m["grid_points_outside"] == 0
    assert m["grid_max_border_displacement"] == 0.0 and m["grid_max_masked_displacement"] == 0.0
    # Through the delivered redirect map: 4-connected texel edges whose texels are both rigid; for the
    # identity a horizontal edge stretches 1.5x (0.5 off), a vertical one not at all.
    rigid = rig >= 0.5
    horizontal = (rigid[:, 1:] & rigid[:, :-1]).sum()
    vertical = (rigid[1:, :] & rigid[:-1, :]).sum()
    assert m["identity_rigid_edges"] == horizontal + vertical
    assert m["identity_stretch_error"] == pytest.approx(0.5 * horizontal / (horizontal + vertical), rel=1e-5)
    assert m["rigid_stretch_removed"] >= 0.8
    assert m["inverted_triangles"] == 0 and m["off_chart_texels"] == 0 and m["chart_texels"] == T * T
    assert m["untangled_points"] == 0 and m["iterations"] > 0 and m["levels"] >= 1
    # The tile border does not move: grid[j, i] = (i / n, j / n) there, bit for bit in float32.
    rest = np.stack(np.meshgrid(np.arange(T + 1) / T, np.arange(T + 1) / T, indexing="xy"), axis=2)
    for edge in (np.s_[0, :], np.s_[-1, :], np.s_[:, 0], np.s_[:, -1]):
        np.testing.assert_array_equal(grid[edge], rest[edge].astype(np.float32))
    # Inside, the warp moved: rigid disks were pulled together (an identity would keep the error).
    assert np.abs(grid - rest).max() > 0.5 / T
    np.testing.assert_array_equal(solver.warp, grid)


def test_a_grid_coarser_than_the_maps_removes_as_much_as_maps_of_its_size():
    # Disks at the tile's border too, painted at T and at 4 T, solved on a grid of T cells: the finer map's
    # solve removes as much of the stretch. The warp mask's band of fixed points along the border is a cell
    # wide for both; at one texel of the finer map it was a quarter of a cell, and the solve made the
    # stretch worse than no warp (-72% removed under a 1.5x stretch).
    pts, counts, idx, uvs, uv_idx = plane()
    removed = {}
    for t in (T, 4 * T):
        rig = disks(t, at=(0.06, 0.5, 0.94))
        solver = dk.UvWarpSolver(pts, counts, idx, uvs, uv_idx, 1001, rig, resolution=T)
        assert (solver.texels, solver.cells) == (t, T)
        solver.solve(stretched(pts))
        removed[t] = solver.metrics()["rigid_stretch_removed"]
    assert removed[T] >= 0.45
    assert removed[4 * T] >= removed[T] - 0.03, removed


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
    assert m["rigid_stretch_error"] == pytest.approx(0.0, abs=1e-5) and m["inverted_triangles"] == 0
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
    options = dict(iterations=8, smoothing=0.2, sweeps_per_level=[1, 2], mask_border_width=2)
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


def test_tolerance_ends_a_settled_solve_and_is_reported():
    pts, counts, idx, uvs, uv_idx = plane()
    solver = dk.UvWarpSolver(pts, counts, idx, uvs, uv_idx, 1001, disks(), iterations=300, tolerance=0.02)
    solver.solve(stretched(pts))
    first = solver.metrics()
    assert first["converged"] and first["last_move"] <= 0.02 and 1 < first["iterations"] < 300
    assert first["remaining_folds"] == 0 and first["reverted_points"] >= 0
    # The same pose again, warm-started: its run sweeps every level first again (docs/decisions.md UV-38), so
    # it settles anew, in about as many iterations as from the identity (58 against 56), and stops there.
    solver.solve(stretched(pts))
    again = solver.metrics()
    assert again["converged"] and again["last_move"] <= 0.02 and again["iterations"] < 300
    fixed = dk.UvWarpSolver(pts, counts, idx, uvs, uv_idx, 1001, disks(), iterations=5)
    fixed.solve(stretched(pts))
    assert fixed.metrics()["iterations"] == 5 and not fixed.metrics()["converged"]


def test_without_warm_start_a_solve_depends_on_its_frame_alone():
    pts, counts, idx, uvs, uv_idx = plane()
    frames = [stretched(pts), pts.copy(), stretched(pts)]
    history = dk.UvWarpSolver(pts, counts, idx, uvs, uv_idx, 1001, disks(), warm_start=False)
    for frame in frames:
        after_history = history.solve(frame).copy()
    alone = dk.UvWarpSolver(pts, counts, idx, uvs, uv_idx, 1001, disks(), warm_start=False).solve(frames[-1])
    np.testing.assert_array_equal(after_history, alone)
    warm = dk.UvWarpSolver(pts, counts, idx, uvs, uv_idx, 1001, disks())
    for frame in frames:
        warmed = warm.solve(frame).copy()
    assert np.abs(warmed - alone).max() > 1e-3 / T  # warm-started, the frames before it count


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
    nan_mask = np.ones_like(rig)
    nan_mask[3, 5] = np.nan  # neither side of 0.5: it froze the texel's points without a word
    with pytest.raises(dk.InvalidInput, match=r"warp mask.*texel \(5, 3\): warp mask value is NaN"):
        dk.UvWarpSolver(pts, counts, idx, uvs, uv_idx, 1001, rig, mask=nan_mask)
    with pytest.raises(dk.InvalidInput, match="orientation map, UDIM tile 1001: 32 texels per side"):
        dk.UvWarpSolver(pts, counts, idx, uvs, uv_idx, 1001, rig, orientation=np.ones((32, 32), np.float32))
    with pytest.raises(dk.InvalidInput, match="resolution: is 48"):
        dk.UvWarpSolver(pts, counts, idx, uvs, uv_idx, 1001, rig, resolution=48)
    with pytest.raises(dk.InvalidInput, match="UDIM tile 1002: holds no UV face"):
        dk.UvWarpSolver(pts, counts, idx, uvs, uv_idx, 1002, rig)
    for option, value, text in (("smoothing", 1.5, "smoothing: is 1.5"), ("damping", "x", "damping: is a str"),
                                ("iterations", 2.5, "iterations: is 2.5"), ("levels", -1, "levels: is -1"),
                                ("iterations", 0, r"iterations: is 0 \(expected a whole number from 1"),
                                ("coarse_stiffness", 0.0, r"coarse_stiffness: is 0.0 \(expected a number in \(0, 1\]"),
                                ("coarse_relaxation", 2.5, "coarse_relaxation: is 2.5"),
                                ("max_levels", -1, "max_levels: is -1"),
                                ("cold_iterations", -2, "cold_iterations: is -2"),
                                ("coarse_relaxation", 0.9,
                                 r"coarse_relaxation: is 0.9 \(expected a number from 1 to 2\)"),
                                ("tolerance", 2.0, "tolerance: is 2.0"),
                                ("warm_start", 1, r"warm_start: is 1 \(expected true or false\)"),
                                ("warm_start", None, r"warm_start: is a NoneType \(expected true or false\)"),
                                ("sweeps_per_level", [0, 0], r"sweeps_per_level: is \[0, 0\].*not all 0"),
                                ("sweeps_per_level", [1, -2], r"sweeps_per_level: is \[1, -2\]"),
                                ("sweeps_per_level", [1, "a"], "sweeps_per_level: is a list holding a str"),
                                ("mask_border_width", 0, "mask_border_width: is 0"),
                                ("border_width", 1, "border_width: is not an option"),
                                ("bogus", 1, "bogus: is not an option")):
        with pytest.raises(dk.InvalidInput, match=text):
            dk.UvWarpSolver(pts, counts, idx, uvs, uv_idx, 1001, rig, **{option: value})
    with pytest.raises(dk.InvalidInput, match="uv_warp_live_options: cells: is 0"):
        dk.uv_warp_live_options(0)
    with pytest.raises(dk.InvalidInput, match=r"cells: is 3 \(expected a power of two from 1 to 32768\)"):
        dk.uv_warp_live_options(3)
    identity = texel_centres().astype(np.float32)
    with pytest.raises(dk.InvalidInput, match="filter: is 'nearest'"):
        dk.apply_redirect(rig, identity, filter="nearest")
    with pytest.raises(dk.InvalidInput, match=r"redirect: has shape \(64, 64\)"):
        dk.apply_redirect(rig, identity[..., 0])
    # The arguments swapped: an RGB texture is no redirect map.
    with pytest.raises(dk.InvalidInput, match=r"redirect: has shape \(64, 64, 3\) \(expected \(R, R, 2\)"):
        dk.apply_redirect(identity, np.dstack([rig, rig, rig]))
    nan = identity.copy()
    nan[3, 4, 1] = np.nan
    with pytest.raises(dk.InvalidInput, match=r"\(4, 3\)"):
        dk.apply_redirect(rig, nan)


# ---- uvwarp_shot: the shot job ----

S = 32  # texels per side of the shot tests' maps
FRAMES = [1, 2, 3, 4]
# Few iterations: the tests compare against the same solve, not a quality. Warm-started (a shot's default is
# every frame from the identity): the replay of a resumed shot is what most of them check.
OPTIONS = dict(iterations=4, warm_start=True)
OUT = "redirect.<UDIM>.####.exr"


def two_tiles(n=16):
    """plane(n) in tile 1001 beside another in tile 1002, each with its own vertices; positions equal UVs."""
    a, b = plane(n), plane(n, tile_origin=(1.0, 0.0))
    b_points = b[0] + np.array([1.0, 0.0, 0.0], np.float32)
    return (np.concatenate([a[0], b_points]), np.concatenate([a[1], b[1]]),
            np.concatenate([a[2], b[2] + len(a[0])]), np.concatenate([a[3], b[3]]),
            np.concatenate([a[4], b[4] + len(a[3])]))


def shot_maps():
    """Per tile: a rigidity map (disks; in 1002 mirrored, so the tiles differ) and an RGB texture."""
    rng = np.random.default_rng(3)
    rig = {1001: disks(S), 1002: np.ascontiguousarray(disks(S)[:, ::-1])}
    tex = {tile: rng.uniform(0, 1, (S, S, 3)).astype(np.float32) for tile in rig}
    return rig, tex


def pose(points, frame):
    """Frame f stretches x by 1 + 0.15 f: a different pose every frame, so the warm start matters."""
    return stretched(points, 1.0 + 0.15 * frame)


def file_bytes(folder):
    return {name: (folder / name).read_bytes() for name in sorted(os.listdir(folder))}


def test_a_texture_file_bakes_in_its_own_pixel_type(tmp_path):
    # A float EXR texture (a displacement map) baked to EXR keeps float: it was written as half, 2.4e-4 off
    # apply_redirect. A half texture stays half; a texture given as an array takes the format's default.
    mesh = two_tiles()
    rig, tex = shot_maps()
    for kind in ("float", "half"):
        folder = tmp_path / kind
        folder.mkdir()
        for tile in (1001, 1002):
            dk.write_image(str(folder / f"tex.{tile}.exr"), tex[tile], type=kind)
        dk.uvwarp_shot(*mesh, [2], lambda f: pose(mesh[0], f), rig, str(folder / OUT),
                       texture=str(folder / "tex.<UDIM>.exr"), bake=str(folder / "col.<UDIM>.####.exr"), **OPTIONS)
        for tile in (1001, 1002):
            baked = str(folder / f"col.{tile}.0002.exr")
            assert dk.read_image_info(baked)["pixel_type"] == kind
            redirect = dk.read_image(str(folder / f"redirect.{tile}.0002.exr"))
            expected = dk.apply_redirect(dk.read_image(str(folder / f"tex.{tile}.exr")), redirect)
            if kind == "half":
                expected = expected.astype(np.float16).astype(np.float32)
            np.testing.assert_array_equal(dk.read_image(baked), expected)


def test_shot_writes_the_solvers_maps_frame_by_frame_with_provenance(tmp_path):
    mesh = two_tiles()
    rig, tex = shot_maps()
    asked, units = [], []

    def deformed(frame):
        asked.append(frame)
        return pose(mesh[0], frame), f"pose {frame}"

    def progress(done, total, unit):
        units.append((done, total, unit))

    report = dk.uvwarp_shot(*mesh, FRAMES, deformed, rig, str(tmp_path / OUT), texture=tex,
                            bake=str(tmp_path / "col.<UDIM>.####.exr"), progress=progress, rest_name="two planes",
                            **OPTIONS)
    assert asked == FRAMES  # each frame's positions asked for once, for both tiles
    # Units are tiles x frames, frame by frame: done counts them one by one.
    assert units == [(k + 1, 8, f"tile {tile} frame {frame} written")
                     for k, (frame, tile) in enumerate((f, t) for f in FRAMES for t in (1001, 1002))]
    assert sorted(report) == [1001, 1002]
    for tile in (1001, 1002):
        solver = dk.UvWarpSolver(*mesh, tile, rig[tile], preset="shot", **OPTIONS)  # a shot's, with OPTIONS
        r = report[tile]
        outs = [str(tmp_path / f"redirect.{tile}.{f:04d}.exr") for f in FRAMES]
        bakes = [str(tmp_path / f"col.{tile}.{f:04d}.exr") for f in FRAMES]
        assert (r["warped"], r["written"], r["baked"], r["replayed"], r["skipped"]) == (True, 4, 4, 0, 0)
        assert r["files"] == [p for pair in zip(outs, bakes) for p in pair] and r["notes"] == []
        for k, frame in enumerate(FRAMES):
            solver.solve(pose(mesh[0], frame))
            redirect = solver.redirect_map()
            written = dk.read_image(outs[k])
            assert written.shape == (S, S, 2)
            np.testing.assert_array_equal(written, redirect)  # bit for bit: float EXR
            # The bake is the module's apply_redirect of the same map, stored as half (EXR's default).
            expected = dk.apply_redirect(tex[tile], redirect).astype(np.float16).astype(np.float32)
            np.testing.assert_array_equal(dk.read_image(bakes[k]), expected)
            for path in (outs[k], bakes[k]):
                a = dk.read_image_info(path)["attributes"]
                assert a["deformkit:version"] == dk.__version__
                assert (a["deformkit:uvwarp:tile"], a["deformkit:uvwarp:frame"]) == (str(tile), str(frame))
                assert json.loads(a["deformkit:uvwarp:inputs"]) == {
                    "rest": "two planes", "rigidity": f"rigidity tile {tile}", "mask": "derived",
                    "orientation": "none", "texture": f"texture tile {tile}", "deformed": f"pose {frame}"}
                used = json.loads(a["deformkit:uvwarp:solver"])
                assert (used["iterations"], used["cells"], used["texels"], used["warmStart"]) == (4, S, S, True)
        metrics = solver.metrics()
        assert r["last_frame"] == 4 and r["metrics"] == {k: metrics[k] for k in r["metrics"]}
        assert r["summary"][0].startswith(f"tile {tile}: 4 frames written (4 baked), 0 replayed, 0 skipped")
    assert len(os.listdir(tmp_path)) == 16  # no temporary file left beside them


def test_shot_maps_in_memory_equal_maps_from_files(tmp_path):
    mesh = two_tiles()
    rig, _ = shot_maps()
    mask = {1001: np.ones((S, S), np.float32)}  # 1002 keeps a derived mask: a note
    maps, a, b = tmp_path / "maps", tmp_path / "a", tmp_path / "b"
    for folder in (maps, a, b):
        folder.mkdir()
    for tile in rig:
        dk.write_image(maps / f"rig.{tile}.exr", rig[tile], "float")
    dk.write_image(maps / "mask.1001.exr", mask[1001], "float")
    for frame in FRAMES:  # the deformed frames as an OBJ sequence, and as read back for the callable
        dk.write_mesh(str(maps / f"anim.{frame:04d}.obj"), dk.Mesh(pose(mesh[0], frame), *mesh[1:]))
    from_files = dk.uvwarp_shot(*mesh, FRAMES, str(maps / "anim.####.obj"), maps / "rig.<UDIM>.exr",
                                str(a / OUT), mask=str(maps / "mask.<UDIM>.exr"), **OPTIONS)
    in_memory = dk.uvwarp_shot(*mesh, FRAMES, lambda f: dk.read_mesh(str(maps / f"anim.{f:04d}.obj")).points,
                               rig, str(b / OUT), mask=("painted mask", mask), **OPTIONS)
    assert sorted(os.listdir(a)) == sorted(os.listdir(b)) and len(os.listdir(a)) == 8
    for name in os.listdir(a):
        np.testing.assert_array_equal(dk.read_image(a / name), dk.read_image(b / name))
    note = "no warp mask '{}': derived from the UVs"
    assert from_files[1002]["notes"] == [note.format(maps / "mask.1002.exr")]
    assert in_memory[1002]["notes"] == [note.format("painted mask tile 1002")]
    # The headers name where each input came from.
    inputs = json.loads(dk.read_image_info(a / "redirect.1001.0002.exr")["attributes"]["deformkit:uvwarp:inputs"])
    assert inputs == {"rest": "rest mesh", "rigidity": str(maps / "rig.1001.exr"),
                      "mask": str(maps / "mask.1001.exr"), "orientation": "none",
                      "deformed": str(maps / "anim.0002.obj")}
    inputs = json.loads(dk.read_image_info(b / "redirect.1001.0002.exr")["attributes"]["deformkit:uvwarp:inputs"])
    assert (inputs["rigidity"], inputs["mask"], inputs["deformed"]) == (
        "rigidity tile 1001", "painted mask tile 1001", "frame 2")


def test_shot_makes_the_folders_of_its_outputs_and_its_log(tmp_path):
    mesh = two_tiles()
    rig, _ = shot_maps()
    out, log = tmp_path / "maps" / "v1" / OUT, tmp_path / "logs" / "shot.jsonl"
    dk.uvwarp_shot(*mesh, FRAMES[:2], lambda f: pose(mesh[0], f), rig, str(out), log=str(log), **OPTIONS)
    assert sorted(os.listdir(tmp_path / "maps" / "v1")) == [
        f"redirect.{tile}.{frame:04d}.exr" for tile in (1001, 1002) for frame in FRAMES[:2]]
    assert len(log.read_text().splitlines()) == 4  # a line per tile and frame


def test_shot_by_default_solves_each_frame_from_the_identity(tmp_path):
    mesh = two_tiles()
    rig, _ = shot_maps()
    (tmp_path / "whole").mkdir()
    (tmp_path / "last").mkdir()
    dk.uvwarp_shot(*mesh, FRAMES, lambda f: pose(mesh[0], f), rig, str(tmp_path / "whole" / OUT), iterations=4)
    asked = []

    def deformed(frame):
        asked.append(frame)
        return pose(mesh[0], frame)

    dk.uvwarp_shot(*mesh, [3, 4], deformed, rig, str(tmp_path / "last" / OUT), iterations=4)
    for tile in (1001, 1002):
        for frame in (3, 4):
            name = f"redirect.{tile}.{frame:04d}.exr"
            whole = dk.read_image(str(tmp_path / "whole" / name))
            np.testing.assert_array_equal(dk.read_image(str(tmp_path / "last" / name)), whole)
            alone = dk.UvWarpSolver(*mesh, tile, rig[tile], preset="shot", iterations=4)
            alone.solve(pose(mesh[0], frame))
            np.testing.assert_array_equal(whole, alone.redirect_map())
    solver = json.loads(dk.read_image_info(str(tmp_path / "whole" / "redirect.1001.0004.exr"))["attributes"][
        "deformkit:uvwarp:solver"])
    assert solver["warmStart"] is False
    # A rerun that misses one output solves that frame only.
    (tmp_path / "whole" / "redirect.1001.0002.exr").unlink()
    report = dk.uvwarp_shot(*mesh, FRAMES, lambda f: pose(mesh[0], f), rig, str(tmp_path / "whole" / OUT),
                            iterations=4)
    assert (report[1001]["written"], report[1001]["replayed"], report[1001]["skipped"]) == (1, 0, 3)


def test_shot_resume_replays_the_warm_start_and_writes_the_same_bytes(tmp_path):
    mesh = two_tiles()
    rig, _ = shot_maps()
    out, log = str(tmp_path / OUT), tmp_path / "log.jsonl"
    dk.uvwarp_shot(*mesh, FRAMES, lambda f: pose(mesh[0], f), rig, out, **OPTIONS)
    full = file_bytes(tmp_path)
    missing = tmp_path / "redirect.1001.0003.exr"
    missing.unlink()
    asked = []

    def deformed(frame):
        asked.append(frame)
        return pose(mesh[0], frame)

    report = dk.uvwarp_shot(*mesh, FRAMES, deformed, rig, out, log=log, **OPTIONS)
    assert asked == [1, 2, 3]  # nothing after the last missing output is evaluated
    r = report[1001]
    assert (r["written"], r["replayed"], r["skipped"], r["files"]) == (1, 2, 1, [str(missing)])
    assert r["last_frame"] == 3
    r = report[1002]  # every output exists: the tile is not solved at all
    assert (r["written"], r["replayed"], r["skipped"], r["files"], r["metrics"]) == (0, 0, 4, [], None)
    assert file_bytes(tmp_path) == {**full, "log.jsonl": log.read_bytes()}  # the same bytes as the first run
    lines = [json.loads(line) for line in log.read_text().splitlines()]
    assert [(d["tile"], d["frame"], d["status"]) for d in lines] == [
        (1001, 1, "replayed"), (1002, 1, "skipped"), (1001, 2, "replayed"), (1002, 2, "skipped"),
        (1001, 3, "written"), (1002, 3, "skipped"), (1001, 4, "skipped"), (1002, 4, "skipped")]
    # skip_existing=False writes every output again, the same bytes.
    report = dk.uvwarp_shot(*mesh, FRAMES, lambda f: pose(mesh[0], f), rig, out, skip_existing=False, **OPTIONS)
    assert [report[t]["written"] for t in (1001, 1002)] == [4, 4]
    assert file_bytes(tmp_path) == {**full, "log.jsonl": log.read_bytes()}


@pytest.mark.parametrize("stop_after", [1, 3])
def test_shot_cancelled_from_progress_leaves_complete_files_and_a_rerun_completes(tmp_path, stop_after):
    mesh = two_tiles()
    rig, _ = shot_maps()
    a, b = tmp_path / "a", tmp_path / "b"
    a.mkdir()
    b.mkdir()
    dk.uvwarp_shot(*mesh, FRAMES, lambda f: pose(mesh[0], f), rig, str(a / OUT), **OPTIONS)
    calls = []

    def progress(done, total, unit):
        calls.append(done)
        return done == stop_after

    with pytest.raises(dk.Cancelled, match="cancelled") as cancelled:
        dk.uvwarp_shot(*mesh, FRAMES, lambda f: pose(mesh[0], f), rig, str(b / OUT), progress=progress, **OPTIONS)
    assert isinstance(cancelled.value, dk.Error) and calls == list(range(1, stop_after + 1))
    # Units run frame by frame over the tiles: exactly the first stop_after outputs exist, complete.
    done = [f"redirect.{t}.{f:04d}.exr" for f in FRAMES for t in (1001, 1002)][:stop_after]
    assert sorted(os.listdir(b)) == sorted(done)
    full = file_bytes(a)
    assert all(full[name] == (b / name).read_bytes() for name in done)
    report = dk.uvwarp_shot(*mesh, FRAMES, lambda f: pose(mesh[0], f), rig, str(b / OUT), **OPTIONS)
    assert sum(r["written"] for r in report.values()) == 8 - stop_after
    assert file_bytes(b) == full


def test_shot_bad_input_names_what_is_wrong(tmp_path):
    mesh = two_tiles()
    rig, _ = shot_maps()
    out = str(tmp_path / OUT)

    def run(**changes):
        args = dict(frames=FRAMES, deformed=lambda f: pose(mesh[0], f), rigidity=rig, out=out, **OPTIONS)
        args.update(changes)
        return dk.uvwarp_shot(*mesh, **args)

    for changes, error, text in (
            (dict(out=str(tmp_path / "redirect.####.exr")), dk.InvalidInput,
             "uvwarp_shot: out: .*redirect.####.exr: has no UDIM token"),
            (dict(out=str(tmp_path / "redirect.<UDIM>.exr")), dk.InvalidInput, "out: .*redirect.<UDIM>.exr: has no frame token"),
            (dict(out=str(tmp_path / "redirect.<UDIM>.####.png")), dk.InvalidInput, "out: .*redirect.<UDIM>.####.png: is not an .exr file"),
            (dict(rigidity="rig.exr"), dk.InvalidInput, "uvwarp_shot: rigidity: rig.exr: has no UDIM token"),
            (dict(mask={1001: np.ones((16, 16), np.float32)}), dk.InvalidInput,
             r"mask tile 1001: warp mask: 16 x 16 texels \(expected 32 x 32, the size of 'rigidity tile 1001'\)"),
            (dict(mask={1001: np.ones(16, np.float32)}), dk.InvalidInput, r"mask\[1001\]: has shape \(16,\)"),
            (dict(rigidity={"a": rig[1001]}), dk.InvalidInput, "rigidity key 'a': is a str"),
            (dict(rigidity={1001: "x"}), dk.InvalidInput, r"rigidity\[1001\]: is a str"),
            (dict(rigidity={}), dk.InvalidInput, "rigidity: has no tile"),
            (dict(rigidity=None), dk.InvalidInput, "rigidity: is None"),
            (dict(rigidity={1003: rig[1001]}), dk.IoError, "rigidity: no tile has a rigidity map"),
            (dict(texture={1001: rig[1001]}), dk.InvalidInput, "texture: given without bake"),
            (dict(frames=[]), dk.InvalidInput, "frames: is empty"),
            (dict(frames=[2, 1]), dk.InvalidInput, "frames: are not ascending"),
            (dict(tiles=[1005]), dk.InvalidInput, "tile 1005: the rest mesh 'rest mesh' has no UV face in it"),
            # An empty list is not None (every tile): a farm split that made one would rewrite every tile.
            (dict(tiles=[]), dk.InvalidInput, r"uvwarp_shot: tiles: is an empty list \(expected None for every tile"),
            (dict(tiles=[1002, 1001, 1002]), dk.InvalidInput, "tiles: lists tile 1002 twice"),
            (dict(mask={1001: np.full((32, 32), np.nan, np.float32)}), dk.InvalidInput,
             r"mask tile 1001.*texel \(0, 0\): warp mask value is NaN"),
            (dict(deformed=7), dk.InvalidInput, "deformed: is an int"),
            (dict(deformed="anim.obj"), dk.InvalidInput, "uvwarp_shot: deformed: anim.obj: has no frame token"),
            (dict(deformed=str(tmp_path / "anim.####.obj")), dk.IoError, "anim.0001.obj: frame 1: is missing"),
            (dict(deformed=lambda f: mesh[0][:5]), dk.InvalidInput, r"deformed\(1\): returned shape \(5, 3\)"),
            (dict(deformed=lambda f: None), dk.InvalidInput, r"deformed\(1\): returned a NoneType \(expected"),
            # A NaN in a frame is the frame's fault, named by the name it was given (it blamed the rest mesh).
            (dict(deformed=lambda f: (np.where(np.arange(len(mesh[0]))[:, None] == 7, np.nan, pose(mesh[0], f))
                                      .astype(np.float32), f"take_{f}.abc")),
             dk.InvalidInput, "take_1.abc: frame 1: vertex 7: is not finite"),
            # Without a name the frame is the input's name, said once.
            (dict(deformed=lambda f: np.where(np.arange(len(mesh[0]))[:, None] == 7, np.nan, pose(mesh[0], f))
                  .astype(np.float32)),
             dk.InvalidInput, r"^frame 1: vertex 7: is not finite"),
            # Finite but where the solver's squared lengths would overflow: named by the frame, not the rest.
            (dict(deformed=lambda f: (pose(mesh[0], f) * np.float32(1e18)).astype(np.float32)),
             dk.InvalidInput, r"^frame 1: vertex 1: is \(7.1874998e\+16, 0, 0\) \(expected finite coordinates within \+-1e15"),
            (dict(progress=3), dk.InvalidInput, "progress: is an int"),
            (dict(smoothing=2.0), dk.InvalidInput, "uvwarp_shot: smoothing: is 2.0"),
            (dict(filter="nearest"), dk.InvalidInput, "filter: is 'nearest'")):
        with pytest.raises(error, match=text):
            run(**changes)
    assert os.listdir(tmp_path) == []  # every check came before the first output
    # A missing output folder is made; one behind a regular file is named.
    (tmp_path / "afile").write_text("x")
    with pytest.raises(dk.IoError, match="afile' is a file, not a folder"):
        run(out=str(tmp_path / "afile" / OUT))
    # An exception raised in a callback reaches the caller unchanged.
    with pytest.raises(ZeroDivisionError):
        run(progress=lambda done, total, unit: 1 / 0)
    with pytest.raises(KeyError):
        run(deformed=lambda f: {}[f])


def test_tile_frame_path_names_outputs():
    assert dk.tile_frame_path(OUT, 1001, 7) == "redirect.1001.0007.exr"
    assert dk.tile_frame_path("out/col.<UDIM>.%03d.exr", 1012, 24) == os.path.join("out", "col.1012.024.exr")


def test_shot_follows_animated_rigidity_maps(tmp_path):
    """rig.<UDIM>.####.exr: one map per frame. The warp gets a frame's map only when it changed (here at frame
    3, to none): frames before it are the static job's bytes, frames from it differ, and the header names the
    frame's map."""
    mesh = two_tiles()
    rig, _ = shot_maps()
    maps, a, b = tmp_path / "maps", tmp_path / "a", tmp_path / "b"
    for folder in (maps, a, b):
        folder.mkdir()
    for tile in rig:
        for frame in FRAMES:
            dk.write_image(maps / f"rig.{tile}.{frame:04d}.exr", rig[tile] if frame < 3 else np.zeros((S, S), np.float32),
                           "float")
    animated = dk.uvwarp_shot(*mesh, FRAMES, lambda f: pose(mesh[0], f), str(maps / "rig.<UDIM>.####.exr"),
                              str(a / OUT), **OPTIONS)
    still = dk.uvwarp_shot(*mesh, FRAMES, lambda f: pose(mesh[0], f), rig, str(b / OUT), **OPTIONS)
    for tile in (1001, 1002):
        assert animated[tile]["map_changes"] == 1 and still[tile]["map_changes"] == 0
        assert "maps changed at 1 frame" in animated[tile]["summary"][0]
        for frame in FRAMES:
            name = f"redirect.{tile}.{frame:04d}.exr"
            same = np.array_equal(dk.read_image(a / name), dk.read_image(b / name))
            assert same == (frame < 3), (tile, frame)
        inputs = json.loads(dk.read_image_info(a / f"redirect.{tile}.0003.exr")["attributes"]["deformkit:uvwarp:inputs"])
        assert inputs["rigidity"] == str(maps / f"rig.{tile}.0003.exr")


def test_shot_maps_of_several_channels_read_channel_0_and_say_so(tmp_path):
    """An RGBA rigidity map in memory (the rigidity in red) gives the one-channel map's redirect maps, with a
    note; UvWarpSolver, whose maps are one channel, refuses it naming the shape."""
    pts, counts, idx, uvs, uv_idx = plane()
    mesh = dk.Mesh(pts, counts, idx, uvs, uv_idx)
    rig = disks()
    rgba = np.stack([rig, np.full_like(rig, 0.3), 1 - rig, np.ones_like(rig)], axis=2)
    out = {}
    for name, maps in (("one", {1001: rig}), ("rgba", {1001: rgba})):
        (tmp_path / name).mkdir()
        report = dk.uvwarp_shot(mesh, [1], lambda f: stretched(pts), maps,
                                str(tmp_path / name / "r.<UDIM>.####.exr"), iterations=2)
        out[name] = (dk.read_image(str(tmp_path / name / "r.1001.0001.exr")), report[1001]["notes"])
    np.testing.assert_array_equal(out["one"][0], out["rgba"][0])
    assert out["one"][1] == []
    assert len(out["rgba"][1]) == 1 and "has 4 channels: channel 0 (red) is read" in out["rgba"][1][0]
    with pytest.raises(dk.InvalidInput, match=r"rigidity: has shape \(64, 64, 4\)"):
        dk.UvWarpSolver(mesh, 1001, rgba)


def test_a_map_worse_than_no_warp_is_said(tmp_path):
    # Charts inset to [0.05, 0.95] with a warp mask of 1 everywhere: the solver moves content across the
    # empty border, and the delivered maps hold more rigid stretch than the identity. They were written with
    # nothing said; the shot notes it once, with the first such frame.
    grid = dk.make_grid(16, 16)
    points = np.asarray(grid.points).copy()
    mesh = (points, grid.face_counts, grid.face_indices, np.asarray(grid.uvs) * 0.9 + 0.05, grid.uv_indices)

    def pose(frame):
        moved = points.copy()
        moved[:, 0] *= 1 + 0.3 * frame
        moved[:, 2] = 0.2 * np.sin(3 * points[:, 0] * frame)
        return moved

    y, x = np.mgrid[0:64, 0:64]
    rigidity = np.zeros((64, 64), np.float32)
    for cx in range(8, 64, 16):
        for cy in range(8, 64, 16):
            rigidity[(x - cx)**2 + (y - cy)**2 < 4.6**2] = 1
    report = dk.uvwarp_shot(*mesh, [1, 2], pose, {1001: rigidity}, str(tmp_path / "r.<UDIM>.####.exr"),
                            mask={1001: np.ones((64, 64), np.float32)})[1001]
    assert report["metrics"]["rigid_stretch_removed"] < 0
    worse = [note for note in report["notes"] if "holds more rigid stretch than no warp" in note]
    assert len(worse) == 1 and worse[0].startswith("frame 1: ")
    # The same rigidity without the mask removes stretch, and nothing is said.
    plain = dk.uvwarp_shot(*mesh, [1, 2], pose, {1001: rigidity}, str(tmp_path / "p.<UDIM>.####.exr"))[1001]
    assert plain["metrics"]["rigid_stretch_removed"] > 0.3  # 41%
    assert not any("no warp" in note for note in plain["notes"])
