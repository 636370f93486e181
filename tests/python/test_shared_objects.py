"""Objects shared between Python threads give what sequential calls give; rejected calls change nothing.

Each bound object runs its calls without the GIL; its Python object serialises them (object_lock.h). The
reference of every threaded result is the same call made alone, before any thread starts.
"""
import concurrent.futures as cf
import os
import tempfile

import numpy as np
import pytest

import deformkit as dk

x, y = np.meshgrid(np.linspace(-1, 1, 121), np.linspace(-1.5, 1.5, 121), indexing="ij")
P = np.stack([x, y, 0.3 * x * y], -1).reshape(-1, 3).astype(np.float32)
CAGE = np.array([[-1.2, -1.8, -.5], [1.2, -1.8, -.5], [1.2, 1.8, -.5], [-1.2, 1.8, -.5]], np.float32)
REF = np.array([[0, -1.5, 0], [0, 0, 0], [0, 1.5, 0]], np.float32)
AXES = np.diag([2.4, 3.2, 1.0]).astype(np.float32)
ORIGIN = np.array([-1.2, -1.6, -0.5], np.float32)


def lattice(k):
    i, j, l = np.meshgrid(np.arange(3), np.arange(3), np.arange(2), indexing="ij")
    grid = ORIGIN + np.stack([i / 2, j / 2, l], -1) @ AXES
    return (grid + np.float32(0.05 * k) * np.sin(grid * 3)).astype(np.float32)


def same_as_alone(call, variants, calls=48):
    """How many of `calls` threaded calls (4 threads, variants in turn) differ from the call made alone."""
    expected = [call(v) for v in variants]
    with cf.ThreadPoolExecutor(4) as pool:
        got = list(pool.map(lambda i: (i % len(variants), call(variants[i % len(variants)])), range(calls)))
    return sum(not np.array_equal(r, expected[i]) for i, r in got)


def test_bound_deformers_shared_by_threads_give_the_calls_made_alone():
    wires = dk.Wires([REF], radius=0.5)
    wires.bind(P)
    assert same_as_alone(lambda c: wires.evaluate(P, wire_curves=[c]),
                         [REF + np.float32([0.1 * k, 0, 0.05 * k]) for k in range(4)]) == 0

    mesh_warp = dk.MeshWarp(CAGE, [4], [0, 1, 2, 3], beta=3.0)
    mesh_warp.bind(P)
    assert same_as_alone(lambda t: mesh_warp.evaluate(t), [CAGE + np.float32([0, 0, 0.1 * k]) for k in range(4)]) == 0

    twist = dk.Twist(P, [0, 0, 0], [0, 1, 0], [-1.5, 1.5], [0, 2.0])
    weights = np.full(len(P), 0.5, np.float32)

    def twisted(p):
        buf = p.copy()
        twist.evaluate(buf, weights=weights, out=buf)
        return buf
    assert same_as_alone(twisted, [P + np.float32(0.05 * k) for k in range(4)]) == 0

    bend = dk.Bend(P, [0, 0, 0], [0, 1, 0], [0, 0, 1], 0.5, 0.0, -1.0, 1.0)
    assert same_as_alone(lambda p: bend.evaluate(p), [P + np.float32(0.05 * k) for k in range(4)]) == 0

    ffd = dk.Ffd(ORIGIN, AXES, [2, 2, 1])
    ffd.bind(P)
    ffd.set_target(lattice(1))
    assert same_as_alone(lambda p: ffd.evaluate(p), [P + np.float32(0.01 * k) for k in range(4)]) == 0
    assert same_as_alone(lambda _: ffd.evaluate(), [None]) == 0

    lines = np.array([[[10, 10], [50, 10]], [[10, 40], [50, 40]]], np.float32)
    beier_neely = dk.BeierNeely(lines, lines + np.float32(2))
    beier_neely.bind(P * np.float32(20) + np.float32(30))
    assert same_as_alone(lambda p: beier_neely.evaluate(p), [P * np.float32(20) + np.float32(30 + k) for k in range(4)]) == 0


def test_rebinding_while_other_threads_evaluate_never_mixes_two_binds():
    # Threads evaluate the bound rest points while others bind again to the same points: every result is
    # the one bound rest gives (a bind swapped under an evaluation would read freed or half-written points).
    ffd = dk.Ffd(ORIGIN, AXES, [2, 2, 1])
    ffd.bind(P)
    ffd.set_target(lattice(2))
    expected = ffd.evaluate()

    def work(i):
        if i % 3 == 0:
            ffd.bind(P.copy())
            return None
        return ffd.evaluate()
    with cf.ThreadPoolExecutor(4) as pool:
        results = [r for r in pool.map(work, range(60)) if r is not None]
    assert all(np.array_equal(r, expected) for r in results)


def test_a_point_cache_read_by_threads_gives_each_thread_its_frame():
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "frames.pc2")
        dk.write_point_cache(path, np.stack([np.full((20000, 3), f, np.float32) for f in range(1, 9)]))
        cache = dk.PointCache(path)
        frames = cache.frames * 20
        with cf.ThreadPoolExecutor(4) as pool:
            results = list(pool.map(cache.read, frames))
        assert sum(not np.all(r == f) for f, r in zip(frames, results)) == 0


def test_an_output_that_overlaps_its_input_is_refused():
    buf = np.vstack([P, P[:1]])
    twist = dk.Twist(P, [0, 0, 0], [0, 1, 0], [-1.5, 1.5], [0, 2.0])
    with pytest.raises(dk.InvalidInput, match="Twist: out: overlaps points without being the same array"):
        twist.evaluate(buf[:-1], out=buf[1:])
    ffd = dk.Ffd(ORIGIN, AXES, [2, 2, 1])
    ffd.bind(P)
    with pytest.raises(dk.InvalidInput, match="Ffd.evaluate: out: overlaps points"):
        ffd.evaluate(buf[:-1], out=buf[1:])
    # In place and apart stay allowed, and equal a fresh array.
    fresh = twist.evaluate(P)
    same = P.copy()
    twist.evaluate(same, out=same)
    apart = np.empty_like(P)
    twist.evaluate(P, out=apart)
    assert np.array_equal(same, fresh) and np.array_equal(apart, fresh)


def test_a_rejected_wires_call_leaves_the_wires_as_they_were():
    wires = dk.Wires([REF, REF + np.float32([1, 0, 0])], radius=0.5)
    wires.bind(P)
    rest = wires.evaluate(P)
    moved = [REF + np.float32([0.3, 0, 0]), REF + np.float32([1.3, 0, 0])]
    with pytest.raises(dk.InvalidInput, match="weights"):
        wires.evaluate(P, wire_curves=moved, weights=np.ones(3, np.float32))
    bad = [moved[0], moved[1].copy()]
    bad[1][1, 2] = np.nan  # the second curve is refused after the first was taken
    with pytest.raises(dk.InvalidInput, match=r"wire 1 wire curve point 1: is \(1.3, 0, nan\)"):
        wires.evaluate(P, wire_curves=bad)
    with pytest.raises(dk.InvalidInput, match="wire 1 wire curve point 1"):
        wires.set_wire_curves(bad)
    assert np.array_equal(wires.evaluate(P), rest)
    # An accepted call keeps its curves, as documented.
    wires.evaluate(P, wire_curves=moved)
    assert not np.array_equal(wires.evaluate(P), rest)


def test_a_wire_index_out_of_range_is_named():
    wires = dk.Wires([REF], radius=0.5, variant="smooth")
    assert wires.smooth_samples(0) >= 16
    for index in (1, -1):
        with pytest.raises(dk.InvalidInput, match=rf"wires: wire index {index}: does not exist \(expected an index in \[0, 1\)\)"):
            wires.smooth_samples(index)


def test_whole_numbers_are_taken_exactly_or_refused_naming_the_argument():
    tri = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32)
    for indices, text in (([0, 1.9, 2.7], "face_indices: holds 1.9 at index 1"),
                          (np.array([0, 1, 2**32 + 2], np.int64), "face_indices: holds 4294967298 at index 2"),
                          (np.array([0, 1, 2**63], np.uint64), "face_indices: holds 9223372036854775808 at index 2"),
                          (["0", "1", "2"], "face_indices: is an array of <U1 values"),
                          ([True, False, True], "face_indices: is an array of bool values")):
        with pytest.raises(dk.InvalidInput, match=rf"Mesh: {text} \(expected whole numbers"):
            dk.Mesh(tri, [3], indices)
    with pytest.raises(dk.InvalidInput, match="face_counts: holds 4294967299 at index 0"):
        dk.Mesh(tri, np.array([2**32 + 3], np.int64), [0, 1, 2])
    with pytest.raises(dk.InvalidInput, match="Ffd: divisions: holds 1.5 at index 0"):
        dk.Ffd([0, 0, 0], np.eye(3), [1.5, 1, 1])
    # Whole numbers of any numeric type give the same mesh as int32.
    want = dk.Mesh(tri, np.array([3], np.int32), np.array([0, 1, 2], np.int32))
    for dtype in (np.int8, np.uint16, np.int64, np.uint64, np.float32, np.float64):
        mesh = dk.Mesh(tri, np.array([3], dtype), np.array([0, 1, 2], dtype))
        assert np.array_equal(mesh.face_indices, want.face_indices) and np.array_equal(mesh.face_counts, want.face_counts)
    assert dk.Ffd([0, 0, 0], np.eye(3), np.array([2.0, 1, 1])).source_points.shape == (3, 2, 2, 3)


def test_a_non_finite_envelope_or_weight_is_refused_by_every_deformer():
    nan_weights = np.full(len(P), np.nan, np.float32)
    ffd = dk.Ffd(ORIGIN, AXES, [2, 2, 1])
    ffd.bind(P)
    beier_neely = dk.BeierNeely(np.array([[[10, 10], [50, 10]]], np.float32), np.array([[[12, 12], [52, 12]]], np.float32))
    beier_neely.bind(P)
    calls = {
        "FFD evaluate: envelope": lambda: ffd.evaluate(P, envelope=float("inf")),
        "FFD evaluate: painted weight of point 0": lambda: ffd.evaluate(P, weights=nan_weights),
        "wires: envelope": lambda: dk.wires(P, [REF], [REF + np.float32(0.2)], envelope=float("nan")),
        "wires: painted weight of point 0": lambda: dk.wires(P, [REF], [REF + np.float32(0.2)], weights=nan_weights),
        "beier_neely: envelope": lambda: beier_neely.evaluate(P, envelope=float("nan")),
        "twist: painted weight of point 0": lambda: dk.twist(P, [0, 0, 0], [0, 1, 0], [-1, 1], [0, 1.5], weights=nan_weights),
    }
    for text, call in calls.items():
        with pytest.raises(dk.InvalidInput, match=text):
            call()
