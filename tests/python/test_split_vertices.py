"""Split vertices as a glTF hands them over: the Khronos Fox (tests/data/fox/Fox.glb, every triangle with its own
three vertices: 1,728 vertices at 290 positions), read by deformkit.read_mesh and slid. Without welding the slide
moved only the handle's own triangle and left a crack; welded, every copy of a position moves to the same place,
and the slide is, copy by copy, the slide of the same mesh with shared vertices (welded here, numbered as the
library numbers it: by first copy), bit for bit. Random drags, fixed seed."""
import os

import numpy as np

import deformkit as dk

DATA = os.path.join(os.path.dirname(__file__), "..", "data", "fox")


def shared_by_first_copy(split):
    """The test's own weld: per split vertex its position's rank by first appearance, and the shared mesh."""
    keys = [tuple(p) for p in split.points.tolist()]
    rank, first = {}, []
    index = np.empty(len(keys), np.int32)
    for k, key in enumerate(keys):
        if key not in rank:
            rank[key] = len(first)
            first.append(k)
        index[k] = rank[key]
    points = split.points[first]
    return index, points, index[split.face_indices]


def test_fox_glb_slides_without_a_crack_and_as_the_shared_mesh():
    split = dk.read_mesh(os.path.join(DATA, "Fox.glb"))
    assert split.num_vertices == 1728 and split.num_faces == 576
    index, points, faces = shared_by_first_copy(split)
    assert len(points) == 290
    assert dk.read_mesh(os.path.join(DATA, "rest.obj")).num_vertices == 290  # Blender's export, welded
    diagonal = float(np.linalg.norm(points.max(0) - points.min(0)))
    rng = np.random.default_rng(37)
    for case in range(12):
        handle = int(rng.integers(split.num_vertices))
        radius = diagonal * float(rng.uniform(0.08, 0.25))
        d = (rng.uniform(-1, 1, 3) * 0.05 * diagonal).astype(np.float32)
        region = "geodesic" if case % 2 else "euclidean"
        slider = dk.Slider(split.points, split.face_counts, split.face_indices, handle=handle, radius=radius,
                           region=region)
        got = slider.evaluate(d)
        out = got.points if hasattr(got, "points") else got
        shared = dk.Slider(points, split.face_counts, faces, handle=int(index[handle]), radius=radius, region=region)
        want = shared.evaluate(d)
        want_points = want.points if hasattr(want, "points") else want
        # Every copy where its shared vertex went, bit for bit: no crack.
        assert out.tobytes() == want_points[index].tobytes(), case
        assert got.welded == 1728 - 290 and got.unreachable == 0
        assert got.moved == want.moved and got.moved > 3  # more than the handle's own triangle
