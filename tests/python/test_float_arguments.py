"""Float arguments take numbers only: an array of bool, strings or complex numbers, a list of strings, and
float64 values beyond float32's range (numpy's cast would give 1.0 for True, parse "1", and give inf for
1e39) are refused with deformkit.InvalidInput naming the function and the argument; float64 and integer
arrays within range give float32's results bit for bit."""
import numpy as np
import pytest

import deformkit as dk

pytestmark = pytest.mark.filterwarnings("ignore:overflow encountered in cast:RuntimeWarning")

AXIS = dict(axis_origin=(0, 0, 0), axis_dir=(0, 1, 0), z_samples=[0, 1], value_samples=[1, 2])


def grid_mesh():
    grid = dk.make_grid(6, 6)
    return np.asarray(grid.points, np.float32), np.asarray(grid.face_counts), np.asarray(grid.face_indices)


def refused(call, match):
    with pytest.raises(dk.InvalidInput, match=match):
        call()


@pytest.mark.parametrize("bad, what", [
    (lambda p: p > 0.5, r"is an array of bool values"),
    (lambda p: p.astype(str), r"is an array of <U\d+ values"),
    (lambda p: p.astype(np.complex64), r"is an array of complex64 values"),
    (lambda p: [["1", "2", "3"]] * len(p), r"is a list that is not numeric"),
    (lambda p: np.where(np.arange(p.size).reshape(p.shape) == 7, 1e39, p.astype(np.float64)),
     r"holds 1e\+39 at flat index 7, beyond float32's range"),
])
def test_non_numbers_are_refused_naming_the_argument(bad, what):
    points, counts, indices = grid_mesh()
    refused(lambda: dk.taper(bad(points), **AXIS), "taper: points: " + what)
    refused(lambda: dk.taper(points, **AXIS, weights=np.asarray(bad(points)).ravel()[:len(points)]),
            "taper: weights: (is an array of|holds 1e\\+39 at index 7)")
    refused(lambda: dk.ffd(bad(points), (0, 0, 0), np.eye(3), (3, 3, 3),
                           np.zeros((4, 4, 4, 3), np.float32)), "ffd: points: " + what)
    refused(lambda: dk.Mesh(bad(points), counts, indices), "points: " + what)


@pytest.mark.parametrize("bad, what", [
    (np.array([True, False, False]), r"is an array of bool values"),
    (np.array([1 + 2j, 0, 0]), r"is an array of complex128 values"),
    (["0.1", "0", "0"], r"is a list that is not numeric"),
    ([None, 0, 0], r"is a list that is not numeric"),
])
def test_double_arguments_take_numbers_only(bad, what):
    # Slide displacements and stack parameters are read in double: numpy's cast read "0.1" as 0.1, True as
    # 1, dropped an imaginary part and None became NaN.
    points, counts, indices = grid_mesh()
    refused(lambda: dk.slide(points, counts, indices, 20, bad, 0.3), "slide: displacement: " + what)
    slider = dk.Slider(points, counts, indices, handle=20, radius=0.3)
    refused(lambda: slider.evaluate(bad), "Slider.evaluate: displacement: " + what)
    stack = dk.DeformerStack()
    stack.set_rest(dk.Mesh(points, counts, indices))
    stack.add("twist")
    refused(lambda: stack.set(0, "handleOrigin", bad), "parameter 'handleOrigin': " + what)
    for flag in (True, np.bool_(True)):
        refused(lambda: stack.set(0, "envelope", flag), "parameter 'envelope': is an? (bool|bool_) ")
    # The same values as numbers are taken, and give the float32 path's result.
    moved = slider.evaluate(np.array([0.1, 0, 0])).points
    assert np.array_equal(moved, slider.evaluate([0.1, 0, 0]).points)
    stack.set(0, "handleOrigin", np.array([0, 1, 0], np.int64))
    assert list(stack.get(0, "handleOrigin")) == [0, 1, 0]
    refused(lambda: stack.evaluate(points > 0), "DeformerStack.evaluate: points: is an array of bool values")


def test_profile_samples_beyond_float_range_are_named():
    points, _, _ = grid_mesh()
    refused(lambda: dk.taper(points, axis_origin=(0, 0, 0), axis_dir=(0, 1, 0), z_samples=[0, 1e39],
                             value_samples=[1, 2]), r"taper: z_samples: holds 1e\+39 at index 1")
    refused(lambda: dk.taper(points, axis_origin=(0, 0, 0), axis_dir=(0, 1, 0), z_samples=[0, 1],
                             value_samples=[True, False]), r"taper: value_samples: is a list that is not numeric")


def test_float64_and_integers_within_range_give_float32_results():
    points, _, _ = grid_mesh()
    want = dk.taper(points, **AXIS)
    for given in (points.astype(np.float64), points.tolist(), points[::1].copy(order="F")):
        np.testing.assert_array_equal(dk.taper(given, **AXIS), want)
    whole = np.round(points * 4).astype(np.int64)
    np.testing.assert_array_equal(dk.taper(whole, **AXIS), dk.taper(whole.astype(np.float32), **AXIS))
    # A float64 inf given as such stays the input's own value, named by the core as not finite.
    bad = points.astype(np.float64)
    bad[3, 1] = np.inf
    refused(lambda: dk.taper(bad, **AXIS), r"point 3")
