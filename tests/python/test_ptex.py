"""deformkit.read_ptex / write_ptex / ptex_vertex_values and slide(weights_ptex=...): round trips bit for
bit per dtype, per-vertex values against a numpy reference, adjacency from a mesh, errors."""
import os

import numpy as np
import pytest

import deformkit as dk


def grid(n=4, with_triangle=False):
    """n x n unit quads (vertex (i, j) = j (n + 1) + i); optionally one more triangle on the right edge."""
    j, i = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    points = np.stack([i.ravel(), j.ravel(), np.zeros(i.size)], axis=1).astype(np.float32)
    a = (np.arange(n)[:, None] * (n + 1) + np.arange(n)[None, :]).ravel()
    faces = [list(f) for f in np.stack([a, a + 1, a + n + 2, a + n + 1], axis=1)]
    if with_triangle:
        points = np.vstack([points, [[n + 1.0, 0.5, 0.0]]]).astype(np.float32)
        faces.append([n, len(points) - 1, 2 * n + 1])
    counts = np.array([len(f) for f in faces], np.int32)
    return dk.Mesh(points, counts, np.concatenate(faces).astype(np.int32))


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16, np.float16, np.float32])
def test_write_then_read_gives_the_same_texels(tmp_path, dtype):
    rng = np.random.default_rng(3)
    shapes = [(4, 8, 3), (1, 1, 3), (16, 2, 3), (2, 2, 3)]
    if np.issubdtype(dtype, np.integer):
        data = [rng.integers(0, np.iinfo(dtype).max, size=s, dtype=dtype) for s in shapes]
    else:
        data = [rng.uniform(-2, 2, size=s).astype(dtype) for s in shapes]
    data[3][:] = data[3][0, 0]  # a constant face
    meta = {"author": "painter", "gains": np.array([0.5, 2.0], np.float64), "ids": np.arange(3, dtype=np.int32)}
    dk.write_ptex(tmp_path / "t.ptx", {"data": data, "metadata": meta})
    back = dk.read_ptex(tmp_path / "t.ptx")
    assert back["channels"] == 3 and back["mesh_type"] == "quad"
    assert back["data_type"] == {np.uint8: "u8", np.uint16: "u16", np.float16: "half", np.float32: "float"}[dtype]
    for a, b in zip(data, back["data"]):
        assert b.dtype == a.dtype and b.shape == a.shape
        assert a.tobytes() == b.tobytes()  # bit for bit
    assert [f["res"] for f in back["faces"]] == [(8, 4), (1, 1), (2, 16), (2, 2)]
    assert back["faces"][3]["constant"] and not back["faces"][0]["constant"]
    assert back["metadata"]["author"] == "painter"
    np.testing.assert_array_equal(back["metadata"]["gains"], meta["gains"])
    np.testing.assert_array_equal(back["metadata"]["ids"], meta["ids"])


def test_vertex_values_are_the_mean_of_the_corner_texels_around_each_vertex(tmp_path):
    mesh = grid(4, with_triangle=True)
    # 16 quads (one Ptex face each) then the triangle (3 sub-faces): face p is 4 x 4, texel (i, j) = p + i / 8 + j.
    data = []
    for p in range(16 + 3):
        j, i = np.meshgrid(np.arange(4), np.arange(4), indexing="ij")
        data.append((p + i / 8.0 + j).astype(np.float32)[:, :, None])
    dk.write_ptex(tmp_path / "m.ptx", {"data": data}, mesh=mesh)
    values = dk.ptex_vertex_values(mesh, tmp_path / "m.ptx")
    assert values.shape == (mesh.num_vertices, 1)
    # Reference: corner k of a quad reads texel (0,0), (3,0), (3,3), (0,3) as (column, row); sub-face k of the
    # triangle (Ptex face 16 + k) reads its (0, 0) at corner k.
    sums = np.zeros(mesh.num_vertices)
    counts = np.zeros(mesh.num_vertices)
    corner = [(0, 0), (3, 0), (3, 3), (0, 3)]
    offset = 0
    for f, n in enumerate(mesh.face_counts):
        verts = mesh.face_indices[offset:offset + n]
        offset += n
        for k, v in enumerate(verts):
            p, (i, j) = (f, corner[k]) if n == 4 else (16 + k, (0, 0))
            sums[v] += data[p][j, i, 0]
            counts[v] += 1
    np.testing.assert_allclose(values[:, 0], sums / counts, rtol=0, atol=1e-6)  # float means of small values
    # The same from the dict, and a file of another mesh is refused naming both counts.
    np.testing.assert_array_equal(dk.ptex_vertex_values(mesh, dk.read_ptex(tmp_path / "m.ptx")), values)
    with pytest.raises(dk.InvalidInput, match="has 19 faces.*16 Ptex faces"):
        dk.ptex_vertex_values(grid(4), tmp_path / "m.ptx")


def test_write_with_a_mesh_gives_opensubdiv_adjacency_and_the_mesh_metadata(tmp_path):
    mesh = grid(2)
    dk.write_ptex(tmp_path / "a.ptx", {"data": [np.zeros((1, 1, 1), np.float32)] * 4}, mesh=mesh)
    back = dk.read_ptex(tmp_path / "a.ptx")
    # Face 0 (bottom left) has face 1 to its right (edge 1) and face 2 above (edge 2); the others are the
    # boundary. The neighbours' edges point back: face 1's left (3), face 2's bottom (0).
    assert back["faces"][0]["adj_faces"] == (-1, 1, 2, -1)
    assert back["faces"][0]["adj_edges"][1:3] == (3, 0)
    np.testing.assert_array_equal(back["metadata"]["PtexFaceVertCounts"], [4, 4, 4, 4])
    np.testing.assert_array_equal(back["metadata"]["PtexFaceVertIndices"], mesh.face_indices)
    np.testing.assert_array_equal(back["metadata"]["PtexVertPositions"], mesh.points.ravel())


def test_slide_takes_weights_from_a_ptex_map(tmp_path):
    mesh = grid(8)
    rng = np.random.default_rng(1)
    data = [np.full((2, 2, 1), rng.uniform(), np.float32) for _ in range(64)]
    dk.write_ptex(tmp_path / "w.ptx", {"data": data}, mesh=mesh)
    weights = dk.ptex_vertex_values(mesh, tmp_path / "w.ptx")[:, 0]
    args = (mesh.points, mesh.face_counts, mesh.face_indices, 40, (0.5, 0.25, 0.0), 3.0)
    from_ptex = dk.slide(*args, weights_ptex=tmp_path / "w.ptx")
    np.testing.assert_array_equal(from_ptex, dk.slide(*args, weights=weights))
    assert np.abs(from_ptex - mesh.points).max() > 0.1
    with pytest.raises(dk.InvalidInput, match="weights_ptex"):
        dk.slide(*args, weights=weights, weights_ptex=tmp_path / "w.ptx")


def test_bad_input_names_the_problem(tmp_path):
    with pytest.raises(dk.InvalidInput, match="power of two"):
        dk.write_ptex(tmp_path / "x.ptx", {"data": [np.zeros((3, 4, 1), np.float32)]})
    with pytest.raises(dk.InvalidInput, match="float64"):
        dk.write_ptex(tmp_path / "x.ptx", {"data": [np.zeros((4, 4, 1), np.float64)]})
    (tmp_path / "bad.ptx").write_bytes(b"x" * 100)
    with pytest.raises(dk.ParseError, match="bad.ptx"):
        dk.read_ptex(tmp_path / "bad.ptx")


def test_metadata_text_in_any_encoding_reads_and_writes_back_byte_for_byte(tmp_path):
    # Ptex text is bytes: a Latin-1 tool writes "\xe9" where UTF-8 has "\xc3\xa9". Such bytes read as surrogate
    # escapes (PEP 383), and written back are the same bytes.
    latin1 = "caf\udce9"  # b"caf\xe9" read with errors="surrogateescape"
    assert latin1.encode("utf-8", "surrogateescape") == b"caf\xe9"
    data = {"data": [np.full((4, 4, 1), 0.5, np.float32)], "metadata": {latin1: "Ren\udce9", "utf8": "Ren\u00e9"}}
    dk.write_ptex(tmp_path / "a.ptx", data)
    # Read back as the same escapes: the file holds the lone byte 0xe9, which no UTF-8 text decodes to.
    back = dk.read_ptex(tmp_path / "a.ptx")
    assert back["metadata"] == {latin1: "Ren\udce9", "utf8": "Ren\u00e9"}
    dk.write_ptex(tmp_path / "b.ptx", back)
    assert dk.read_ptex(tmp_path / "b.ptx")["metadata"] == back["metadata"]
    # A lone surrogate that is no escaped byte, and a key that is no str, are named.
    with pytest.raises(dk.InvalidInput, match=r"metadata 'k': holds a lone surrogate"):
        dk.write_ptex(tmp_path / "c.ptx", {**data, "metadata": {"k": "\ud800"}})
    with pytest.raises(dk.InvalidInput, match=r"metadata key 7: is of type int \(expected a str\)"):
        dk.write_ptex(tmp_path / "c.ptx", {**data, "metadata": {7: "x"}})
    # A triangle-type file cannot be laid out on a mesh's Ptex faces: said so, not as a face count.
    mesh = dk.Mesh(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32), np.array([3], np.int32),
                   np.array([0, 1, 2], np.int32))
    with pytest.raises(dk.InvalidInput, match=r"mesh_type: is 'triangle' with a mesh \(expected 'quad'"):
        dk.write_ptex(tmp_path / "t.ptx", {**data, "mesh_type": "triangle"}, mesh=mesh)
    # A value that is no string or array is named by its type (None was "an array of 0 dimensions").
    for value, kind in ((None, "NoneType"), (3.5, "float"), ({"a": 1}, "dict")):
        with pytest.raises(dk.InvalidInput, match=rf"metadata 'k': is {kind} \(expected a string or a 1-D"):
            dk.write_ptex(tmp_path / "c.ptx", {**data, "metadata": {"k": value}})


def test_constant_faces_read_as_one_pixel_seen_everywhere_and_write_back_as_constants(tmp_path):
    # An unpainted face declared 32768 x 32768 (float RGBA: 16 GiB expanded) next to a painted one: read as a
    # read-only broadcast of its pixel, written back byte for byte, sampled by ptex_vertex_values.
    value = np.array([0.25, 0.5, 0.75, 1.0], np.float32)
    painted = np.random.default_rng(3).random((4, 4, 4), dtype=np.float32)
    dk.write_ptex(tmp_path / "c.ptx", {"data": [np.broadcast_to(value, (32768, 32768, 4)), painted]})
    back = dk.read_ptex(tmp_path / "c.ptx")
    big = back["data"][0]
    assert big.shape == (32768, 32768, 4) and big.strides == (0, 0, 4) and not big.flags.writeable
    assert back["faces"][0]["constant"] and not back["faces"][1]["constant"]
    np.testing.assert_array_equal(big[[0, 12345, 32767], [32767, 0, 777]], np.tile(value, (3, 1)))
    np.testing.assert_array_equal(back["data"][1], painted)
    dk.write_ptex(tmp_path / "d.ptx", back)
    assert (tmp_path / "d.ptx").read_bytes() == (tmp_path / "c.ptx").read_bytes()
    # A face whose texels are all equal is written as a constant too, and so read.
    dk.write_ptex(tmp_path / "e.ptx", {"data": [np.full((8, 8, 1), 0.5, np.float32)]})
    assert dk.read_ptex(tmp_path / "e.ptx")["data"][0].strides[:2] == (0, 0)


def test_arguments_of_the_wrong_type_name_the_argument_and_what_was_expected(tmp_path):
    face = np.zeros((4, 4, 1), np.float32)
    grid = dk.make_grid(2, 2)
    cases = [
        (lambda: dk.ptex_vertex_values(grid, 0.5), r"^ptex_vertex_values: ptex: is a float \(expected a Ptex file "
         r"path or read_ptex's dict\)"),
        (lambda: dk.ptex_vertex_values(1.5, tmp_path / "w.ptx"), r"^ptex_vertex_values: mesh: is a float \(expected "
         r"a deformkit.Mesh or a mesh file path\)"),
        (lambda: dk.write_ptex(tmp_path / "x.ptx", {"data": [face]}, 5), r"^write_ptex: mesh: is an int"),
        (lambda: dk.write_ptex(tmp_path / "x.ptx", {"data": 3}), r"^write_ptex: data: is an int \(expected a list of"),
        (lambda: dk.write_ptex(tmp_path / "x.ptx", {"data": [face], "alpha_channel": "x"}),
         r"^write_ptex: alpha_channel: is a str \(expected an int"),
        (lambda: dk.write_ptex(tmp_path / "x.ptx", {"data": [face], "faces": 3}), r"^write_ptex: faces: is an int"),
        (lambda: dk.write_ptex(tmp_path / "x.ptx", {"data": [face], "faces": [3]}), r"^write_ptex: faces\[0\]: is an int"),
        (lambda: dk.write_ptex(tmp_path / "x.ptx", {"data": [face], "faces": [{"adj_faces": 1, "adj_edges": 2}]}),
         r"^write_ptex: faces\[0\]\['adj_faces'\]: is an int \(expected 4 ints"),
        (lambda: dk.write_ptex(tmp_path / "x.ptx", {"data": [face], "metadata": 3}), r"^write_ptex: metadata: is an int"),
        (lambda: dk.write_ptex(tmp_path / "x.ptx", {"data": [face], "faces": [{"adj_faces": [0, 0, 0, 0]}]}),
         r"^write_ptex: faces\[0\]: has adj_faces but no adj_edges"),
        (lambda: dk.shot_report(3, tmp_path / "p.html"), r"^shot_report: logs: is an int \(expected a JSON-lines"),
        # Typos and malformed entries are named, not ignored or cut.
        (lambda: dk.write_ptex(tmp_path / "x.ptx", {"data": [face], "meta_data": {}}),
         r"^write_ptex: ptex key 'meta_data': is not a key it takes \(expected one of data, "),
        (lambda: dk.write_ptex(tmp_path / "x.ptx", {"data": [face], "faces": [{"adjfaces": [0, 0, 0, 0]}]}),
         r"^write_ptex: faces\[0\] key 'adjfaces': is not a key it takes"),
        (lambda: dk.write_ptex(tmp_path / "x.ptx", {"data": [face], "faces": [{}, {}]}),
         r"^write_ptex: faces: has 2 entries \(expected 1, one per face of data\)"),
        (lambda: dk.write_ptex(tmp_path / "x.ptx", {"data": [face], "faces": [{"adj_faces": [0, 0], "adj_edges": [0, 0]}]}),
         r"^write_ptex: faces\[0\]\['adj_faces'\]: has 2 entries \(expected 4, one per edge\)"),
        (lambda: dk.write_ptex(tmp_path / "x.ptx", {"data": [face], "faces": [{"adj_faces": [0, 0, 0, 0],
                                                                              "adj_edges": [0, 300, 0, 0]}]}),
         r"^write_ptex: faces\[0\]\['adj_edges'\]\[1\]: is 300 \(expected an edge 0 to 3\)"),
        (lambda: dk.write_ptex(tmp_path / "x.ptx", {"data": [face], "metadata": {"m": np.zeros((2, 2), np.float32)}}),
         r"^write_ptex: metadata 'm': is an array of 2 dimensions"),
    ]
    for call, message in cases:
        with pytest.raises(dk.InvalidInput, match=message):
            call()
    assert not (tmp_path / "x.ptx").exists()


REFERENCE_FILES = os.path.join(os.path.dirname(__file__), "..", "data", "ptex")


@pytest.mark.parametrize("name", ["ref_tri_float.ptx", "ref_quad_u8_rgba.ptx", "ref_quad_half_a0.ptx"])
def test_a_reference_file_read_and_written_again_is_the_same_file(tmp_path, name):
    """Files written by the reference Ptex library (tests/data/ptex/README.txt): the dict keeps the mesh
    type, modes, adjacency and metadata, and the writer gives back the reference writer's bytes."""
    path = os.path.join(REFERENCE_FILES, name)
    d = dk.read_ptex(path)
    assert d["mesh_type"] == ("triangle" if "tri" in name else "quad")
    dk.write_ptex(tmp_path / name, d)
    assert (tmp_path / name).read_bytes() == open(path, "rb").read()


def test_mesh_type_and_modes_are_written_and_checked(tmp_path):
    data = [np.arange(16, dtype=np.float32).reshape(4, 4, 1)]
    dk.write_ptex(tmp_path / "t.ptx", {"data": data, "mesh_type": "triangle", "v_border_mode": "periodic",
                                       "edge_filter_mode": "tangent_vectors"})
    back = dk.read_ptex(tmp_path / "t.ptx")
    assert (back["mesh_type"], back["u_border_mode"], back["v_border_mode"], back["edge_filter_mode"]) == (
        "triangle", "clamp", "periodic", "tangent_vectors")
    with pytest.raises(dk.InvalidInput, match="mesh_type: is 'quads' .*'triangle' or 'quad'"):
        dk.write_ptex(tmp_path / "x.ptx", {"data": data, "mesh_type": "quads"})
    with pytest.raises(dk.InvalidInput, match="face 0.*triangle file"):
        dk.write_ptex(tmp_path / "x.ptx", {"data": [np.zeros((4, 8, 1), np.float32)], "mesh_type": "triangle"})


def test_a_file_of_another_mesh_names_the_file_once_and_the_mesh_by_its_size_or_path(tmp_path):
    dk.write_ptex(tmp_path / "w.ptx", {"data": [np.zeros((2, 2, 1), np.float32)] * 16}, mesh=grid(4))
    small = grid(3)
    expected = r"w\.ptx: has 16 faces \(expected 9 Ptex faces .* for mesh \(16 vertices, 9 faces\)\)$"
    with pytest.raises(dk.InvalidInput, match=expected) as error:
        dk.ptex_vertex_values(small, tmp_path / "w.ptx")
    assert str(error.value).count("w.ptx") == 1
    with pytest.raises(dk.InvalidInput, match=r"^slide: weights_ptex: .*w\.ptx: .*for mesh \(16 vertices, 9 faces\)"):
        dk.slide(small.points, small.face_counts, small.face_indices, 0, [0.1, 0, 0], 0.5,
                 weights_ptex=tmp_path / "w.ptx")
    dk.write_mesh(tmp_path / "small.obj", small)
    with pytest.raises(dk.InvalidInput, match=r"for mesh .*small\.obj\)$"):
        dk.ptex_vertex_values(tmp_path / "small.obj", tmp_path / "w.ptx")
