"""What a redirect map delivers (deformkit.redirect_metrics, uvwarp/redirect_metrics.h), against a second
implementation written here in numpy: texel centres located in the UV triangles by brute force, f_D and f_O
by barycentric interpolation, the rigidity sampled bilinearly, the 4-connected edges, the inverted triangles
of the texel-centre grid (both diagonals) and the off-chart texels. On a mesh of two charts in one tile with a
non-linear deformation, for the identity map, the solver's map, and maps made to fold and to leave the charts."""
import numpy as np
import pytest

import deformkit as dk

T = 64
N = 8  # quads per side of each chart


def two_charts():
    """Two UV charts of N x N quads in tile 1001 (u in [0.05, 0.45] and [0.55, 0.95], v in [0.1, 0.9]), each a
    curved sheet in 3D; vertex (i, j) of chart c is c (N + 1)^2 + j (N + 1) + i."""
    points, uvs, faces = [], [], []
    for c, (u0, offset) in enumerate(((0.05, 0.0), (0.55, 3.0))):
        base = c * (N + 1) ** 2
        for j in range(N + 1):
            for i in range(N + 1):
                u, v = u0 + 0.4 * i / N, 0.1 + 0.8 * j / N
                uvs.append((u, v))
                points.append((offset + 2.0 * i / N, np.sin(2.0 * j / N), np.cos(2.0 * j / N)))
        for j in range(N):
            for i in range(N):
                a = base + j * (N + 1) + i
                faces.append((a, a + 1, a + N + 2, a + N + 1))
    points = np.asarray(points, np.float32)
    uvs = np.asarray(uvs, np.float32)
    idx = np.asarray(faces, np.int32).ravel()
    mesh = dk.Mesh(points, np.full(len(faces), 4, np.int32), idx, uvs, idx.copy())
    return mesh, points, uvs, np.asarray(faces), np.repeat([0, 1], N * N)


def deform(points):
    """A non-linear deformation: stretched along x by a factor growing with y, and bent."""
    p = points.astype(np.float64)
    x = p[:, 0] * (1.0 + 0.4 * p[:, 1] ** 2)
    return np.stack([x, p[:, 1] + 0.1 * x ** 2, p[:, 2]], axis=1).astype(np.float32)


def rigidity():
    y, x = np.meshgrid(np.arange(T), np.arange(T), indexing="ij")
    u, v = (x + 0.5) / T, 1.0 - (y + 0.5) / T
    rig = np.zeros((T, T), np.float32)
    for cu in (0.2, 0.3, 0.7, 0.8):
        for cv in (0.3, 0.6):
            rig[np.hypot(u - cu, v - cv) < 0.07] = 0.8
    return rig


def reference(points, uvs, faces, charts, deformed, rig, redirect):
    """The delivered figures, computed independently."""
    # Fan triangles (corner 0, k, k + 1), as the library triangulates polygons.
    tris = np.concatenate([faces[:, [0, 1, 2]], faces[:, [0, 2, 3]]])
    tri_chart = np.concatenate([charts, charts])
    a, b, c = uvs[tris[:, 0]].astype(np.float64), uvs[tris[:, 1]].astype(np.float64), uvs[tris[:, 2]].astype(np.float64)

    def locate(p, tolerance):
        """(triangle or -1, barycentrics) of points p (M, 2), the lowest-index triangle holding each."""
        v0, v1 = b - a, c - a
        den = v0[:, 0] * v1[:, 1] - v1[:, 0] * v0[:, 1]
        v2 = p[:, None, :] - a[None, :, :]
        l1 = (v2[..., 0] * v1[None, :, 1] - v1[None, :, 0] * v2[..., 1]) / den
        l2 = (v0[None, :, 0] * v2[..., 1] - v2[..., 0] * v0[None, :, 1]) / den
        l0 = 1.0 - l1 - l2
        inside = (l0 >= -tolerance) & (l1 >= -tolerance) & (l2 >= -tolerance)
        tri = np.where(inside.any(axis=1), inside.argmax(axis=1), -1)
        rows = np.arange(len(p))
        bary = np.stack([l0[rows, tri], l1[rows, tri], l2[rows, tri]], axis=1)
        return tri, bary

    def at(values, tri, bary):
        v = values.astype(np.float64)[tris[tri]]
        return (bary[:, :, None] * v).sum(axis=1)

    y, x = np.meshgrid(np.arange(T), np.arange(T), indexing="ij")
    q = np.stack([(x + 0.5) / T, 1.0 - (y + 0.5) / T], axis=2).reshape(-1, 2)
    tq, bq = locate(q, 0.0)
    r = redirect.reshape(-1, 2).astype(np.float64)
    tr, br = locate(r, 1e-7)
    chart = np.where(tq >= 0, tri_chart[tq], -1)
    fd_q = at(deformed, np.maximum(tq, 0), bq)
    fo_q = at(points, np.maximum(tq, 0), bq)
    fo_r = at(points, np.maximum(tr, 0), br)

    def bilinear(p):
        px, py = p[:, 0] * T - 0.5, (1.0 - p[:, 1]) * T - 0.5
        x0, y0 = np.floor(px).astype(int), np.floor(py).astype(int)
        fx, fy = px - x0, py - y0
        def texel(i, j):
            return rig[np.clip(j, 0, T - 1), np.clip(i, 0, T - 1)].astype(np.float64)
        return ((1 - fx) * (1 - fy) * texel(x0, y0) + fx * (1 - fy) * texel(x0 + 1, y0) +
                (1 - fx) * fy * texel(x0, y0 + 1) + fx * fy * texel(x0 + 1, y0 + 1))

    rigid_q = (rig.reshape(-1) >= 0.5)
    located = tr >= 0
    rigid_r = located & (bilinear(r) >= 0.5)
    error, edges, identity_error, identity_edges = 0.0, 0, 0.0, 0
    index = np.arange(T * T).reshape(T, T)
    for ia, ib in ((index[:, :-1].ravel(), index[:, 1:].ravel()), (index[:-1, :].ravel(), index[1:, :].ravel())):
        same = (chart[ia] >= 0) & (chart[ia] == chart[ib])
        length = np.linalg.norm(fd_q[ib] - fd_q[ia], axis=1)
        rest = np.linalg.norm(fo_q[ib] - fo_q[ia], axis=1)
        # At the identity, edges without a measurable rest length (a degenerate rest surface) are left out.
        keep = same & rigid_q[ia] & rigid_q[ib] & (rest > 1e-9 * np.linalg.norm(points.max(0) - points.min(0)))
        identity_error += np.abs(length[keep] / rest[keep] - 1).sum()
        identity_edges += keep.sum()
        keep = same & rigid_r[ia] & rigid_r[ib]
        rest = np.linalg.norm(fo_r[ib] - fo_r[ia], axis=1)[keep]
        # Both texels showing one point of the map count with an error of 1; other edges without a
        # measurable rest length (a degenerate rest surface) are left out.
        tiny = rest <= 1e-9 * np.linalg.norm(points.max(0) - points.min(0))
        collapsed = tiny & np.all(r[ib][keep] == r[ia][keep], axis=1)
        counted = ~tiny | collapsed
        error += np.where(collapsed, 1.0, np.abs(length[keep] / np.where(tiny, 1.0, rest) - 1))[counted].sum()
        edges += counted.sum()

    R = redirect.astype(np.float64)
    p00, p10, p01, p11 = R[:-1, :-1], R[:-1, 1:], R[1:, :-1], R[1:, 1:]

    def area(p, s, t):
        return (s[..., 0] - p[..., 0]) * (t[..., 1] - p[..., 1]) - (s[..., 1] - p[..., 1]) * (t[..., 0] - p[..., 0])

    inverted = sum(int((area(*tri) > 0).sum()) for tri in ((p00, p10, p11), (p00, p11, p01), (p00, p10, p01),
                                                           (p10, p11, p01)))
    return {"rigid_stretch_error": error / edges if edges else 0.0, "rigid_edges": edges,
            "identity_stretch_error": identity_error / identity_edges, "identity_rigid_edges": identity_edges,
            "inverted_triangles": inverted, "off_chart_texels": int(((chart >= 0) & ~located).sum()),
            "chart_texels": int((chart >= 0).sum())}


def check(got, expected):
    for key in ("rigid_edges", "identity_rigid_edges", "inverted_triangles", "off_chart_texels", "chart_texels"):
        assert got[key] == expected[key], key
    for key in ("rigid_stretch_error", "identity_stretch_error"):
        assert got[key] == pytest.approx(expected[key], rel=1e-6, abs=1e-12), key
    removed = 1 - expected["rigid_stretch_error"] / expected["identity_stretch_error"]
    if expected["rigid_edges"] == 0:  # no rigid content shown: none of its stretch removed
        removed = 0.0
    assert got["rigid_stretch_removed"] == pytest.approx(removed, rel=1e-6, abs=1e-9)


def identity_map():
    y, x = np.meshgrid(np.arange(T), np.arange(T), indexing="ij")
    return np.stack([(x + 0.5) / T, 1.0 - (y + 0.5) / T], axis=2).astype(np.float32)


def test_the_delivered_figures_equal_an_independent_computation():
    mesh, points, uvs, faces, charts = two_charts()
    deformed = deform(points)
    rig = rigidity()
    cases = {"identity": identity_map()}
    solver = dk.UvWarpSolver(mesh, 1001, rig, iterations=8)
    solver.solve(deformed)
    cases["solver"] = solver.redirect_map()
    folded = identity_map().copy()
    folded[20:24, 10:14] = folded[20:24, 10:14][:, ::-1]  # a mirrored patch: its triangles turn over
    cases["folded"] = folded
    outside = identity_map().copy()
    outside[30:34, 20:24] = (0.5, 0.5)  # content from the gap between the charts
    cases["outside"] = outside
    # Rigid content collapsed: every texel of a disk's neighbourhood shows the disk's centre (rigid), and a
    # map whose every texel shows one rigid point.
    patch = identity_map().copy()
    patch[int((1 - 0.6) * T) - 6:int((1 - 0.6) * T) + 6, int(0.2 * T) - 6:int(0.2 * T) + 6] = (0.2, 0.6)
    cases["collapsed disk"] = patch
    cases["collapsed"] = np.broadcast_to(np.float32([0.2, 0.6]), (T, T, 2)).copy()
    # A map showing elastic content only (a point between the disks of chart 0).
    cases["elastic only"] = np.broadcast_to(np.float32([0.25, 0.45]), (T, T, 2)).copy()
    for name, redirect in cases.items():
        got = dk.redirect_metrics(mesh, 1001, rig, deformed, redirect)
        expected = reference(points, uvs, faces, charts, deformed, rig, redirect)
        print(name, {k: got[k] for k in ("rigid_stretch_removed", "inverted_triangles", "off_chart_texels")})
        check(got, expected)
    # What the cases were made to show.
    assert dk.redirect_metrics(mesh, 1001, rig, deformed, cases["identity"])["rigid_stretch_removed"] == 0.0
    assert dk.redirect_metrics(mesh, 1001, rig, deformed, cases["folded"])["inverted_triangles"] > 0
    assert dk.redirect_metrics(mesh, 1001, rig, deformed, cases["outside"])["off_chart_texels"] == 16
    # A map that collapses or hides rigid detail does not score as if it removed its stretch.
    identity = dk.redirect_metrics(mesh, 1001, rig, deformed, cases["identity"])
    disk = dk.redirect_metrics(mesh, 1001, rig, deformed, cases["collapsed disk"])
    assert disk["rigid_stretch_error"] > identity["rigid_stretch_error"] and disk["rigid_stretch_removed"] < 0
    collapsed = dk.redirect_metrics(mesh, 1001, rig, deformed, cases["collapsed"])
    assert collapsed["rigid_stretch_error"] == 1.0 and collapsed["rigid_stretch_removed"] < 0
    hidden = dk.redirect_metrics(mesh, 1001, rig, deformed, cases["elastic only"])
    assert hidden["rigid_edges"] == 0 and hidden["rigid_stretch_removed"] == 0.0
    # The solver's metrics() report the figures of its own redirect map.
    m = solver.metrics()
    check(m, reference(points, uvs, faces, charts, deformed, rig, cases["solver"]))
    assert m["rigid_stretch_removed"] > 0.3 and m["inverted_triangles"] == 0 and m["off_chart_texels"] == 0


def test_a_degenerate_rest_surface_is_left_out_through_the_map_as_at_the_identity():
    # The rest mesh collapsed to a point around one vertex (its four quads degenerate there): edges without
    # a measurable rest length whose texels show distinct points are left out through any map, as at the
    # identity, so the identity still removes nothing; a map collapsing content there counts as before.
    mesh, points, uvs, faces, charts = two_charts()
    centre = 4 * (N + 1) + 4  # vertex (4, 4) of chart 0
    squashed = points.copy()
    for v in (centre - N - 2, centre - N - 1, centre - N, centre - 1, centre + 1, centre + N, centre + N + 1,
              centre + N + 2):
        squashed[v] = points[centre]
    idx = faces.ravel().astype(np.int32)
    degenerate = dk.Mesh(squashed, np.full(len(faces), 4, np.int32), idx, uvs, idx.copy())
    rig = np.ones((T, T), np.float32)
    deformed = deform(squashed)
    got = dk.redirect_metrics(degenerate, 1001, rig, deformed, identity_map())
    check(got, reference(squashed, uvs, faces, charts, deformed, rig, identity_map()))
    assert got["rigid_stretch_removed"] == 0.0
    assert got["rigid_edges"] == got["identity_rigid_edges"]


def test_bad_inputs_name_what_is_wrong():
    mesh, points, *_ = two_charts()
    rig = rigidity()
    with pytest.raises(dk.InvalidInput, match="redirect_metrics: deformed_points: has shape"):
        dk.redirect_metrics(mesh, 1001, rig, points[:5], identity_map())
    with pytest.raises(dk.InvalidInput, match=r"redirect map: is 32 x 32"):
        dk.redirect_metrics(mesh, 1001, rig, points, identity_map()[:32, :32])
    bad = identity_map()
    bad[3, 5, 0] = np.nan
    with pytest.raises(dk.InvalidInput, match=r"redirect map texel \(5, 3\): is not finite"):
        dk.redirect_metrics(mesh, 1001, rig, points, bad)
    with pytest.raises(dk.InvalidInput, match="UDIM tile 1002: holds no UV face"):
        dk.redirect_metrics(mesh, 1002, rig, points, identity_map())
    # The rigidity map and the deformed points are checked as the solver checks them: a NaN or a 5 in the
    # map, a NaN point, changed the figures without a word.
    for value, shown in ((np.nan, "nan"), (5.0, "5"), (-0.5, "-0.5")):
        wrong = rig.copy()
        wrong[7, 9] = value
        with pytest.raises(dk.InvalidInput,
                           match=rf"rigidity map texel \(9, 7\): is {shown} \(expected a finite value in \[0, 1\]\)"):
            dk.redirect_metrics(mesh, 1001, wrong, points, identity_map())
    moved = points.copy()
    moved[3, 1] = np.nan
    with pytest.raises(dk.InvalidInput, match=r"deformed position of vertex 3: is not finite"):
        dk.redirect_metrics(mesh, 1001, rig, moved, identity_map())
