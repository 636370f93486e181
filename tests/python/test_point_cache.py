"""Point caches from Python: deformkit.write_point_cache and deformkit.PointCache against PC2 and MDD bytes parsed
here with struct (the formats' own descriptions, docs/io.md), and the UV warp's shot job fed the rigged Fox shot
(tests/data/fox, Blender's OBJ export) as a PC2 and an MDD cache: the same redirect maps, bit for bit, as from its
OBJ sequence."""
import os
import struct
import sys

import numpy as np
import pytest

import deformkit as dk

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "scripts"))
from uvwarp_rigged_figures import chart_texels, rigid_disks  # noqa: E402

SHOT = os.path.join(os.path.dirname(__file__), "..", "data", "fox")


def parse_pc2(data):
    magic, version, vertices, start, sampling, samples = struct.unpack_from("<12siiffi", data, 0)
    assert magic == b"POINTCACHE2\0" and version == 1
    positions = np.frombuffer(data, "<f4", offset=32).reshape(samples, vertices, 3)
    return start, sampling, positions


def parse_mdd(data):
    frames, vertices = struct.unpack_from(">ii", data, 0)
    times = np.frombuffer(data, ">f4", count=frames, offset=8)
    positions = np.frombuffer(data, ">f4", offset=8 + 4 * frames).reshape(frames, vertices, 3)
    return times, positions


def test_written_caches_parse_by_hand_and_read_back(tmp_path):
    rng = np.random.default_rng(7)
    positions = (rng.standard_normal((5, 11, 3)) * 10.0 ** rng.integers(-6, 6, (5, 11, 3))).astype(np.float32)
    dk.write_point_cache(tmp_path / "a.pc2", positions, first_frame=-2)
    start, sampling, parsed = parse_pc2((tmp_path / "a.pc2").read_bytes())
    assert (start, sampling) == (-2.0, 1.0)
    assert np.array_equal(parsed, positions)
    dk.write_point_cache(tmp_path / "a.mdd", positions, first_frame=-2, fps=30.0)
    times, parsed = parse_mdd((tmp_path / "a.mdd").read_bytes())
    assert np.array_equal(times, (np.arange(5) / 30.0).astype(np.float32))
    assert np.array_equal(parsed, positions)

    pc2, mdd = dk.PointCache(tmp_path / "a.pc2"), dk.PointCache(tmp_path / "a.mdd", first_frame=-2)
    assert pc2.format == "PC2" and mdd.format == "MDD"
    assert pc2.frames == mdd.frames == [-2, -1, 0, 1, 2]
    assert pc2.vertex_count == 11 and pc2.sample_count == 5
    for frame in (2, -2, 0):
        assert np.array_equal(pc2.read(frame), positions[frame + 2])
        assert np.array_equal(mdd.read(frame), positions[frame + 2])
    assert dk.PointCache(tmp_path / "a.mdd").frames == [1, 2, 3, 4, 5]  # an MDD counts from 1 unless told

    with pytest.raises(dk.Error, match=r"a.pc2: frame 3: is not in the cache \(expected one of its frames -2 to 2\)"):
        pc2.read(3)
    assert [pc2.sample_frame(k) for k in range(5)] == [-2.0, -1.0, 0.0, 1.0, 2.0]
    for sample in (5, -1):
        with pytest.raises(dk.InvalidInput, match=rf"a.pc2: sample {sample}: does not exist \(expected a sample from 0 to 4\)"):
            pc2.sample_frame(sample)
    with pytest.raises(dk.Error, match=r"\(frames, vertices, 3\)"):
        dk.write_point_cache(tmp_path / "b.pc2", positions[0])
    bad = positions.copy()
    bad[3, 4, 1] = np.nan
    with pytest.raises(dk.Error, match=r"b.pc2: frame 4: vertex 4: is not finite"):
        dk.write_point_cache(tmp_path / "b.pc2", bad, first_frame=1)
    assert not (tmp_path / "b.pc2").exists()
    (tmp_path / "cut.mdd").write_bytes((tmp_path / "a.mdd").read_bytes()[:-1])
    with pytest.raises(dk.Error, match=r"cut.mdd: frame 5: is cut short"):
        dk.PointCache(tmp_path / "cut.mdd")


def test_fox_shot_from_caches_writes_the_maps_of_its_obj_sequence(tmp_path):
    rest = dk.read_mesh(os.path.join(SHOT, "rest.obj"))
    frames = list(range(1, 25))
    positions = np.stack([dk.read_mesh(os.path.join(SHOT, f"anim.{f:04d}.obj")).points for f in frames])
    dk.write_point_cache(tmp_path / "fox.pc2", positions, first_frame=1)
    dk.write_point_cache(tmp_path / "fox.mdd", positions, first_frame=1)  # frames 0.. by time, 1.. by count
    t = 64
    rigidity = {1001: rigid_disks(chart_texels(rest, t), t)}
    solved = [9, 19, 24]  # a few frames of the run, the most deformed among them (19)
    outputs = {}
    for name, deformed, extra in (("obj", os.path.join(SHOT, "anim.####.obj"), {}),
                                  ("pc2", str(tmp_path / "fox.pc2"), {}),
                                  ("mdd", str(tmp_path / "fox.mdd"), {"cache_start": 1})):
        out = tmp_path / name
        out.mkdir()
        report = dk.uvwarp_shot(rest, solved, deformed, ("disks", rigidity), str(out / "redirect.<UDIM>.####.exr"),
                                resolution=t, **extra)
        assert report[1001]["written"] == len(solved)
        outputs[name] = [dk.read_image(out / f"redirect.1001.{f:04d}.exr") for f in solved]
    for name in ("pc2", "mdd"):
        for a, b in zip(outputs[name], outputs["obj"]):
            assert a.tobytes() == b.tobytes()
    # The maps warp: not the identity.
    assert max(np.abs(m - outputs["obj"][0]).max() for m in outputs["obj"][1:]) > 1.0 / t
