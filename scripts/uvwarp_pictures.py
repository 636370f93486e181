"""Remakes the UV warp's pictures in docs/images/uvwarp/ from the DCC shots in tests/data: rigid disks (radius
0.025 of the tile on a 0.1 lattice, kept inside the UV charts) are painted into a rigidity map and, as red dots
on a grey grid, into a texture; `deformkit uvwarp` solves the shot (shot preset) and bakes the texture through
each redirect map; `deformkit preview` renders the chosen frame with the texture as painted (<name>_before.png)
and as baked (<name>_after.png). With --crop, <name>_texture.png puts a window of the texture as painted beside
the same window baked at that frame, in texture space.

    suzanne  Suzanne bent and twisted by keyed modifiers (tests/data/suzanne), 512^2, frame 6
    fox      the rigged Fox running (tests/data/fox), 1024^2, frame 19 (its skinning's largest area change)

Usage, from the repository's root:

    python3 scripts/uvwarp_pictures.py build/bin/deformkit [--python build/python] [--keep DIR] [suzanne] [fox]"""
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np

from uvwarp_rigged_figures import chart_texels

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


def make(name, shot, deformkit, dk, images, keep):
    t = shot["texels"]
    mesh = dk.read_mesh(shot["rest"])
    covered = chart_texels(mesh, t)
    interior = covered.copy()
    for dy in range(-shot["margin"], shot["margin"] + 1):
        for dx in range(-shot["margin"], shot["margin"] + 1):
            interior &= np.roll(np.roll(covered, dy, 0), dx, 1)
    yy, xx = np.mgrid[0:t, 0:t]
    u, v = (xx + 0.5) / t, 1 - (yy + 0.5) / t
    centres = np.arange(0.05, 1, 0.1)
    distance = np.min([np.hypot(u - cu, v - cv) for cu in centres for cv in centres], axis=0)
    rigid = (distance < 0.025) & interior
    texture = np.full((t, t, 3), 0.72, np.float32)
    texture[((xx % shot["grid"]) == 0) | ((yy % shot["grid"]) == 0)] = 0.45
    texture[rigid] = (0.85, 0.12, 0.1)
    texture[rigid & (distance < 0.012)] = (1.0, 0.85, 0.2)
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


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("deformkit")
    parser.add_argument("--python", default="build/python")
    parser.add_argument("--keep", help="folder to keep the maps, texture and bakes in (default: a temporary one)")
    parser.add_argument("shots", nargs="*", default=list(SHOTS))
    args = parser.parse_intermixed_args()
    sys.path.insert(0, os.path.abspath(args.python))
    import deformkit as dk
    images = os.path.join("docs", "images", "uvwarp")
    for name in args.shots:
        keep = os.path.join(args.keep, name) if args.keep else None
        make(name, SHOTS[name], os.path.abspath(args.deformkit), dk, images, keep)


if __name__ == "__main__":
    main()
