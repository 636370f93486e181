"""Remakes docs/images/uvwarp/suzanne_*.png: the UV warp on the Blender shot of tests/data/suzanne. Rigid disks
(radius 0.025 of the tile on a 0.1 lattice, kept inside the UV charts) are painted into a rigidity map and, as
red dots on a grey grid, into a texture; `deformkit uvwarp` solves the six frames (512^2) and bakes the texture
through each redirect map; `deformkit preview` renders frame 6 with the texture as painted (before) and as
baked (after). Usage, from the repository's root:

    python3 scripts/uvwarp_suzanne_pictures.py build/bin/deformkit [build/python]"""
import os
import subprocess
import sys
import tempfile

import numpy as np

deformkit = os.path.abspath(sys.argv[1])
sys.path.insert(0, os.path.abspath(sys.argv[2] if len(sys.argv) > 2 else "build/python"))
import deformkit as dk  # noqa: E402

T = 512
shot = os.path.join("tests", "data", "suzanne")
images = os.path.join("docs", "images", "uvwarp")
mesh = dk.read_mesh(os.path.join(shot, "suzanne.0001.obj"))

# Texels inside the UV charts: rasterise the quads' two triangles at texel centres (row 0 at v = 1).
yy, xx = np.mgrid[0:T, 0:T]
u, v = (xx + 0.5) / T, 1 - (yy + 0.5) / T
covered = np.zeros((T, T), bool)
offset = 0
for count in mesh.face_counts:
    corners = mesh.uvs[mesh.uv_indices[offset:offset + count]].astype(np.float64)
    offset += count
    for k in range(1, count - 1):
        a, b, c = corners[0], corners[k], corners[k + 1]
        lo = np.floor(np.minimum(np.minimum(a, b), c) * T).astype(int).clip(0, T - 1)
        hi = np.ceil(np.maximum(np.maximum(a, b), c) * T).astype(int).clip(0, T - 1)
        px, py = u[T - 1 - hi[1]:T - lo[1], lo[0]:hi[0] + 1], v[T - 1 - hi[1]:T - lo[1], lo[0]:hi[0] + 1]

        def edge(p, q):
            return (q[0] - p[0]) * (py - p[1]) - (q[1] - p[1]) * (px - p[0])

        w = np.stack([edge(b, c), edge(c, a), edge(a, b)])
        inside = (w >= 0).all(0) | (w <= 0).all(0)
        covered[T - 1 - hi[1]:T - lo[1], lo[0]:hi[0] + 1] |= inside
interior = covered.copy()
for dy in range(-8, 9):
    for dx in range(-8, 9):
        interior &= np.roll(np.roll(covered, dy, 0), dx, 1)
centres = np.arange(0.05, 1, 0.1)
distance = np.min([np.hypot(u - cu, v - cv) for cu in centres for cv in centres], axis=0)
rigid = (distance < 0.025) & interior
texture = np.full((T, T, 3), 0.72, np.float32)
grid = ((xx % 16) == 0) | ((yy % 16) == 0)
texture[grid] = 0.45
texture[rigid] = (0.85, 0.12, 0.1)
texture[rigid & (distance < 0.012)] = (1.0, 0.85, 0.2)

with tempfile.TemporaryDirectory() as work:
    dk.write_image(os.path.join(work, "rig.1001.exr"), rigid.astype(np.float32)[..., None])
    dk.write_image(os.path.join(work, "col.1001.png"), texture)
    subprocess.run([deformkit, "uvwarp", "--rest", os.path.join(shot, "suzanne.0001.obj"),
                    "--deformed", os.path.join(shot, "suzanne.####.obj"), "--frames", "1-6",
                    "--rigidity", os.path.join(work, "rig.<UDIM>.exr"), "--texture",
                    os.path.join(work, "col.<UDIM>.png"), "--out", os.path.join(work, "redirect.<UDIM>.####.exr"),
                    "--bake", os.path.join(work, "baked.<UDIM>.####.png")], check=True)
    frame6 = os.path.join(shot, "suzanne.0006.obj")
    view = ["--view", "0.25,-0.3,-1", "--width", "640", "--height", "480", "--frame", "-1.1,-0.4,-0.8,1.1,1.0,0.85"]
    subprocess.run([deformkit, "preview", frame6, "--texture", os.path.join(work, "col.<UDIM>.png"), "--out",
                    os.path.join(images, "suzanne_before.png")] + view, check=True)
    subprocess.run([deformkit, "preview", frame6, "--texture", os.path.join(work, "baked.1001.0006.png"), "--out",
                    os.path.join(images, "suzanne_after.png")] + view, check=True)
print("wrote", os.path.join(images, "suzanne_before.png"), "and suzanne_after.png")
