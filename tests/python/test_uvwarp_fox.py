"""The UV warp on a rigged character as a DCC hands it over: the Khronos Fox (tests/data/fox: 290 vertices,
14 UV charts in tile 1001), skinned to its armature and animated by its own Run clip in Blender, exported as
a 24-frame OBJ shot. Rigid disks are painted inside its charts; every frame is solved with the shot preset
(from the identity) and measured on the redirect map it delivers (deformkit.redirect_metrics). The invariants
that hold on any input are asserted on every frame, and again over random poses and random rigid layouts,
each checked here in numpy apart from the library's own count: no inverted triangle of the redirect map's
texel-centre grid, no chart texel showing content off the charts, finite maps. The quality figures are
printed and held to floors just under what is measured, at 256^2 to stay quick (docs/uvwarp_quality.md gives the
1024^2 figures against the targets)."""
import os
import subprocess
import sys

import numpy as np
import pytest

import deformkit as dk

# The chart coverage and the disk layout of the figures docs/uvwarp_quality.md quotes (scripts/uvwarp_rigged_figures.py).
sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "scripts"))
from uvwarp_rigged_figures import chart_texels, rigid_disks, whole_disks  # noqa: E402

SHOT = os.path.join(os.path.dirname(__file__), "..", "data", "fox")
T = 256


def uv_triangles(mesh):
    """(K, 3, 2) float64: the UV triangles of the mesh, fan-triangulated."""
    uv = mesh.uvs.astype(np.float64)
    out, offset = [], 0
    for count in mesh.face_counts:
        corners = mesh.uv_indices[offset:offset + count]
        offset += count
        out += [(uv[corners[0]], uv[corners[k]], uv[corners[k + 1]]) for k in range(1, count - 1)]
    return np.asarray(out)


def inverted_triangles(redirect):
    """Triangles of the texel-centre grid of a (T, T, 2) redirect map, both splittings of every cell, wound
    counter-clockwise for the identity (v up), whose cross product is negative."""
    r = redirect.astype(np.float64)
    bl, br, tr, tl = r[1:, :-1], r[1:, 1:], r[:-1, 1:], r[:-1, :-1]

    def cross(a, b, c):
        return (b[..., 0] - a[..., 0]) * (c[..., 1] - a[..., 1]) - (b[..., 1] - a[..., 1]) * (c[..., 0] - a[..., 0])

    return int(sum((cross(*t) < 0).sum() for t in ((bl, br, tr), (bl, tr, tl), (bl, br, tl), (br, tr, tl))))


def off_chart_texels(redirect, inside, triangles, t):
    """Chart texels (inside) whose content r lies in no UV triangle (1e-7 barycentric slack, float rounding on
    a border); texels showing their own centre are on their chart and skipped. Points are bucketed on a 64 x 64
    grid so each triangle tests only those near it."""
    y, x = np.nonzero(inside)
    q = np.stack([(x + 0.5) / t, 1 - (y + 0.5) / t], -1)
    r = redirect[y, x].astype(np.float64)
    r = r[np.abs(r - q).max(axis=1) > 1e-6]
    g = 64
    cell = np.clip(np.floor(r * g).astype(int), 0, g - 1)
    order = np.argsort(cell[:, 1] * g + cell[:, 0], kind="stable")
    starts = np.searchsorted((cell[:, 1] * g + cell[:, 0])[order], np.arange(g * g + 1))
    found = np.zeros(len(r), bool)
    for a, b, c in triangles:
        lo = np.clip(np.floor((np.minimum.reduce([a, b, c]) - 1e-6) * g).astype(int), 0, g - 1)
        hi = np.clip(np.floor((np.maximum.reduce([a, b, c]) + 1e-6) * g).astype(int), 0, g - 1)
        near = np.concatenate([order[starts[row * g + lo[0]]:starts[row * g + hi[0] + 1]]
                               for row in range(lo[1], hi[1] + 1)])
        if not len(near):
            continue
        e0, e1, p = b - a, c - a, r[near] - a
        den = e0[0] * e1[1] - e1[0] * e0[1]
        if den == 0:
            continue
        l1 = (p[:, 0] * e1[1] - e1[0] * p[:, 1]) / den
        l2 = (e0[0] * p[:, 1] - p[:, 0] * e0[1]) / den
        found[near[(l1 >= -1e-7) & (l2 >= -1e-7) & (l1 + l2 <= 1 + 1e-7)]] = True
    return int((~found).sum())



def assert_fold_free_on_charts(m, redirect, inside, triangles, t, label):
    """The delivered map's invariants, by the library's count (metrics m) and by this file's own: no inverted
    triangle, no chart texel showing content off the charts."""
    assert m["inverted_triangles"] == 0 and inverted_triangles(redirect) == 0, label
    assert m["off_chart_texels"] == 0 and off_chart_texels(redirect, inside, triangles, t) == 0, label

def test_the_fox_running_keeps_its_rigid_disks_through_every_frame():
    rest = dk.read_mesh(os.path.join(SHOT, "rest.obj"))
    assert rest.udim_tiles() == [1001]
    rigidity = rigid_disks(chart_texels(rest, T), T)
    assert rigidity.sum() > 2000
    solver = dk.UvWarpSolver(rest, 1001, rigidity, preset="shot")
    inside, triangles = chart_texels(rest, T), uv_triangles(rest)
    removed, repaired = [], []
    for frame in range(1, 25):
        posed = dk.read_mesh(os.path.join(SHOT, f"anim.{frame:04d}.obj"))
        assert posed.points.shape == rest.points.shape
        grid = solver.solve(posed.points)
        m = solver.metrics()
        redirect = solver.redirect_map()
        assert np.isfinite(grid).all() and np.isfinite(redirect).all()
        assert m["grid_fold_overs"] == 0, frame
        assert_fold_free_on_charts(m, redirect, inside, triangles, T, frame)
        assert m["repair_regions_scaled"] == 0, frame  # smoothing alone unfolded the map
        assert m["identity_stretch_error"] > 0.01, frame  # skinning does stretch the texture
        removed.append(m["rigid_stretch_removed"])
        repaired.append(m["repair_inverted_found"])
    removed = np.array(removed)
    print(f"Fox Run at {T}^2, shot preset: {100 * np.median(removed):.1f}% of the rigid stretch removed (median), "
          f"worst {100 * removed.min():.1f}% (frame {removed.argmin() + 1}); the fold repair unfolded "
          f"{sum(repaired)} inverted triangles in {sum(1 for i in repaired if i)} frames")
    # Measured 64.9% median, 58.3% worst at 256^2 (the disks are 6 texels across).
    assert np.median(removed) > 0.62 and removed.min() > 0.55


def test_the_fox_running_meets_the_goal_at_1024():
    """The goal docs/uvwarp_quality.md measures against: with the shot preset at 1024^2, at least 85% of the
    rigid stretch removed on the median frame and 75% on the worst, through the delivered maps (the metric is
    checked against a second implementation in test_redirect_metrics.py), no inverted triangle."""
    t = 1024
    rest = dk.read_mesh(os.path.join(SHOT, "rest.obj"))
    solver = dk.UvWarpSolver(rest, 1001, rigid_disks(chart_texels(rest, t), t), preset="shot")
    removed = []
    for frame in range(1, 25):
        solver.solve(dk.read_mesh(os.path.join(SHOT, f"anim.{frame:04d}.obj")).points)
        m = solver.metrics()
        assert m["inverted_triangles"] == 0 and inverted_triangles(solver.redirect_map()) == 0, frame
        assert m["off_chart_texels"] == 0, frame
        removed.append(m["rigid_stretch_removed"])
    removed = np.array(removed)
    print(f"Fox Run at {t}^2, shot preset: {100 * np.median(removed):.1f}% median, worst {100 * removed.min():.1f}%")
    # Measured 85.1% median, 77.7% worst (frame 19).
    assert np.median(removed) >= 0.85 and removed.min() >= 0.75


def test_the_figures_gap_to_the_shot_preset_is_each_frames_difference():
    # The script's --gap-to-shot against a second computation here: the live preset warm-started over frames
    # 20-24 in order, the shot preset from the identity on each, both measured on their delivered maps.
    script = os.path.join(os.path.dirname(__file__), "..", "..", "scripts", "uvwarp_rigged_figures.py")
    out = subprocess.run([sys.executable, script, SHOT, "--texels", str(T), "--first", "20", "--python",
                          os.path.dirname(dk.__file__), "--option", "preset=live", "--gap-to-shot"],
                         capture_output=True, text=True, check=True).stdout
    printed = [float(g) for g in out.split("per frame gap:")[1].split("\n")[0].split()]
    rest = dk.read_mesh(os.path.join(SHOT, "rest.obj"))
    rigidity = rigid_disks(chart_texels(rest, T), T)
    live = dk.UvWarpSolver(rest, 1001, rigidity, preset="live")
    shot = dk.UvWarpSolver(rest, 1001, rigidity, preset="shot")  # every solve from the identity
    expected = []
    for frame in range(20, 25):
        posed = dk.read_mesh(os.path.join(SHOT, f"anim.{frame:04d}.obj"))
        removed = []
        for solver in (shot, live):
            solver.solve(posed.points)
            removed.append(dk.redirect_metrics(rest, 1001, rigidity, posed.points,
                                               solver.redirect_map())["rigid_stretch_removed"])
        expected.append(100 * (removed[0] - removed[1]))
    print("gap per frame, printed:", printed, "expected:", np.round(expected, 2))
    assert len(printed) == 5 and np.allclose(printed, expected, atol=0.051)
    assert f"within 3 points on {sum(g <= 3 for g in expected)} of 5 frames" in out


def test_the_figures_split_the_disks_into_whole_and_cut():
    # A square chart over [0, 0.47]^2 of the tile: the disks centred at 0.05 .. 0.35 lie inside it with their
    # margin, those at 0.45 reach past 0.47 and are cut, the others are off the chart.
    t = 256
    y, x = np.meshgrid(np.arange(t), np.arange(t), indexing="ij")
    u, v = (x + 0.5) / t, 1 - (y + 0.5) / t
    inside = (u < 0.47) & (v < 0.47)
    rigidity = rigid_disks(inside, t)
    whole = whole_disks(rigidity, t)
    cut = rigidity - whole
    assert set(np.unique(whole)) <= {0.0, 1.0} and (cut >= 0).all()
    for cu in np.arange(0.05, 1, 0.1):
        for cv in np.arange(0.05, 1, 0.1):
            disk = np.hypot(u - cu, v - cv) < 0.025
            if max(cu, cv) < 0.4:
                assert whole[disk].all() and not cut[disk].any(), (cu, cv)
            elif max(cu, cv) < 0.5:
                assert not whole[disk].any() and cut[disk].any() and not cut[disk].all(), (cu, cv)
            else:
                assert not rigidity[disk].any(), (cu, cv)
    # The margin: rigid texels stay that many texels off the chart's edge (u < 0.47: texel 119 is the last inside).
    for margin in (1, 4):
        assert rigid_disks(inside, t, margin)[:, 119 - margin + 1:].sum() == 0
        assert rigid_disks(inside, t, margin)[:, 119 - margin].sum() > 0


def test_random_poses_and_rigid_layouts_give_fold_free_on_chart_maps():
    """Poses drawn from the span of the Fox's own skinned frames (random convex mixtures, pushed up to 1.5
    times as far from the rest pose, so skinning's collapsed triangles get worse), rigid disks of random
    size anywhere in the charts, borders and joints included, at 512^2 and 1024^2, shot and live presets.
    The solves leave inverted texel triangles in the maps' first draft (the repair reports how many); what is
    delivered has none."""
    rest = dk.read_mesh(os.path.join(SHOT, "rest.obj"))
    frames = np.stack([dk.read_mesh(os.path.join(SHOT, f"anim.{f:04d}.obj")).points for f in range(1, 25)])
    triangles = uv_triangles(rest)
    rng = np.random.default_rng(7)
    cases, unfolded = 0, 0
    for t in (512, 1024):
        inside = chart_texels(rest, t)
        y, x = np.meshgrid(np.arange(t), np.arange(t), indexing="ij")
        u, v = (x + 0.5) / t, 1 - (y + 0.5) / t
        for case in range(4):
            centres = rng.uniform(0, 1, (int(rng.integers(10, 60)), 2))
            radii = rng.uniform(0.005, 0.04, len(centres))
            disks = np.zeros((t, t), bool)
            for (cu, cv), radius in zip(centres, radii):
                disks |= np.hypot(u - cu, v - cv) < radius
            rigidity = (disks & inside).astype(np.float32)
            solver = dk.UvWarpSolver(rest, 1001, rigidity, preset="shot" if case % 2 == 0 else "live")
            for pose in range(2):
                weights = rng.dirichlet(np.full(len(frames), 0.3))
                reach = rng.uniform(0.5, 1.5)
                posed = rest.points + reach * np.tensordot(weights, frames - rest.points, axes=1)
                solver.solve(posed.astype(np.float32))
                m = solver.metrics()
                redirect = solver.redirect_map()
                label = f"{t}^2 case {case} pose {pose}"
                assert np.isfinite(redirect).all(), label
                assert_fold_free_on_charts(m, redirect, inside, triangles, t, label)
                unfolded += m["repair_inverted_found"]
                cases += 1
            # The checks see what they look for: a chart texel sent off the charts (to the tile's corner,
            # which no chart of the Fox reaches) and one pushed across its neighbours.
            broken = redirect.copy()
            ys, xs = np.nonzero(inside)
            broken[ys[len(ys) // 2], xs[len(ys) // 2]] = (0.999, 0.001)
            assert off_chart_texels(broken, inside, triangles, t) == 1
            assert inverted_triangles(broken) > 0
    print(f"{cases} random poses and layouts: {unfolded} inverted triangles unfolded, none delivered")
    assert cases == 16 and unfolded > 100


def test_a_grid_coarser_than_the_map_delivers_no_off_chart_texel():
    """A grid of a quarter or half the map's size cannot follow a chart border texel by texel. Its warp mask
    keeps a band a cell wide along the borders fixed (within one map texel, a fraction of a cell, the
    inverse sent thousands of texels a frame next to borders to content off the charts, which the repair
    then placed back): what is delivered shows no texel off the charts and no fold, and the repair finds
    none to place back (its own test: tests/unit/uvwarp/redirect_repair_test.cpp)."""
    rest = dk.read_mesh(os.path.join(SHOT, "rest.obj"))
    frames = np.stack([dk.read_mesh(os.path.join(SHOT, f"anim.{f:04d}.obj")).points for f in range(1, 25)])
    triangles = uv_triangles(rest)
    rng = np.random.default_rng(11)
    t = 512
    inside = chart_texels(rest, t)
    placed = 0
    for cells in (128, 256):
        for case in range(2):
            rigidity = rigid_disks(inside, t) if case == 0 else (inside & (rng.random((t, t)) < 0.3)).astype(
                np.float32)
            solver = dk.UvWarpSolver(rest, 1001, rigidity, resolution=cells, warm_start=False)
            for frame in rng.choice(24, 2, replace=False):
                solver.solve(frames[frame])
                m = solver.metrics()
                redirect = solver.redirect_map()
                label = f"{cells} cells case {case} frame {frame + 1}"
                assert_fold_free_on_charts(m, redirect, inside, triangles, t, label)
                placed += m["repair_off_chart_found"]
    print(f"grids of 128 and 256 cells on 512^2 maps: {placed} texels placed back on their charts, none delivered off")
    assert placed == 0


# Floors of the rigid stretch removed, under what was measured: on the disks 0.45-0.57 (grid) and 0.57-0.67
# (the preset's refinement; the map's grid alone 0.47-0.61), on the scattered texels 0.38-0.43 and 0.33-0.34
# (0.13-0.20).
@pytest.mark.parametrize("finer, floor", [({"resolution": 512, "refinement_sweeps": 0}, 0.3), ({}, 0.2)],
                         ids=["grid", "refinement"])
def test_a_grid_finer_than_the_map_delivers_fold_free_on_chart_maps(finer, floor):
    """A grid twice the map's size, solved on (resolution) or refining the solve on the map's grid (the shot
    preset's refinement by the grid's size; docs/uvwarp_quality.md): each texel's content is read from a
    warp of four cells; what is delivered still has no fold and no texel off the charts."""
    rest = dk.read_mesh(os.path.join(SHOT, "rest.obj"))
    triangles = uv_triangles(rest)
    rng = np.random.default_rng(12)
    t = 256
    inside = chart_texels(rest, t)
    for case in range(2):
        rigidity = rigid_disks(inside, t) if case == 0 else (inside & (rng.random((t, t)) < 0.3)).astype(np.float32)
        solver = dk.UvWarpSolver(rest, 1001, rigidity, preset="shot", **finer)
        assert solver.warp.shape == (2 * t + 1, 2 * t + 1, 2)
        for frame in rng.choice(24, 3, replace=False):
            solver.solve(dk.read_mesh(os.path.join(SHOT, f"anim.{frame + 1:04d}.obj")).points)
            m = solver.metrics()
            redirect = solver.redirect_map()
            label = f"case {case} frame {frame + 1}"
            assert redirect.shape == (t, t, 2), label
            assert np.isfinite(redirect).all(), label
            assert_fold_free_on_charts(m, redirect, inside, triangles, t, label)
            assert m["grid_fold_overs"] == 0, label
            assert m["rigid_stretch_removed"] > floor, label  # the warp does act
