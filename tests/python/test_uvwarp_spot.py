"""The UV warp on real layouts (Keenan Crane's Spot, tests/data/spot, and Bob, tests/data/bob), measured by a
metric written here, independent of the solver: geometry images of the rest and deformed mesh rasterised from the
UV triangles, and for every 8-connected grid edge with rigid ends inside one UV island the deformed 3D length
between the warped ends against the rest 3D length. Rigid disks painted inside the charts, and the same disks
unclipped, so that chart borders (pinned by the derived mask) cut them."""
import os

import numpy as np

import deformkit as dk

SPOT = os.path.join(os.path.dirname(__file__), "..", "data", "spot", "spot_quadrangulated.obj")
T = 256  # rigidity texels = grid cells
RASTER = 1024  # texels of the test's own UV-triangle look-up


class Layout:
    """For any uv of tile 1001: the fan triangle of the mesh holding it (a raster, then exact barycentric
    coordinates), its UV island (triangles sharing UV corners, welded by value), and a 3D point of given
    vertex positions."""

    def __init__(self, mesh):
        uv, ui, fi, fc = mesh.uvs.astype(np.float64), mesh.uv_indices, mesh.face_indices, mesh.face_counts
        tuv, tv, off = [], [], 0
        for c in fc:
            for k in range(1, c - 1):
                tuv.append((ui[off], ui[off + k], ui[off + k + 1]))
                tv.append((fi[off], fi[off + k], fi[off + k + 1]))
            off += c
        self.uv, self.tuv, self.tv = uv, np.array(tuv), np.array(tv)
        welded = {}
        weld = np.array([welded.setdefault((round(float(a), 7), round(float(b), 7)), i) for i, (a, b) in enumerate(uv)])
        parent = list(range(len(uv)))

        def find(x):
            while parent[x] != x:
                parent[x] = parent[parent[x]]
                x = parent[x]
            return x

        for t in self.tuv:
            a, b, c = (find(weld[x]) for x in t)
            parent[b] = a
            parent[find(c)] = find(a)
        self.island = np.array([find(weld[t[0]]) for t in self.tuv])
        self.raster = -np.ones((RASTER, RASTER), np.int64)
        corners = uv[self.tuv] * RASTER
        for t, (a, b, c) in enumerate(corners):
            lo = np.clip(np.floor(np.minimum(np.minimum(a, b), c)).astype(int), 0, RASTER - 1)
            hi = np.clip(np.ceil(np.maximum(np.maximum(a, b), c)).astype(int), 0, RASTER - 1)
            xs, ys = np.meshgrid(np.arange(lo[0], hi[0] + 1) + 0.5, np.arange(lo[1], hi[1] + 1) + 0.5)
            inside = (self.bary(a, b, c, xs, ys) >= -1e-9).all(0)
            self.raster[lo[1]:hi[1] + 1, lo[0]:hi[0] + 1][inside] = t

    @staticmethod
    def bary(a, b, c, x, y):
        d = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
        l1 = ((x - a[0]) * (c[1] - a[1]) - (y - a[1]) * (c[0] - a[0])) / d
        l2 = ((b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0])) / d
        return np.stack([1 - l1 - l2, l1, l2])

    def locate(self, u, v):
        x = np.clip((u * RASTER).astype(int), 0, RASTER - 1)
        y = np.clip((v * RASTER).astype(int), 0, RASTER - 1)
        t = self.raster[y, x]
        p = self.uv[self.tuv[np.maximum(t, 0)]]
        return t, self.bary(p[:, 0].T, p[:, 1].T, p[:, 2].T, u, v)

    def point(self, positions, t, b):
        return (b.T[:, :, None] * positions[self.tv[np.maximum(t, 0)]]).sum(1)


def measure(layout, rest, deformed, warp, rigid):
    """(mean |l_def / l_rest - 1| over the island-internal rigid edges, their count, edges whose warped ends
    left their island, inverted grid triangles of cells covered at rest)."""
    n = warp.shape[0] - 1
    jj, ii = np.mgrid[0:n + 1, 0:n + 1]
    t0, b0 = layout.locate((ii / n).ravel(), (jj / n).ravel())
    t1, b1 = layout.locate(warp[..., 0].ravel(), warp[..., 1].ravel())
    p0, p1 = layout.point(rest, t0, b0), layout.point(deformed, t1, b1)
    island0 = np.where(t0 >= 0, layout.island[np.maximum(t0, 0)], -1)
    island1 = np.where(t1 >= 0, layout.island[np.maximum(t1, 0)], -1)
    r = rigid.ravel()
    errors, left = [], 0
    for di, dj in ((1, 0), (0, 1), (1, 1), (1, -1)):
        i0, j0 = np.meshgrid(np.arange(max(0, -di), n + 1 - max(0, di)), np.arange(max(0, -dj), n + 1 - max(0, dj)))
        a, b = (j0 * (n + 1) + i0).ravel(), ((j0 + dj) * (n + 1) + i0 + di).ravel()
        keep = r[a] & r[b] & (t0[a] >= 0) & (t0[b] >= 0) & (island0[a] == island0[b])
        a, b = a[keep], b[keep]
        stays = (island1[a] == island0[a]) & (island1[b] == island0[a])
        left += int((~stays).sum())
        a, b = a[stays], b[stays]
        rest_length = np.linalg.norm(p0[a] - p0[b], axis=1)
        deformed_length = np.linalg.norm(p1[a] - p1[b], axis=1)
        errors.append(np.abs(deformed_length / rest_length - 1))
    errors = np.concatenate(errors)
    u, v = warp[..., 0], warp[..., 1]
    covered = (t0 >= 0).reshape(n + 1, n + 1)
    cells = covered[:-1, :-1] & covered[1:, :-1] & covered[:-1, 1:] & covered[1:, 1:]

    def area(ax, ay, bx, by, cx, cy):
        return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)

    lower = area(u[:-1, :-1], v[:-1, :-1], u[:-1, 1:], v[:-1, 1:], u[1:, 1:], v[1:, 1:])
    upper = area(u[:-1, :-1], v[:-1, :-1], u[1:, 1:], v[1:, 1:], u[1:, :-1], v[1:, :-1])
    return errors.mean(), len(errors), left, int((((lower <= 0) | (upper <= 0)) & cells).sum())


def folded_anywhere(warp):
    """Grid triangles of non-positive area over the whole tile, both diagonal splittings of every cell."""
    u, v = warp[..., 0], warp[..., 1]
    a, b, c, d = (u[:-1, :-1], v[:-1, :-1]), (u[:-1, 1:], v[:-1, 1:]), (u[1:, 1:], v[1:, 1:]), (u[1:, :-1], v[1:, :-1])

    def area(p, q, r):
        return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])

    return int(sum((area(*t) <= 0).sum() for t in ((a, b, c), (a, c, d), (a, b, d), (b, c, d))))


def bent(rest):
    """Spot bent about its length: each point turned about the x axis by 0.6 rad per unit of z."""
    centre = rest.mean(0)
    q = rest.copy()
    angle, y = 0.6 * (rest[:, 2] - centre[2]), rest[:, 1] - centre[1]
    q[:, 1] = centre[1] + y * np.cos(angle)
    q[:, 2] = rest[:, 2] + y * np.sin(angle)
    return q


def rigid_disks(layout, clip_to_charts=True):
    """Rigid disks (radius 0.025) on a 0.1 lattice as a T x T map, clipped to the chart interiors (texels whose
    4-texel neighbourhood is inside a chart) or not; and the same map at the grid points (point (i, j) at uv
    (i / T, j / T): the nearest texel), as booleans."""
    yy, xx = np.mgrid[0:T, 0:T]
    u, v = (xx + 0.5) / T, 1 - (yy + 0.5) / T
    t, _ = layout.locate(u.ravel(), v.ravel())
    covered = (t >= 0).reshape(T, T)
    interior = covered.copy()
    for dy in range(-4, 5):
        for dx in range(-4, 5):
            interior &= np.roll(np.roll(covered, dy, 0), dx, 1)
    centres = np.arange(0.05, 1, 0.1)
    disks = np.min([np.hypot(u - cu, v - cv) for cu in centres for cv in centres], axis=0) < 0.025
    rigidity = (disks & interior if clip_to_charts else disks).astype(np.float32)
    jj, ii = np.mgrid[0:T + 1, 0:T + 1]
    rigid = rigidity[np.clip(np.round((1 - jj / T) * T - 0.5).astype(int), 0, T - 1),
                     np.clip(np.round(ii / T * T - 0.5).astype(int), 0, T - 1)] >= 0.5
    return rigidity, rigid


def spot_case(clip_to_charts, pose="stretch", model=SPOT):
    """Spot stretched 1.4x along x, rigid disks (radius 0.025) on a 0.1 lattice, clipped to the chart interiors
    (texels whose 4-texel neighbourhood is inside a chart) or not. Returns (independent error before, after,
    rigid edges, edges that left their island, inverted triangles, the solver's own fraction removed)."""
    mesh = dk.read_mesh(model)
    layout = Layout(mesh)
    rest = mesh.points.astype(np.float64)
    rigidity, rigid = rigid_disks(layout, clip_to_charts)
    stretched = rest.copy()
    centre = rest.mean(0)
    stretched[:, 0] = centre[0] + 1.4 * (rest[:, 0] - centre[0])
    if pose == "bend":
        stretched = bent(rest)
    solver = dk.UvWarpSolver(mesh, 1001, rigidity)
    solver.solve(stretched.astype(np.float32))
    assert folded_anywhere(np.asarray(solver.warp, np.float64)) == 0
    identity = np.stack(np.meshgrid(np.arange(T + 1) / T, np.arange(T + 1) / T), -1)
    before, edges, _, _ = measure(layout, rest, stretched, identity, rigid)
    after, _, left, inverted = measure(layout, rest, stretched, np.asarray(solver.warp, np.float64), rigid)
    metrics = solver.metrics()
    return before, after, edges, left, inverted, 1 - metrics["rigid_stretch_error"] / metrics["identity_stretch_error"]


def checked_case(label, min_edges, floor, **case):
    """Runs spot_case, prints its figures and asserts the rigid edges counted, the fraction removed and that no
    edge left its island nor any triangle inverted. Returns (fraction removed, the solver's own fraction)."""
    before, after, edges, left, inverted, solver_removed = spot_case(**case)
    removed = 1 - after / before
    print(f"{label}: {edges} rigid edges, error {before:.4f} -> {after:.4f} ({100 * removed:.1f}% removed), "
          f"{left} edges left their island, {inverted} inverted triangles")
    assert edges > min_edges
    assert removed > floor
    assert left == 0 and inverted == 0
    return removed, solver_removed


def test_spot_stretched_keeps_rigid_disks_inside_charts():
    # Measured 91.3% (the target for real layouts: 85%; 88.7% with orientation preservation 0.05, UV-37).
    removed, solver_removed = checked_case("Spot 1.4x, disks inside charts", 10000, 0.88, clip_to_charts=True)
    assert abs(solver_removed - removed) < 0.1  # the solver's own figure agrees to within a tenth


def test_spot_stretched_keeps_rigid_disks_that_chart_borders_cut():
    # The derived mask pins chart borders. A rigid segment with one pinned end keeps its length to the border
    # (docs/decisions.md, UV-15): without that the disks tore from the border and the warp made the error
    # worse than no warp at all (-26%). Measured 72.8% (70.7% with orientation preservation 0.05, UV-37).
    checked_case("Spot 1.4x, disks cut by chart borders", 20000, 0.69, clip_to_charts=False)


def test_spot_bent_keeps_every_grid_triangle():
    # A bend drives points of the grid against the pinned chart borders, where the hierarchy's propagation
    # can fold triangles that the neighbours' mean cannot repair; every iteration ends fold-free
    # (docs/decisions.md, UV-16). spot_case asserts no folded triangle anywhere. Measured 85.9% (the target
    # for a bend: 75%; 82.9% with orientation preservation 0.05, UV-37).
    checked_case("Spot bent, disks inside charts", 10000, 0.82, clip_to_charts=True, pose="bend")


def test_bob_stretched_and_bent_keeps_rigid_disks_inside_charts():
    # A second real layout (Keenan Crane's Bob, triangles, its own UVs), the same disks, poses and metric.
    bob = os.path.join(os.path.dirname(__file__), "..", "data", "bob", "bob_tri.obj")
    # Measured 92.2%, 85.4% (89.6%, 80.9% with orientation preservation 0.05, UV-37).
    for pose, floor in (("stretch", 0.89), ("bend", 0.81)):
        checked_case(f"Bob {pose}", 10000, floor, clip_to_charts=True, pose=pose, model=bob)


def test_live_preset_follows_an_animation_within_2_points_of_converged():
    # The live preset at this grid size (dk.uv_warp_live_options: one warm-started iteration a frame, the
    # coarse levels over-relaxed) on a 24-frame stretch from 1x to 1.4x, against each probed frame solved cold
    # to convergence with the default options and the preset's orientation preservation (20 solves of 4
    # iterations), by the independent metric.
    # A warm start lags most early in the shot (docs/decisions.md UV-28), so early frames are probed.
    for model in (SPOT, os.path.join(os.path.dirname(__file__), "..", "data", "bob", "bob_tri.obj")):
        mesh = dk.read_mesh(model)
        layout = Layout(mesh)
        rest = mesh.points.astype(np.float64)
        rigidity, rigid = rigid_disks(layout, True)
        centre = rest.mean(0)
        identity = np.stack(np.meshgrid(np.arange(T + 1) / T, np.arange(T + 1) / T), -1)

        def pose(f):
            stretched = rest.copy()
            stretched[:, 0] = centre[0] + (1 + 0.4 * f / 23) * (rest[:, 0] - centre[0])
            return stretched

        def removed(p, warp):
            before = measure(layout, rest, p, identity, rigid)[0]
            return 1 - measure(layout, rest, p, np.asarray(warp, np.float64), rigid)[0] / before

        live_options = dk.uv_warp_live_options(T)
        live = dk.UvWarpSolver(mesh, 1001, rigidity, **live_options)
        gaps = []
        for f in range(24):
            live.solve(pose(f).astype(np.float32))
            if f in (3, 6, 12, 23):
                converged = dk.UvWarpSolver(mesh, 1001, rigidity,
                                            orientation_density=live_options["orientation_density"])
                for _ in range(20):
                    converged.solve(pose(f).astype(np.float32))
                assert folded_anywhere(np.asarray(live.warp, np.float64)) == 0
                gaps.append(100 * (removed(pose(f), converged.warp) - removed(pose(f), live.warp)))
        print(f"{os.path.basename(model)}, live preset at {T}^2: points short of converged on frames 4, 7, 13, 24: "
              + ", ".join(f"{g:.2f}" for g in gaps))
        assert max(gaps) <= 2.0
