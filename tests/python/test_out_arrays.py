"""Bound deformers write into a caller's array when given out=: the same values as a fresh result, the same
array object back, in place when out is the input, and a clear error for an array they cannot write."""
import numpy as np
import pytest

import deformkit as dk


def grid():
    rng = np.random.default_rng(3)
    return (rng.uniform(0, 1, (5000, 3)) * [4, 1, 0.2]).astype(np.float32)


def bound_deformers(points):
    origin, axis, up = (np.array(v, np.float32) for v in ((0, 0.5, 0), (1, 0, 0), (0, 0, 1)))
    taper = dk.Taper(points, origin, axis, np.array([0, 2, 4], np.float32), np.array([1, 0.5, 1.5], np.float32))
    twist = dk.Twist(points, origin, axis, np.array([0, 4], np.float32), np.array([0, 2], np.float32))
    bend = dk.Bend(points, origin, axis, up, 0.8, 2.0, 0.5, 3.5)
    ffd = dk.Ffd(np.array([-0.1, -0.1, -0.5], np.float32), np.diag([4.2, 1.2, 1.2]).astype(np.float32),
                 np.array([3, 3, 3], np.int32))
    ffd.bind(points)
    source = ffd.source_points
    ffd.set_target(source + 0.1 * np.stack([np.sin(source[..., 1] * 3), np.cos(source[..., 0]), source[..., 0] * 0.1],
                                           -1).astype(np.float32))
    return {"Taper": taper, "Twist": twist, "Bend": bend, "Ffd": ffd}


@pytest.mark.parametrize("envelope", [1.0, 0.6])
def test_out_gives_the_fresh_result_in_the_callers_array(envelope):
    points = grid()
    weights = np.linspace(0, 1, len(points), dtype=np.float32)
    for name, deformer in bound_deformers(points).items():
        fresh = deformer.evaluate(points, weights=weights, envelope=envelope)
        assert np.abs(fresh - points).max() > 1e-3, name
        out = np.empty_like(points)
        got = deformer.evaluate(points, weights=weights, envelope=envelope, out=out)
        assert got is out or np.shares_memory(got, out), name
        assert out.tobytes() == fresh.tobytes(), name
        # out is the input: deformed in place, the same values.
        inplace = points.copy()
        deformer.evaluate(inplace, weights=weights, envelope=envelope, out=inplace)
        assert inplace.tobytes() == fresh.tobytes(), name


def test_an_out_array_that_cannot_be_written_is_refused():
    points = grid()
    for name, deformer in bound_deformers(points).items():
        for bad, what in ((np.empty((10, 3), np.float32), r"out: has shape \(10, 3\)"),
                          (np.empty_like(points, dtype=np.float64), "out: is not a C-contiguous float32 array"),
                          (np.empty((3, len(points)), np.float32).T, "out: is not a C-contiguous float32 array")):
            with pytest.raises(dk.Error, match=what):
                deformer.evaluate(points, out=bad)
        frozen = np.empty_like(points)
        frozen.setflags(write=False)
        with pytest.raises(dk.Error, match="read-only"):
            deformer.evaluate(points, out=frozen)
