"""Remakes the UV warp's pictures in docs/images/uvwarp/ from the DCC shots in tests/data: rigid disks (radius
0.025 of the tile on a 0.1 lattice, kept inside the UV charts) are painted into a rigidity map and, as red dots
on a grey grid, into a texture; `deformkit uvwarp` solves the shot (shot preset) and bakes the texture through
each redirect map; `deformkit preview` renders the chosen frame with the texture as painted (<name>_before.png)
and as baked (<name>_after.png).

    suzanne  Suzanne bent and twisted by keyed modifiers (tests/data/suzanne), 512^2, frame 6
    fox      the rigged Fox running (tests/data/fox), 1024^2, frame 19 (its skinning's largest area change)
    ceiling  the model's ceiling (fox_ceiling.png): the Fox at frame 18 of its Run, 256^2, the disk its skinning
             squashes most, as painted, through the PBD solve's map and through the map of the model's
             optimum (bench_uvwarp_reference --maps: Levenberg-Marquardt to convergence); prints each disk's
             area as shown over its rest area, for the three, worst disks first
    residual the Fox at frame 18 of its Run, 1024^2 (fox_residual.png): each disk coloured by the rigid stretch
             error left on it through the delivered map, without refinement, with a grid twice the map's size
             and with the shot preset; prints the figures of the whole and the cut disks for each
    live     the same at frame 18 (fox_live.png): the live preset played from frame 1 (a preview's warm starts)
             beside the shot preset

Usage, from the repository's root:

    python3 scripts/uvwarp_pictures.py build/bin/deformkit [--python build/python] [--keep DIR]
        [--bench build/bin/bench_uvwarp_reference] [suzanne] [fox] [ceiling] [residual] [live]"""
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np

from uvwarp_rigged_figures import chart_texels, lattice_distance, surface_at_texels

SHOTS = {
    "suzanne": dict(rest="tests/data/suzanne/suzanne.0001.obj", deformed="tests/data/suzanne/suzanne.####.obj",
                    frames=(1, 6), frame=6, texels=512, margin=8, grid=16,
                    view=["--view", "0.25,-0.3,-1", "--width", "640", "--height", "480",
                          "--frame", "-1.1,-0.4,-0.8,1.1,1.0,0.85"]),
    "fox": dict(rest="tests/data/fox/rest.obj", deformed="tests/data/fox/anim.####.obj", frames=(1, 24),
                frame=19, texels=1024, margin=4, grid=32,
                view=["--view", "-1,-0.1,0.05", "--width", "640", "--height", "400",
                      "--frame", "-17,20,-45,17,70,30"]),
}


def disk_texture(rigid, distance, grid):
    """The pictures' texture: grey, grid lines every `grid` texels, rigid texels red with a yellow centre."""
    yy, xx = np.mgrid[0:rigid.shape[0], 0:rigid.shape[1]]
    texture = np.full(rigid.shape + (3,), 0.72, np.float32)
    texture[((xx % grid) == 0) | ((yy % grid) == 0)] = 0.45
    texture[rigid] = (0.85, 0.12, 0.1)
    texture[rigid & (distance < 0.012)] = (1.0, 0.85, 0.2)
    return texture


def make(name, shot, deformkit, dk, images, keep):
    t = shot["texels"]
    mesh = dk.read_mesh(shot["rest"])
    covered = chart_texels(mesh, t)
    interior = covered.copy()
    for dy in range(-shot["margin"], shot["margin"] + 1):
        for dx in range(-shot["margin"], shot["margin"] + 1):
            interior &= np.roll(np.roll(covered, dy, 0), dx, 1)
    distance = lattice_distance(t)
    rigid = (distance < 0.025) & interior
    texture = disk_texture(rigid, distance, shot["grid"])
    first, last = shot["frames"]
    with tempfile.TemporaryDirectory() as scratch:
        work = keep or scratch
        os.makedirs(work, exist_ok=True)
        dk.write_image(os.path.join(work, "rig.1001.exr"), rigid.astype(np.float32)[..., None])
        dk.write_image(os.path.join(work, "col.1001.png"), texture)
        subprocess.run([deformkit, "uvwarp", "--rest", shot["rest"], "--deformed", shot["deformed"], "--frames",
                        f"{first}-{last}", "--preset", "shot", "--rigidity", os.path.join(work, "rig.<UDIM>.exr"),
                        "--texture", os.path.join(work, "col.<UDIM>.png"),
                        "--out", os.path.join(work, "redirect.<UDIM>.####.exr"),
                        "--bake", os.path.join(work, "baked.<UDIM>.####.png")], check=True)
        posed = shot["deformed"].replace("####", f"{shot['frame']:04d}")
        baked = os.path.join(work, f"baked.1001.{shot['frame']:04d}.png")
        for suffix, image in (("before", os.path.join(work, "col.<UDIM>.png")), ("after", baked)):
            out = os.path.join(images, f"{name}_{suffix}.png")
            subprocess.run([deformkit, "preview", posed, "--texture", image, "--out", out] + shot["view"],
                           check=True)


def texel_areas(surface):
    """(t, t): the surface area a texel spans (forward differences), 0 at chart borders and off the charts."""
    dx, dy = np.zeros_like(surface), np.zeros_like(surface)
    dx[:, :-1] = surface[:, 1:] - surface[:, :-1]
    dy[:-1] = surface[1:] - surface[:-1]
    area = np.linalg.norm(np.cross(dx, dy), axis=-1)
    area[~np.isfinite(area)] = 0
    return area


def label_disks(rigid):
    """(t, t) int: each 4-connected region of rigid texels numbered from 0, -1 elsewhere; and their count."""
    t = rigid.shape[0]
    label = -np.ones(rigid.shape, int)
    count = 0
    for y0, x0 in zip(*np.nonzero(rigid)):
        if label[y0, x0] >= 0:
            continue
        label[y0, x0] = count
        stack = [(y0, x0)]
        while stack:
            y, x = stack.pop()
            for yy, xx in ((y + 1, x), (y - 1, x), (y, x + 1), (y, x - 1)):
                if 0 <= yy < t and 0 <= xx < t and rigid[yy, xx] and label[yy, xx] < 0:
                    label[yy, xx] = count
                    stack.append((yy, xx))
        count += 1
    return label, count


def ceiling(bench, deformkit, dk, images, keep, frame=18, t=256, shown=1024):
    """fox_ceiling.png and the per-disk areas (see the module's docstring)."""
    rest = dk.read_mesh("tests/data/fox/rest.obj")
    posed = f"tests/data/fox/anim.{frame:04d}.obj"
    with tempfile.TemporaryDirectory() as scratch:
        work = keep or scratch
        os.makedirs(work, exist_ok=True)
        subprocess.run([bench, "--maps", work, f"--benchmark_filter=BM_UvWarpReference/1/{frame}/{t}/"],
                       check=True, stdout=subprocess.DEVNULL)
        stem = os.path.join(work, f"reference_1_{frame}_{t}_")
        rigid = dk.read_image(stem + "rigidity.exr")[..., 0] >= 0.5
        maps = {name: dk.read_image(stem + name + ".exr") for name in ("pbd", "optimum")}
        # Each disk's area as the deformed surface shows it (the texels whose content lies in it) over its area
        # at rest: 1 is its rest size.
        label, disks = label_disks(rigid)
        rest_area = texel_areas(surface_at_texels(rest, rest.points, t))
        posed_area = texel_areas(surface_at_texels(rest, dk.read_mesh(posed).points, t))
        at_rest = np.array([rest_area[label == d].sum() for d in range(disks)])
        ratio = {"painted": np.array([posed_area[label == d].sum() for d in range(disks)]) / at_rest}
        for name, m in maps.items():
            x = np.clip(np.floor(m[..., 0] * t).astype(int), 0, t - 1)
            y = np.clip(np.floor((1 - m[..., 1]) * t).astype(int), 0, t - 1)
            content = label[y, x]
            ratio[name] = np.array([posed_area[content == d].sum() for d in range(disks)]) / at_rest
        print(f"{disks} disks; area shown / rest area, worst disks (by the optimum) first:")
        for d in np.argsort(-np.abs(np.log(ratio["optimum"])))[:6]:
            print(f"  disk of {(label == d).sum():3d} texels: painted {ratio['painted'][d]:.2f}, "
                  f"PBD {ratio['pbd'][d]:.2f}, optimum {ratio['optimum'][d]:.2f}")
        # The texture at `shown`^2 (disks where the rigidity map is rigid), the maps read bilinearly between
        # their texel centres, the texture bilinearly through them.
        yy, xx = np.mgrid[0:shown, 0:shown]
        distance = lattice_distance(shown)
        texture = disk_texture(rigid[yy * t // shown, xx * t // shown] & (distance < 0.025), distance, 32)

        def bilinear(image, x, y):
            x = np.clip(x, 0, image.shape[1] - 1.001)
            y = np.clip(y, 0, image.shape[0] - 1.001)
            x0, y0 = np.floor(x).astype(int), np.floor(y).astype(int)
            fx, fy = (x - x0)[..., None], (y - y0)[..., None]
            return (image[y0, x0] * (1 - fx) * (1 - fy) + image[y0, x0 + 1] * fx * (1 - fy)
                    + image[y0 + 1, x0] * (1 - fx) * fy + image[y0 + 1, x0 + 1] * fx * fy)

        panels = {"painted": texture}
        for name, m in maps.items():
            r = bilinear(m, (xx + 0.5) * t / shown - 0.5, (yy + 0.5) * t / shown - 0.5)
            panels[name] = bilinear(texture, r[..., 0] * shown - 0.5, (1 - r[..., 1]) * shown - 0.5).astype(np.float32)
        views = []
        for name, image in panels.items():
            path = os.path.join(work, f"ceiling_{name}.png")
            dk.write_image(path, image)
            out = os.path.join(work, f"view_{name}.png")
            subprocess.run([deformkit, "preview", posed, "--texture", path, "--out", out, "--width", "320",
                            "--height", "320", "--view", "-1,-0.3,0.2", "--frame", "4,38,-42,22,60,-16"],
                           check=True, stdout=subprocess.DEVNULL)
            views.append(dk.read_image(out))
        dk.write_image(os.path.join(images, "fox_ceiling.png"), np.concatenate(views, 1))


def residual_panel(dk, rest, posed, inside, label, disks, redirect, shown):
    """A residual picture's panel: the tile grey on the charts, each disk coloured by the rigid stretch error
    the redirect map leaves on it (green 0, yellow 5%, red 10% or more), `shown` texels a side."""
    t = inside.shape[0]
    image = np.where(inside[..., None], np.float32(0.55), np.float32(0.1)) * np.ones(3, np.float32)
    for d in range(disks):
        part = (label == d).astype(np.float32)
        m = dk.redirect_metrics(rest, 1001, part, posed.points, redirect)
        share = float(np.clip(m["rigid_stretch_error"] / 0.1, 0, 1))  # 10% or more: red
        image[label == d] = (min(1.0, 2 * share), min(1.0, 2 * (1 - share)), 0.1)
    step = t // shown
    return image[::step, ::step]


def residual(dk, images, frame=18, t=1024, shown=512, live=False,
             solves=({"refinement_sweeps": 0}, {"resolution": 2048}, {})):
    """fox_residual.png: the Fox's tile at `frame` of its Run, each disk coloured by the rigid stretch error
    the delivered map leaves on it (the mean |l_def / l_rest - 1| over its texel edges: green 0, yellow 5%,
    red 10% or more), a panel per solve of the shot preset: the map's grid without refinement, a grid twice
    the map's size, the preset itself (the map's grid, refined); prints each panel's whole and cut figures.
    live: fox_live.png instead, the live preset played from frame 1 to `frame` (warm-started, as a preview
    plays the shot) beside the shot preset on `frame`."""
    from uvwarp_rigged_figures import disk_parts, rigid_disks
    rest = dk.read_mesh("tests/data/fox/rest.obj")
    posed = dk.read_mesh(f"tests/data/fox/anim.{frame:04d}.obj")
    inside = chart_texels(rest, t)
    rigidity = rigid_disks(inside, t)
    parts = {"all": rigidity, **disk_parts(rigidity, t)}
    label, disks = label_disks(rigidity >= 0.5)
    panels = []
    for options in ({"preset": "live"}, {}) if live else solves:
        solver = dk.UvWarpSolver(rest, 1001, rigidity, **{"preset": "shot", **options})
        for f in range(1 if options.get("preset") == "live" else frame, frame + 1):
            solver.solve(dk.read_mesh(f"tests/data/fox/anim.{f:04d}.obj").points)
        redirect = solver.redirect_map()
        figures = {name: dk.redirect_metrics(rest, 1001, r, posed.points, redirect)["rigid_stretch_removed"]
                   for name, r in parts.items()}
        print(f"frame {frame}, {options or 'defaults'}: " + ", ".join(f"{k} {100 * v:.1f}%" for k, v in figures.items()))
        panels.append(residual_panel(dk, rest, posed, inside, label, disks, redirect, shown))
        panels.append(np.ones((shown, 8, 3), np.float32))
    name = "fox_live.png" if live else "fox_residual.png"
    dk.write_image(os.path.join(images, name), np.concatenate(panels[:-1], 1))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("deformkit")
    parser.add_argument("--python", default="build/python")
    parser.add_argument("--keep", help="folder to keep the maps, texture and bakes in (default: a temporary one)")
    parser.add_argument("--bench", default="build/bin/bench_uvwarp_reference",
                        help="bench_uvwarp_reference, for the ceiling picture")
    parser.add_argument("shots", nargs="*", default=list(SHOTS) + ["ceiling", "residual", "live"])
    args = parser.parse_intermixed_args()
    sys.path.insert(0, os.path.abspath(args.python))
    import deformkit as dk
    images = os.path.join("docs", "images", "uvwarp")
    for name in args.shots:
        keep = os.path.join(args.keep, name) if args.keep else None
        if name == "ceiling":
            if not os.path.exists(args.bench):
                raise SystemExit(f"uvwarp_pictures: {args.bench} is missing: build it "
                                 "(cmake --build build --target bench_uvwarp_reference)")
            ceiling(os.path.abspath(args.bench), os.path.abspath(args.deformkit), dk, images, keep)
        elif name in ("residual", "live"):
            residual(dk, images, live=name == "live")
        else:
            make(name, SHOTS[name], os.path.abspath(args.deformkit), dk, images, keep)


if __name__ == "__main__":
    main()
