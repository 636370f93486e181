"""Arguments as pipeline scripts pass them: numpy scalars where Python ones are expected, None where a path
is needed, callables returning the wrong thing, points edited in place. Each is taken as meant or refused with
InvalidInput naming the function and the argument, never a pybind11 cast error or a file that cannot be read
back."""
import os
import tempfile

import numpy as np
import pytest

import deformkit as dk

T = 16


def plane(n=4):
    """An n x n quad grid over UV tile 1001 (positions = UVs, z = 0)."""
    pts, uvs, counts, idx = [], [], [], []
    for j in range(n + 1):
        for i in range(n + 1):
            pts.append((i / n, j / n, 0.0))
            uvs.append((i / n, j / n))
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            counts.append(4)
            idx += [a, a + 1, a + n + 2, a + n + 1]
    idx = np.array(idx, np.int32)
    return dk.Mesh(np.array(pts, np.float32), np.array(counts, np.int32), idx, np.array(uvs, np.float32), idx)


def disk():
    y, x = np.mgrid[0:T, 0:T]
    return (np.hypot((x + 0.5) / T - 0.5, (y + 0.5) / T - 0.5) < 0.25).astype(np.float32)


def test_numpy_booleans_are_booleans_in_uv_warp_options():
    mesh = plane()
    for flag in (np.bool_(False), np.bool_(True)):
        a = dk.UvWarpSolver(mesh, 1001, disk(), warm_start=flag, seam_slide=flag)
        b = dk.UvWarpSolver(mesh, 1001, disk(), warm_start=bool(flag), seam_slide=bool(flag))
        assert a.options == b.options
    with pytest.raises(dk.InvalidInput, match="warm_start: is 1"):
        dk.UvWarpSolver(mesh, 1001, disk(), warm_start=np.int64(1))


def test_numpy_integer_tile_keys_are_tiles_in_shot_report():
    mesh = plane()
    with tempfile.TemporaryDirectory() as folder:
        log = os.path.join(folder, "shot.jsonl")
        dk.uvwarp_shot(mesh, [1, 2], lambda f: mesh.points * np.float32([1 + 0.1 * f, 1, 1]), {1001: disk()},
                       os.path.join(folder, "r.<UDIM>.####.exr"), log=log, iterations=1)
        tile = np.unique([1001])[0]  # np.int64
        got = dk.shot_report(log, os.path.join(folder, "a.html"), rigidity={tile: disk()})
        want = dk.shot_report(log, os.path.join(folder, "b.html"), rigidity={1001: disk()})
        assert got["problems"] == want["problems"] == 0
        for bad in (np.bool_(True), 1000.0, "1001"):
            with pytest.raises(dk.InvalidInput, match=r"shot_report: rigidity\[.*\]: is not a UDIM tile"):
                dk.shot_report(log, os.path.join(folder, "c.html"), rigidity={bad: disk()})
        # A deformed callable that returns an empty tuple: named in the page's notes, not a bare IndexError.
        notes = dk.shot_report(log, os.path.join(folder, "d.html"), rest=mesh, deformed=lambda f: (),
                               rigidity={1001: disk()})["notes"]
        assert any("shot_report: deformed(" in n and "is not the rest mesh's positions" in n for n in notes), notes


def test_an_output_pattern_of_none_is_named():
    mesh = plane()
    with pytest.raises(dk.InvalidInput, match=r"uvwarp_shot: out: is None \(expected a path pattern"):
        dk.uvwarp_shot(mesh, [1], lambda f: mesh.points, {1001: disk()}, None)


def test_a_mesh_whose_points_were_made_nan_is_not_written():
    mesh = dk.Mesh(np.eye(3, dtype=np.float32), [3], [0, 1, 2])
    mesh.points[1] = np.nan
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "m.obj")
        with pytest.raises(dk.InvalidInput, match=r"vertex 1: is \(nan, nan, nan\) \(expected finite coordinates\)"):
            dk.write_mesh(path, mesh)
        assert not os.path.exists(path)
        mesh.points[1] = (0, 1, 0)
        dk.write_mesh(path, mesh)
        assert np.array_equal(dk.read_mesh(path).points, mesh.points)



def test_a_mesh_whose_points_were_made_nan_is_not_written_into_a_ptex_file():
    # The file's mesh metadata held the NaN positions (PtexVertPositions) without a word.
    mesh = dk.make_grid(2, 2)
    mesh.points[3] = np.nan
    ptex = {"data": [np.zeros((2, 2, 1), np.float32)] * mesh.num_faces}
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "a.ptx")
        with pytest.raises(dk.InvalidInput, match=r"^write_ptex: mesh: vertex 3: is \(nan, nan, nan\)"):
            dk.write_ptex(path, ptex, mesh=mesh)
        assert not os.path.exists(path)
        mesh.points[3] = (1, 0, 0)
        dk.write_ptex(path, ptex, mesh=mesh)
        assert not np.isnan(dk.read_ptex(path)["metadata"]["PtexVertPositions"]).any()
