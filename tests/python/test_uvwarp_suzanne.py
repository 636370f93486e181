"""The UV warp on a shot made and exported by a DCC (tests/data/suzanne: Blender's Suzanne with Blender's UVs,
bent and twisted by keyframed SimpleDeform modifiers, six frames exported by Blender's OBJ exporter),
solved frame after frame with warm start, measured by the independent metric of test_uvwarp_spot.py (geometry
images rasterised from the UV triangles in the test, rigid edges inside one UV island, the deformed 3D length
between the warped ends against the rest length) and the fold count computed in the test."""
import os

import numpy as np

import deformkit as dk
from test_uvwarp_spot import T, Layout, folded_anywhere, measure, rigid_disks

SHOT = os.path.join(os.path.dirname(__file__), "..", "data", "suzanne")


def test_suzanne_shot_from_blender_keeps_rigid_disks_frame_after_frame():
    frames = [dk.read_mesh(os.path.join(SHOT, "suzanne.%04d.obj" % f)) for f in range(1, 7)]
    mesh = frames[0]  # frame 1 is the rest pose
    layout = Layout(mesh)
    rest = mesh.points.astype(np.float64)
    rigidity, rigid = rigid_disks(layout)
    identity = np.stack(np.meshgrid(np.arange(T + 1) / T, np.arange(T + 1) / T), -1)
    solver = dk.UvWarpSolver(mesh, 1001, rigidity)
    removed = []
    for frame, deformed in enumerate(frames, start=1):
        points = deformed.points.astype(np.float64)
        solver.solve(points.astype(np.float32))
        warp = np.asarray(solver.warp, np.float64)
        assert folded_anywhere(warp) == 0, f"frame {frame}"
        before, edges, _, _ = measure(layout, rest, points, identity, rigid)
        after, _, left, inverted = measure(layout, rest, points, warp, rigid)
        assert edges > 20000 and left == 0 and inverted == 0, f"frame {frame}"
        if frame > 1:
            removed.append(1 - after / before)
        print(f"Suzanne frame {frame}: error {before:.4f} -> {after:.4f}")
    print("removed per frame:", " ".join(f"{100 * r:.1f}%" for r in removed))
    # Measured 57.3, 68.8, 74.1, 76.4, 77.4% (frames 2-6): the warm start follows the animation, and the
    # more the pose deforms the more of its error is removed. Before UV-16 to UV-19 a similar Blender shot of
    # Suzanne lost 40-49% with 57-1,575 inverted grid cells.
    assert removed[-1] > 0.74
    assert all(r > 0.5 for r in removed)
    assert all(b >= a - 0.01 for a, b in zip(removed, removed[1:]))
