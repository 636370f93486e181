"""Every public function and class of the deformkit module called with random arguments (fixed seed): wrong
types, wrong shapes, NaN and infinite values, empty arrays, huge integers, paths that do not exist. Whatever it
is given, a call returns or raises deformkit.Error (a message naming the function and argument), TypeError
(pybind11's list of the accepted signatures) or another standard Python error of a value; the process never
dies, and no pybind11 cast error ("Unable to cast Python instance") reaches the caller."""
import math
import random

import numpy as np
import pytest

import deformkit as dk

# numpy warns when a huge Python int or a NaN is cast to an int array; such values are among those tried.
pytestmark = [pytest.mark.filterwarnings("ignore::DeprecationWarning"),
              pytest.mark.filterwarnings("ignore:invalid value encountered in cast:RuntimeWarning"),
              pytest.mark.filterwarnings("ignore:overflow encountered in cast:RuntimeWarning")]

CALLS = 1000  # per callable: the whole module in about 10 seconds

# Errors a caller may see besides deformkit.Error: pybind11's signature mismatch (TypeError) and Python's own
# errors of a value.
ALLOWED = (dk.Error, TypeError, ValueError, OverflowError, IndexError, KeyError, AttributeError)

def argument_pool():
    grid = dk.make_grid(4, 4)
    points = np.asarray(grid.points, dtype=np.float32)
    return [
        None, 0, 1, -1, 3, 2**31, 2**63 - 1, -2**31, 0.0, -0.0, 1.5, math.nan, math.inf, -math.inf, 1e-45, 1e38,
        "", "x", "a.obj", "a.pc2", "1001", "<UDIM>", "tex.<UDIM>.exr", "missing/folder/f.exr",
        [], [[]], [0], [1, 2, 3], [[0, 0, 0]], (0, 0, 0), {}, {"a": 1}, {"data": 3}, True, False,
        np.zeros((0, 3), np.float32), np.zeros((5, 2), np.float32), np.full((4, 3), np.nan, np.float32),
        np.zeros((3, 3), np.int64), np.zeros((2, 2, 2), np.float32), np.zeros(7, np.float32),
        np.zeros((3, 3), np.float64), np.ones((16, 16), np.float32), np.ones((16, 16, 4), np.float32),
        np.zeros((16, 16, 0), np.float32), np.full((8, 8), np.inf, np.float32),
        np.ones((4, 3), bool), np.full((4, 3), "1"), np.full((4, 3), 1e39), [[True, False, True]], ["1", "2"],
        np.zeros((4, 3), np.float32)[:, ::2], points[::-1], points, points[:3], grid, b"bytes", object(),
    ]


KEYWORDS = ["points", "texels", "tile", "preset", "iterations", "sweeps", "frame", "path", "weights", "axis",
            "angle", "rate", "mesh", "rest", "deformed", "rigidity", "mask", "threads", "options", "resolution",
            "start", "fps", "frames", "out", "falloff", "radius", "size", "ptex", "logs", "page"]


def public_callables():
    return sorted(name for name in dir(dk)
                  if not name.startswith("_") and callable(getattr(dk, name))
                  and not (isinstance(getattr(dk, name), type) and issubclass(getattr(dk, name), BaseException)))


@pytest.mark.parametrize("name", public_callables())
def test_random_arguments_return_or_raise_a_named_error(name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # writers given relative paths write here
    pool = argument_pool()
    rng = random.Random(name)  # a fixed seed per callable
    function = getattr(dk, name)
    for call in range(CALLS):
        args = [rng.choice(pool) for _ in range(rng.randint(0, 4))]
        kwargs = {rng.choice(KEYWORDS): rng.choice(pool) for _ in range(rng.randint(0, 2))}
        try:
            result = function(*args, **kwargs)
            if hasattr(result, "evaluate"):  # a bound object: evaluated on the grid's points too
                result.evaluate(pool[-6])
        except ALLOWED as error:
            if isinstance(error, RuntimeError) and not isinstance(error, dk.Error):
                pytest.fail(f"call {call}: {name}(*{args!r}, **{kwargs!r}) raised {error!r}")
            assert "Unable to cast" not in str(error), f"call {call}: {name}: {error}"
