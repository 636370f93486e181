"""deformkit.warp_engine against a numpy implementation of the framework's Eq. (3)."""
import numpy as np
import pytest

import deformkit as dk


def reference(points, transforms, strengths, weights):
    out = points.astype(np.float64).copy()
    for u, p in enumerate(points.astype(np.float64)):
        w = weights[u].astype(np.float64)
        if w.sum() == 0:
            continue
        moved = np.einsum("nij,j->ni", transforms[:, :, :3].astype(np.float64), p) + transforms[:, :, 3]
        disp = strengths[u, :, None] * (moved - p)  # displacement method
        out[u] = p + (w[:, None] * disp).sum(0) / w.sum()
    return out


def test_matches_numpy_reference():
    rng = np.random.default_rng(11)
    n, k = 200, 5
    points = rng.normal(size=(n, 3)).astype(np.float32)
    transforms = np.tile(np.hstack([np.eye(3), np.zeros((3, 1))]), (k, 1, 1)).astype(np.float32)
    transforms += rng.normal(scale=0.2, size=transforms.shape).astype(np.float32)
    strengths = rng.uniform(0, 1, size=(n, k)).astype(np.float32)
    weights = rng.uniform(0, 2, size=(n, k)).astype(np.float32)
    weights[rng.uniform(size=(n, k)) < 0.4] = 0.0
    weights[7] = 0.0  # all-zero weights: identity
    out = dk.warp_engine(points, transforms, strengths, weights)
    assert out.shape == (n, 3) and out.dtype == np.float32
    np.testing.assert_allclose(out, reference(points, transforms, strengths, weights), atol=2e-5)
    assert np.array_equal(out[7], points[7])


def test_shape_errors_name_the_argument():
    with pytest.raises(dk.InvalidInput, match="strengths"):
        dk.warp_engine(np.zeros((4, 3), np.float32), np.zeros((2, 3, 4), np.float32),
                       np.zeros((4, 3), np.float32), np.zeros((4, 2), np.float32))


def test_non_finite_entries_are_refused_by_index():
    # Eq. (3) would turn each into NaN output, or a NaN weight into no weight at all (the point left put).
    points = np.array([[0, 0, 0], [1, 1, 1]], np.float32)
    transforms = np.zeros((2, 3, 4), np.float32)
    transforms[:, :, :3] = np.eye(3)
    ones = np.ones((2, 2), np.float32)
    for name, index, value in (("points", (0, 0), np.nan), ("transforms", (1, 2, 3), np.inf),
                               ("strengths", (0, 1), np.nan), ("weights", (1, 0), -np.inf)):
        args = dict(points=points.copy(), transforms=transforms.copy(), strengths=ones.copy(),
                    weights=ones.copy())
        args[name][index] = value
        text = f"warp_engine: {name}[{', '.join(map(str, index))}]: is {'nan' if np.isnan(value) else str(value)}"
        with pytest.raises(dk.InvalidInput, match=text.replace("[", r"\[").replace("]", r"\]")):
            dk.warp_engine(**args)
