"""The deformkit Python module: numpy views, round trips and errors, checked against numpy references."""
import os
import struct
import subprocess
import sys
import zlib

import numpy as np
import pytest

import deformkit as dk


def quad_and_triangle():
    points = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0]], dtype=np.float32)
    return dk.Mesh(points, np.array([4, 3]), np.array([0, 1, 2, 3, 1, 4, 2]))


def test_built_for_debian_python():
    # Blender embeds Debian's own interpreter; the module must import there.
    assert sys.version_info[:2] == (3, 11)
    assert dk.__file__.endswith(".cpython-311-x86_64-linux-gnu.so")


def test_points_are_a_writable_view_without_copy():
    mesh = quad_and_triangle()
    pts = mesh.points
    assert pts.shape == (5, 3) and pts.dtype == np.float32
    assert not pts.flags.owndata  # a view of the C++ mesh
    pts[4] = (7, 8, 9)
    assert mesh.points[4].tolist() == [7, 8, 9]
    assert mesh.face_counts.tolist() == [4, 3]
    assert mesh.face_indices.tolist() == [0, 1, 2, 3, 1, 4, 2]
    assert not mesh.face_counts.flags.writeable
    assert mesh.uvs is None and mesh.uv_indices is None


def test_mesh_round_trip_is_bit_exact(tmp_path):
    rng = np.random.default_rng(7)
    tube = dk.make_capped_tube()
    tube.points[:] += rng.normal(scale=1e-3, size=tube.points.shape).astype(np.float32)
    path = tmp_path / "tube.obj"
    dk.write_mesh(path, tube)
    back = dk.read_mesh(path)
    assert np.array_equal(back.points, tube.points)
    assert np.array_equal(back.uvs, tube.uvs)
    assert np.array_equal(back.face_indices, tube.face_indices)
    assert np.array_equal(back.uv_indices, tube.uv_indices)
    assert back.udim_tiles() == [1001, 1002]
    assert back.is_manifold()


def test_image_round_trips(tmp_path):
    rng = np.random.default_rng(3)
    data = rng.uniform(-2, 3, size=(5, 7, 3)).astype(np.float32)
    dk.write_image(tmp_path / "a.exr", data, type="float", attributes={"deformkit:frame": "12"})
    back = dk.read_image(tmp_path / "a.exr")
    assert back.shape == (5, 7, 3) and back.dtype == np.float32
    assert np.array_equal(back, data)

    half = dk.read_image(_write(tmp_path / "h.exr", data, "half"))
    assert np.array_equal(half, data.astype(np.float16).astype(np.float32))

    unit = rng.uniform(0, 1, size=(4, 6)).astype(np.float32)
    png = dk.read_image(_write(tmp_path / "b.png", unit, "uint8"), channels=1)
    assert png.shape == (4, 6, 1)
    assert np.allclose(png[..., 0], np.round(unit * 255) / 255, atol=1e-7)
    with pytest.raises(dk.InvalidInput, match=r"read_image: channels: is -1"):
        dk.read_image(tmp_path / "b.png", channels=-1)


def _write(path, data, type):
    dk.write_image(path, data, type=type)
    return path


def test_openimageio_is_loaded_by_the_first_image_call_only(tmp_path):
    # A fresh interpreter: importing the module maps no OpenImageIO library; the first image written does.
    script = (
        "import sys, numpy as np, deformkit as dk\n"
        "def mapped():\n"
        "    return 'libOpenImageIO' in open('/proc/self/maps').read()\n"
        "before = mapped()\n"
        "dk.write_image(sys.argv[1], np.zeros((2, 2, 1), np.float32))\n"
        "print(before, mapped(), dk.read_image(sys.argv[1]).shape)\n"
    )
    out = subprocess.run([sys.executable, "-c", script, str(tmp_path / "a.exr")], check=True, capture_output=True,
                         text=True)
    assert out.stdout.split("\n")[0] == "False True (2, 2, 1)"


def test_udim_tiles(tmp_path):
    img = np.zeros((2, 2, 1), dtype=np.float32)
    for tile in (1001, 1002, 1011):
        dk.write_image(tmp_path / dk.expand_udim("r.<UDIM>.exr", tile), img)
    (tmp_path / "r.0999.exr").write_bytes(b"decoy")
    tiles = dk.udim_tiles(str(tmp_path / "r.<UDIM>.exr"))
    assert list(tiles) == [1001, 1002, 1011]
    assert tiles[1011].endswith("r.1011.exr")
    assert dk.expand_udim("t.<UVTILE>.png", 1012) == "t.u2_v2.png"


def test_errors_are_deformkit_errors(tmp_path):
    with pytest.raises(dk.IoError, match="nope.obj"):
        dk.read_mesh(tmp_path / "nope.obj")
    assert issubclass(dk.IoError, dk.Error) and issubclass(dk.TopologyError, dk.InvalidInput)
    with pytest.raises(dk.InvalidInput, match=r"face 1 corner 1"):
        dk.Mesh(np.zeros((3, 3), np.float32), np.array([3, 3]), np.array([0, 1, 2, 0, 9, 1]))
    with pytest.raises(dk.InvalidInput, match=r"\(n, 3\)"):
        dk.Mesh(np.zeros((3, 2), np.float32), np.array([3]), np.array([0, 1, 2]))
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n")
    with pytest.raises(dk.Error, match="line 3"):
        dk.read_mesh(bad)
    dk.write_image(tmp_path / "rgb.exr", np.zeros((2, 2, 3), np.float32))
    with pytest.raises(dk.InvalidInput, match="3 channels"):
        dk.read_image(tmp_path / "rgb.exr", channels=1)
    with pytest.raises(dk.Error, match="matches no file"):
        dk.udim_tiles(str(tmp_path / "none.<UDIM>.exr"))


def test_an_image_side_beyond_int32_is_refused_not_cropped(tmp_path):
    # (1, 2^31) float32 zeros: 8 GiB of address space numpy maps without touching. Its side was cut to its low
    # 32 bits and the image written as a crop of it without a word.
    wide = np.zeros((1, 2**31), np.float32)
    with pytest.raises(dk.InvalidInput, match=r"write_image: array: has shape \(1, 2147483648\) \(expected at most"):
        dk.write_image(tmp_path / "wide.exr", wide)
    assert not (tmp_path / "wide.exr").exists()
    identity = np.zeros((4, 4, 2), np.float32)
    with pytest.raises(dk.InvalidInput, match=r"apply_redirect: texture: has shape \(1, 2147483648\)"):
        dk.apply_redirect(wide, identity)


def test_text_that_is_not_utf8_reaches_python_whole(tmp_path):
    # A file name of other bytes: the message names it, the byte shown as its escape (an error whose text
    # was not UTF-8 used to reach Python without a message).
    name = os.fsdecode(bytes(tmp_path) + b"/x\xff.obj")
    with pytest.raises(dk.IoError) as raised:
        dk.read_mesh(name)
    assert str(raised.value).startswith(str(tmp_path) + "/x\\xff.obj: cannot open")
    # A PNG comment in Latin-1 (as its format says tEXt is): read as surrogate escapes, which encode back to
    # the file's bytes (a UnicodeDecodeError before).
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 2, 2, 8, 0, 0, 0, 0)) +
           chunk(b"tEXt", b"Comment\x00caf\xe9") + chunk(b"IDAT", zlib.compress(b"\x00" * 6)) + chunk(b"IEND", b""))
    (tmp_path / "latin1.png").write_bytes(png)
    comment = dk.read_image_info(tmp_path / "latin1.png")["attributes"]["Comment"]
    assert comment.encode("utf-8", "surrogateescape") == b"caf\xe9"


def test_array_arguments_are_checked_alike_by_every_function(tmp_path):
    # One set of conversions (numpy_support.h): the same shape messages from Mesh, the slide and the warps.
    tri = (np.zeros((3, 3), np.float32), np.array([3], np.int32), np.array([0, 1, 2], np.int32))
    with pytest.raises(dk.InvalidInput, match=r"Mesh: face_indices: has shape \(1, 3\)"):
        dk.Mesh(tri[0], tri[1], tri[2].reshape(1, 3))
    with pytest.raises(dk.InvalidInput, match=r"Mesh: uvs: given without uv_indices"):
        dk.Mesh(*tri, uvs=np.zeros((3, 2), np.float32))
    with pytest.raises(dk.InvalidInput, match=r"Mesh: uvs: has shape \(3, 3\)"):
        dk.Mesh(*tri, uvs=np.zeros((3, 3), np.float32), uv_indices=np.array([0, 1, 2], np.int32))
    with pytest.raises(dk.InvalidInput, match=r"write_image: array: has shape \(0, 4\) with 0 pixels"):
        dk.write_image(tmp_path / "empty.exr", np.zeros((0, 4), np.float32))
    with pytest.raises(dk.InvalidInput, match=r"write_image: array: has shape \(4,\)"):
        dk.write_image(tmp_path / "flat.exr", np.zeros(4, np.float32))


def test_preview_of_a_grid_fills_the_expected_region():
    grid = dk.make_grid(4, 4, 2.0, 2.0)
    img = dk.render_preview(grid, width=64, height=48)
    assert img.shape == (48, 64, 3)
    background = np.array([0.16, 0.17, 0.19], np.float32)
    covered = np.any(np.abs(img - background) > 1e-3, axis=2)
    assert 0.1 < covered.mean() < 0.9


def test_points_and_uvs_written_after_the_mesh_was_made_are_checked_where_used():
    # Mesh.points and Mesh.uvs are writable: a NaN written there is named as the vertex or UV it is, not as
    # a corner of a triangle being rasterised.
    mesh = dk.make_capped_tube()
    mesh.points[500] = np.nan
    with pytest.raises(dk.InvalidInput, match=r"^preview: vertex 500: is \(nan, nan, nan\)"):
        dk.render_preview(mesh, width=64, height=48)
    mesh = dk.make_capped_tube()
    mesh.uvs[500] = np.nan
    with pytest.raises(dk.InvalidInput, match=r"UV 500: is \(nan, nan\) \(expected finite texture coordinates\)"):
        dk.UvWarpSolver(mesh, 1001, np.zeros((64, 64), np.float32))


def test_make_grid_names_its_keywords():
    # The library named its own fields ("primitive: cellsX: is -1").
    with pytest.raises(dk.InvalidInput, match=r"^make_grid: cells_x: is -1 \(expected at least 1\)"):
        dk.make_grid(-1, 2)
    with pytest.raises(dk.InvalidInput, match=r"^make_grid: cells_y: is 0"):
        dk.make_grid(2, 0)
    with pytest.raises(dk.InvalidInput, match=r"^make_grid: size_y: is nan \(expected a finite size\)"):
        dk.make_grid(2, 2, 1.0, float("nan"))
    grid = dk.make_grid(3, 2, 6.0, 4.0)
    assert grid.num_vertices == 12 and np.asarray(grid.points).max(axis=0).tolist() == [6, 4, 0]
