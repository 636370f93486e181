"""How far the UV warp's view of the posed surface is from the surface, on frames of a rigged shot (rest.obj
and anim.NNNN.obj, as scripts/make_rigged_shot.py writes them), with the disks and the shot preset of
scripts/uvwarp_rigged_figures.py. The solver measures a segment's posed length through f_D interpolated
bilinearly between its grid points; the mesh is flat on each triangle and bends at its edges, so where a cell
straddles a mesh edge the two differ. For the warp grid the solver delivers, on its 4-connected edges whose
ends' four texels are all rigid, the rigid stretch removed (1 - warped / identity mean error):

  view 1x, 2x, 4x   f_D bilinear from its image at the grid's points, and from images 2 and 4 times finer
  surface           f_D on the mesh itself (barycentric on the triangle under each point)
  across edges      the share of the surface's error on grid edges whose ends lie on different mesh triangles
  delivered         the redirect map's figure (deformkit.redirect_metrics, docs/uvwarp_quality.md)

Usage, from the repository's root:

    python3 scripts/uvwarp_view_error.py SHOT FRAME[,FRAME...] [--texels 1024] [--python build/python]
        [--option name=value ...]
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from uvwarp_rigged_figures import chart_texels, rigid_disks, value  # noqa: E402


class SurfaceLocator:
    """The mesh's UV triangles (faces as fans), located through an S x S raster of the triangle under each
    raster cell's centre; a point takes the best of the triangles under its cell and the 8 around it (a point
    within a cell of an edge may lie on the next triangle: extrapolating a triangle's plane across a crease is
    wrong by the distance times the bend)."""

    def __init__(self, mesh, size=4096):
        tris = []
        offset = 0
        for count in mesh.face_counts:
            vertex = mesh.face_indices[offset:offset + count]
            corner = mesh.uv_indices[offset:offset + count]
            offset += count
            tris += [(vertex[0], vertex[k], vertex[k + 1], corner[0], corner[k], corner[k + 1])
                     for k in range(1, count - 1)]
        self.tris = np.array(tris, dtype=np.int64).reshape(-1, 6)
        self.uv = mesh.uvs.astype(np.float64)
        self.size = size
        self.ids = np.full((size, size), -1, np.int64)  # row: v * size
        for n, (a, b, c) in enumerate(self.uv[self.tris[:, 3:]]):
            lo = np.floor(np.minimum.reduce([a, b, c]) * size).astype(int)
            hi = np.ceil(np.maximum.reduce([a, b, c]) * size).astype(int)
            xs = np.arange(max(lo[0], 0), min(hi[0], size))
            ys = np.arange(max(lo[1], 0), min(hi[1], size))
            if not len(xs) or not len(ys):
                continue
            x, y = np.meshgrid(xs, ys)
            l0, l1, l2 = self._barycentric(np.full(x.shape, n), (x + 0.5) / size, (y + 0.5) / size)
            inside = (l0 >= 0) & (l1 >= 0) & (l2 >= 0)
            self.ids[y[inside], x[inside]] = n

    def _barycentric(self, n, u, v):
        a, b, c = (self.uv[self.tris[n, k]] for k in (3, 4, 5))
        e0, e1 = b - a, c - a
        den = e0[..., 0] * e1[..., 1] - e1[..., 0] * e0[..., 1]
        den = np.where(den == 0, np.inf, den)
        qx, qy = u - a[..., 0], v - a[..., 1]
        l1 = (qx * e1[..., 1] - e1[..., 0] * qy) / den
        l2 = (e0[..., 0] * qy - qx * e0[..., 1]) / den
        return 1 - l1 - l2, l1, l2

    def locate(self, u, v):
        """(triangle, l0, l1, l2) for tile-local points (u, v) (flat arrays); triangle -1 off the charts."""
        u, v = np.asarray(u, np.float64), np.asarray(v, np.float64)
        ix = np.clip((u * self.size).astype(int), 0, self.size - 1)
        iy = np.clip((v * self.size).astype(int), 0, self.size - 1)
        best = np.full(u.shape, -1, np.int64)
        score = np.full(u.shape, -np.inf)
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                n = self.ids[np.clip(iy + dy, 0, self.size - 1), np.clip(ix + dx, 0, self.size - 1)]
                s = np.min(self._barycentric(np.maximum(n, 0), u, v), axis=0)
                better = (n >= 0) & (s > score)
                best, score = np.where(better, n, best), np.where(better, s, score)
        best = np.where(score >= -1e-7, best, -1)
        return (best, *self._barycentric(np.maximum(best, 0), u, v))

    def surface(self, points, u, v):
        """(len(u), 3): the mesh (vertices at `points`) at tile-local (u, v); NaN off the charts."""
        n, l0, l1, l2 = self.locate(u, v)
        p = np.asarray(points, np.float64)
        t = self.tris[np.maximum(n, 0)]
        out = l0[:, None] * p[t[:, 0]] + l1[:, None] * p[t[:, 1]] + l2[:, None] * p[t[:, 2]]
        out[n < 0] = np.nan
        return out


def bilinear(corner, cells, u, v):
    """At (u, v), the bilinear blend of corner(i, j) (an (n, 3) field at points (i / cells, j / cells)) over
    the cell of the grid of `cells` cells that holds each point: only the cells used are evaluated."""
    x = np.clip(np.asarray(u, np.float64) * cells, 0, cells * (1 - 1e-12))
    y = np.clip(np.asarray(v, np.float64) * cells, 0, cells * (1 - 1e-12))
    i, j = np.floor(x).astype(int), np.floor(y).astype(int)
    fx, fy = (x - i)[..., None], (y - j)[..., None]
    return ((corner(i, j) * (1 - fx) + corner(i + 1, j) * fx) * (1 - fy)
            + (corner(i, j + 1) * (1 - fx) + corner(i + 1, j + 1) * fx) * fy)


# The ends of a grid's 4-connected edges, as index pairs of its point arrays: along rows, then along columns.
EDGES = (((slice(None), slice(0, -1)), (slice(None), slice(1, None))),
         ((slice(0, -1), slice(None)), (slice(1, None), slice(None))))


def grid_edge_errors(deformed, rest, rigid):
    """|l_def / l_org - 1| on the 4-connected edges of a grid of points (rows, columns, 3) with both ends rigid."""
    errors = []
    for a, b in EDGES:
        keep = rigid[a] & rigid[b]
        ratio = np.linalg.norm(deformed[b] - deformed[a], axis=-1) / np.linalg.norm(rest[b] - rest[a], axis=-1)
        errors.append(np.where(keep, np.abs(ratio - 1), np.nan))
    return errors


def figures(locator, rest_points, posed_points, warp, rigidity):
    """The figures of the module's docstring for one solved warp grid (cells + 1, cells + 1, 2)."""
    cells = warp.shape[0] - 1
    t = rigidity.shape[0]
    j, i = np.meshgrid(np.arange(cells + 1), np.arange(cells + 1), indexing="ij")
    eps = 1e-9  # the tile's own border points, located inside it
    gu, gv = np.clip(i / cells, eps, 1 - eps).ravel(), np.clip(j / cells, eps, 1 - eps).ravel()
    rest = locator.surface(rest_points, gu, gv).reshape(cells + 1, cells + 1, 3)
    # A grid point is rigid when every texel whose square touches it is (rows of the map run down in v).
    x, y = i * (t / cells), (cells - j) * (t / cells)
    padded = np.pad(rigidity >= 0.5, 1)
    rigid = np.ones(x.shape, bool)
    for cx in (np.ceil(x).astype(int) - 1, np.floor(x).astype(int)):
        for cy in (np.ceil(y).astype(int) - 1, np.floor(y).astype(int)):
            rigid &= padded[np.clip(cy + 1, 0, t + 1), np.clip(cx + 1, 0, t + 1)]
    wu, wv = np.clip(warp[..., 0], eps, 1 - eps).ravel(), np.clip(warp[..., 1], eps, 1 - eps).ravel()
    # Every figure over the same edges: those every variant measures (a point whose bilinear look-up reads an
    # image point off the charts, NaN, drops out; the solver's image is dilated there instead).
    variants = {"identity": locator.surface(posed_points, gu, gv)}
    image = variants["identity"].reshape(cells + 1, cells + 1, 3)  # f_D at the grid's own points
    for k in (1, 2, 4):
        fine = cells * k

        def corner(ci, cj, fine=fine):
            if fine == cells:
                return image[cj, ci]
            return locator.surface(posed_points, np.clip(ci / fine, eps, 1 - eps), np.clip(cj / fine, eps, 1 - eps))

        variants[f"view {k}x"] = bilinear(corner, fine, wu, wv)
    variants["surface"] = locator.surface(posed_points, wu, wv)
    errors = {name: grid_edge_errors(p.reshape(cells + 1, cells + 1, 3), rest, rigid)
              for name, p in variants.items()}
    common = [np.all([np.isfinite(e[d]) for e in errors.values()], axis=0) for d in range(2)]
    mean = {name: np.concatenate([e[d][common[d]] for d in range(2)]).mean() for name, e in errors.items()}
    out = {name: 1 - mean[name] / mean["identity"] for name in mean if name != "identity"}
    errors = [np.where(common[d], errors["surface"][d], np.nan) for d in range(2)]
    triangle = locator.locate(gu, gv)[0].reshape(cells + 1, cells + 1)
    across, crossing = 0.0, 0
    for e, (a, b) in zip(errors, EDGES):
        across += np.nansum(np.where(triangle[a] != triangle[b], e, 0.0))
        crossing += (np.isfinite(e) & (triangle[a] != triangle[b])).sum()
    out["across edges"] = across / sum(np.nansum(e) for e in errors)
    out["edges across"] = crossing / sum(np.isfinite(e).sum() for e in errors)
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("shot")
    parser.add_argument("frames", help="frame numbers, comma-separated")
    parser.add_argument("--texels", type=int, default=1024)
    parser.add_argument("--python", default="build/python")
    parser.add_argument("--option", action="append", default=[], help="a solver option, name=value")
    args = parser.parse_args()
    sys.path.insert(0, os.path.abspath(args.python))
    import deformkit as dk

    t = args.texels
    rest = dk.read_mesh(os.path.join(args.shot, "rest.obj"))
    rigidity = rigid_disks(chart_texels(rest, t), t)
    options = dict(preset="shot")
    options.update({k: value(v) for k, v in (o.split("=", 1) for o in args.option)})
    solver = dk.UvWarpSolver(rest, 1001, rigidity, **options)
    locator = SurfaceLocator(rest)
    print(f"{args.shot} at {t}^2, grid {solver.cells}: rigid stretch removed on the grid's rigid edges")
    for frame in (int(f) for f in args.frames.split(",")):
        posed = dk.read_mesh(os.path.join(args.shot, f"anim.{frame:04d}.obj")).points
        solver.solve(posed)
        f = figures(locator, rest.points, posed, solver.warp, rigidity)
        delivered = dk.redirect_metrics(rest, 1001, rigidity, posed, solver.redirect_map())["rigid_stretch_removed"]
        print(f"frame {frame}: view 1x / 2x / 4x {100 * f['view 1x']:.1f} / {100 * f['view 2x']:.1f} / "
              f"{100 * f['view 4x']:.1f}%, surface {100 * f['surface']:.1f}% ({100 * f['across edges']:.0f}% of "
              f"its error on the {100 * f['edges across']:.0f}% of edges across mesh edges); delivered {100 * delivered:.1f}%")


if __name__ == "__main__":
    main()
