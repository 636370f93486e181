"""The UV warp's figures on a rigged shot (rest.obj and anim.NNNN.obj, as scripts/make_rigged_shot.py writes
them), as docs/uvwarp_quality.md quotes them: rigid disks of radius 0.025 on a 0.1 lattice at texels whose 9 x 9
neighbourhood (at 1024^2; (2 T / 256 + 1)^2 in general) lies inside the UV charts, every frame solved with
the shot preset from the identity, measured on the redirect map it delivers (deformkit.redirect_metrics):
the rigid stretch removed (median and worst frame), the inverted triangles delivered and those the fold
repair unfolded, off-chart texels, the time a frame takes (solve and map). Usage, from the repository's root:

    python3 scripts/uvwarp_rigged_figures.py tests/data/fox [--texels 1024] [--python build/python]
        [--first 1] [--option name=value ...] [--margin TEXELS] [--split] [--gap-to-shot]

--split also measures the same maps over the disks whole inside a chart and over those a chart border cuts.
--gap-to-shot also solves every frame with the shot preset from the identity and prints, per frame, how many
points of rigid stretch removed the solve asked for (--option preset=live: the live preset, warm-started
frame after frame as a preview plays the shot) leaves behind it: the live preset's requirement is a gap of
at most 3 points on every frame."""
import argparse
import os
import sys
import time

import numpy as np


def surface_at_texels(mesh, points, t):
    """(t, t, 3): the surface point (mesh vertices moved to `points`) under each texel centre, NaN off the charts."""
    uv, p = mesh.uvs.astype(np.float64), points.astype(np.float64)
    out = np.full((t, t, 3), np.nan)
    offset = 0
    for count in mesh.face_counts:
        vertex = mesh.face_indices[offset:offset + count]
        corner = mesh.uv_indices[offset:offset + count]
        offset += count
        for k in range(1, count - 1):
            ids = (0, k, k + 1)
            a, b, c = (uv[corner[i]] for i in ids)
            lo = np.floor(np.minimum.reduce([a, b, c]) * t).astype(int)
            hi = np.ceil(np.maximum.reduce([a, b, c]) * t).astype(int)
            xs, ys = np.arange(max(lo[0], 0), min(hi[0], t)), np.arange(max(t - hi[1], 0), min(t - lo[1], t))
            e0, e1 = b - a, c - a
            den = e0[0] * e1[1] - e1[0] * e0[1]
            if not len(xs) or not len(ys) or den == 0:
                continue
            x, y = np.meshgrid(xs, ys)
            q = np.stack([(x + 0.5) / t, 1 - (y + 0.5) / t], -1) - a
            l1 = (q[..., 0] * e1[1] - e1[0] * q[..., 1]) / den
            l2 = (e0[0] * q[..., 1] - q[..., 0] * e0[1]) / den
            ok = (l1 >= 0) & (l2 >= 0) & (l1 + l2 <= 1)
            value = ((1 - l1 - l2)[..., None] * p[vertex[ids[0]]] + l1[..., None] * p[vertex[ids[1]]]
                     + l2[..., None] * p[vertex[ids[2]]])
            out[y[ok], x[ok]] = value[ok]
    return out


def chart_texels(mesh, t):
    """(t, t) bool: texel centres (row 0 at v = 1) inside a UV triangle of the mesh's faces (fans)."""
    return np.isfinite(surface_at_texels(mesh, mesh.points, t)[..., 0])


def lattice_distance(t):
    """(t, t): each texel centre's distance (tile units) to the nearest disk centre of the 0.1 lattice."""
    y, x = np.meshgrid(np.arange(t), np.arange(t), indexing="ij")
    u, v = (x + 0.5) / t, 1 - (y + 0.5) / t
    centres = np.arange(0.05, 1, 0.1)
    return np.min([np.hypot(u - cu, v - cv) for cu in centres for cv in centres], axis=0)


def rigid_disks(inside, t, margin=None):
    """(t, t) float32: 1 at texels of the disks whose (2 margin + 1)^2 neighbourhood lies inside the charts
    (margin: t / 256 texels, at least 1, unless given), 0 elsewhere."""
    d = lattice_distance(t)
    interior = inside.copy()
    r = max(1, t // 256) if margin is None else margin
    for dy in range(-r, r + 1):
        for dx in range(-r, r + 1):
            interior &= np.roll(np.roll(inside, dy, 0), dx, 1)
    return ((d < 0.025) & interior).astype(np.float32)


def whole_disks(rigidity, t):
    """(t, t) float32: the texels of `rigidity` (rigid_disks) in disks that no chart border cuts (every texel of
    the disk's circle is rigid); rigidity minus it is the disks that chart borders cut."""
    y, x = np.meshgrid(np.arange(t), np.arange(t), indexing="ij")
    u, v = (x + 0.5) / t, 1 - (y + 0.5) / t
    whole = np.zeros_like(rigidity)
    for cu in np.arange(0.05, 1, 0.1):
        for cv in np.arange(0.05, 1, 0.1):
            disk = np.hypot(u - cu, v - cv) < 0.025
            if disk.any() and (rigidity[disk] >= 0.5).all():
                whole[disk] = rigidity[disk]
    return whole


def disk_parts(rigidity, t):
    """{"whole": the disks whole inside a chart, "cut": those a chart border cuts} (whole_disks)."""
    whole = whole_disks(rigidity, t)
    return {"whole": whole, "cut": rigidity - whole}


def value(text):
    if text in ("true", "false"):
        return text == "true"
    if "," in text:  # a list: sweeps_per_level=4,8,16
        return [value(part) for part in text.split(",")]
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("shot")
    parser.add_argument("--texels", type=int, default=1024)
    parser.add_argument("--python", default="build/python")
    parser.add_argument("--first", type=int, default=1, help="first frame measured (2 skips a rest pose)")
    parser.add_argument("--option", action="append", default=[], help="a solver option, name=value")
    parser.add_argument("--margin", type=int, help="texels between the disks and the chart borders (T / 256)")
    parser.add_argument("--split", action="store_true",
                        help="also the figures of the disks whole inside a chart and of those chart borders cut")
    parser.add_argument("--gap-to-shot", action="store_true",
                        help="also each frame's gap to the shot preset solved from the identity, in points")
    args = parser.parse_args()
    sys.path.insert(0, os.path.abspath(args.python))
    import deformkit as dk

    t = args.texels
    rest = dk.read_mesh(os.path.join(args.shot, "rest.obj"))
    rigidity = rigid_disks(chart_texels(rest, t), t, args.margin)
    # The same maps measured over subsets of the disks: those whole inside a chart, those a chart border cuts.
    parts = disk_parts(rigidity, t) if args.split else {}
    part_removed = {name: [] for name in parts}
    options = dict(preset="shot")
    options.update({k: value(v) for k, v in (o.split("=", 1) for o in args.option)})
    solver = dk.UvWarpSolver(rest, 1001, rigidity, **options)
    shot = dk.UvWarpSolver(rest, 1001, rigidity, preset="shot") if args.gap_to_shot else None
    shot_removed = []
    frames = sorted(int(name[5:9]) for name in os.listdir(args.shot) if name.startswith("anim."))
    removed, inverted, unfolded, off_chart, seconds = [], 0, 0, 0, []
    for frame in (f for f in frames if f >= args.first):
        posed = dk.read_mesh(os.path.join(args.shot, f"anim.{frame:04d}.obj"))
        start = time.perf_counter()
        solver.solve(posed.points)
        redirect = solver.redirect_map()
        seconds.append(time.perf_counter() - start)
        m = dk.redirect_metrics(rest, 1001, rigidity, posed.points, redirect)
        removed.append(m["rigid_stretch_removed"])
        inverted += m["inverted_triangles"]
        off_chart += m["off_chart_texels"]
        unfolded += solver.metrics()["repair_inverted_found"]
        if shot is not None:  # untimed
            shot.solve(posed.points)
            shot_removed.append(dk.redirect_metrics(rest, 1001, rigidity, posed.points,
                                                    shot.redirect_map())["rigid_stretch_removed"])
        for name, part in parts.items():
            part_removed[name].append(
                dk.redirect_metrics(rest, 1001, part, posed.points, redirect)["rigid_stretch_removed"])
    removed = np.array(removed)
    print(f"{args.shot} at {t}^2, {int(rigidity.sum())} rigid texels, {len(removed)} frames: rigid stretch removed "
          f"{100 * np.median(removed):.1f}% median, {100 * removed.min():.1f}% worst (frame "
          f"{args.first + int(removed.argmin())}); {inverted} inverted triangles delivered ({unfolded} unfolded by "
          f"the repair), {off_chart} off-chart texels; {1e3 * np.median(seconds):.0f} ms a frame (solve and map)")
    print("per frame removed:", " ".join(f"{100 * r:.1f}" for r in removed))
    if shot is not None:
        gap = 100 * (np.array(shot_removed) - removed)
        print(f"gap to the shot preset: {np.median(gap):.1f} points median, {gap.max():.1f} worst (frame "
              f"{args.first + int(gap.argmax())}); within 3 points on {int((gap <= 3).sum())} of {len(gap)} frames")
        print("per frame gap:", " ".join(f"{g:.1f}" for g in gap))
    for name, values in part_removed.items():
        values = np.array(values)
        print(f"disks {'whole inside a chart' if name == 'whole' else 'cut by a chart border'} "
              f"({int(parts[name].sum())} texels): {100 * np.median(values):.1f}% median, "
              f"{100 * values.min():.1f}% worst (frame {args.first + int(values.argmin())})")


if __name__ == "__main__":
    main()
