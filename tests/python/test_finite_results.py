"""No deformer hands back a point that is not finite. Parameters within float range can still take a finite point
beyond it (an envelope of 1e38, a taper factor of 3e38, a lattice pulled 1e38 away); every warp, one-off and
bound, into a new array and in place, refuses such a result with an error naming the point, and a point that
comes in not finite is named as the input's."""
import numpy as np
import pytest

import deformkit as dk

ORIGIN = np.array([-0.5, 0.2, 1.0], np.float32)
AXES = np.array([[2.0, 0.3, -0.1], [0.2, 1.5, 0.2], [-0.3, 0.1, 1.8]], np.float32)  # rows X, Y, Z
OCTA = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], np.float32) * 3
OCTA_COUNTS = np.full(8, 3, np.int32)
OCTA_INDICES = np.array([0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5], np.int32)
AXIS = {"axis_origin": np.zeros(3, np.float32), "axis_dir": np.array([0, 0, 1], np.float32)}
Z = np.array([-1, 1], np.float32)


def inside_points(n=200):
    """Points inside the lattice (ORIGIN + [0, 1]^3 AXES), the octahedron cage and the wires' reach."""
    rng = np.random.default_rng(5)
    return (ORIGIN + rng.uniform(0.2, 0.8, (n, 3)) @ AXES).astype(np.float32)


def lattice(divisions, shift):
    i, j, k = np.meshgrid(*[np.arange(d + 1) for d in divisions], indexing="ij")
    st = np.stack([i / divisions[0], j / divisions[1], k / divisions[2]], -1)
    return (ORIGIN + st @ AXES + shift).astype(np.float32)


def one_offs(envelope, shift=4.0):
    """Each warp's one-off on inside_points(), a displacement of about `shift` scaled by `envelope`."""
    p = inside_points()
    d3, d2 = np.array([3, 3, 3], np.int32), np.array([2, 2, 2], np.int32)
    frames = np.broadcast_to(np.eye(3, dtype=np.float32), (4, 4, 4, 3, 3)).copy()
    ref = np.array([[-3, 0, 1], [0, 0, 1], [3, 0, 1]], np.float32)
    return {
        "taper": lambda: dk.taper(p, **AXIS, z_samples=Z, value_samples=np.array([1 + shift, 1 + shift], np.float32),
                                  envelope=envelope),
        "twist": lambda: dk.twist(p, **AXIS, z_samples=Z, value_samples=np.array([1, 1], np.float32) * shift,
                                  envelope=envelope),
        "bend": lambda: dk.bend(p, **AXIS, up_dir=np.array([0, 1, 0], np.float32), rate=shift, centre=0.0, lo=-1.0,
                                hi=1.0, envelope=envelope),
        "ffd (Bernstein, 4x4x4, unbound)": lambda: dk.ffd(p, ORIGIN, AXES, d3, lattice(d3, shift), envelope=envelope),
        "ffd (B-spline)": lambda: dk.ffd(p, ORIGIN, AXES, d3, lattice(d3, shift), basis="bspline", envelope=envelope),
        "ffd (3x3x3, per point)": lambda: dk.ffd(p, ORIGIN, AXES, d2, lattice(d2, shift), envelope=envelope),
        "ffd_frames": lambda: dk.ffd_frames(p, ORIGIN, AXES, d3, lattice(d3, shift), frames, envelope=envelope),
        "mesh_warp": lambda: dk.mesh_warp(p, OCTA, OCTA_COUNTS, OCTA_INDICES, OCTA + shift, envelope=envelope),
        "wires": lambda: dk.wires(p, [ref], [ref + shift], radius=50.0, envelope=envelope),
    }


@pytest.mark.parametrize("name", list(one_offs(1.0)))
def test_one_offs_refuse_a_result_beyond_float_range(name):
    # Within range: the same call gives finite points, moved.
    fine = one_offs(0.5)[name]()
    assert np.isfinite(fine).all() and np.abs(fine - inside_points()).max() > 1e-3, name
    for envelope in (3e38, -3e38):
        # The warps of the engine and the wires deform a copy in place: their message gives the result alone.
        with pytest.raises(dk.InvalidInput, match=r"point \d+: is (deformed from \(.*\) to \(.*inf|\(.*inf.*\) once "
                                                  r"deformed).*float range"):
            one_offs(envelope)[name]()


def test_a_parameter_alone_can_take_a_point_beyond_float_range():
    # A taper factor of 3e38 at points about 1.5 from the axis: 4.5e38, with the envelope at 1.
    with pytest.raises(dk.InvalidInput, match=r"taper: point 0: is deformed from .* to .*inf.*float range"):
        one_offs(1.0, shift=3e38)["taper"]()


def bound_deformers(points):
    origin, axis, up = (np.array(v, np.float32) for v in ((0, 0, 0), (0, 0, 1), (0, 1, 0)))
    deformers = {
        "Taper": dk.Taper(points, origin, axis, Z, np.array([5, 5], np.float32)),
        "Twist": dk.Twist(points, origin, axis, Z, np.array([1, 1], np.float32)),
        "Bend": dk.Bend(points, origin, axis, up, 1.0, 0.0, -1.0, 1.0),
    }
    for name, basis in (("Ffd", "bernstein"), ("Ffd (B-spline)", "bspline")):
        ffd = dk.Ffd(ORIGIN, AXES, np.array([3, 3, 3], np.int32), basis=basis)
        ffd.bind(points)
        ffd.set_target(lattice([3, 3, 3], 4.0))
        deformers[name] = ffd
    return deformers


def test_bound_deformers_refuse_it_into_a_new_array_and_in_place():
    points = inside_points()
    for name, deformer in bound_deformers(points).items():
        assert np.isfinite(deformer.evaluate(points, envelope=0.5)).all(), name
        with pytest.raises(dk.InvalidInput, match=r"point \d+: is deformed from .* to .*float range"):
            deformer.evaluate(points, envelope=3e38)
        # In place the input is overwritten as it is deformed: the message gives the result alone.
        inplace = points.copy()
        with pytest.raises(dk.InvalidInput, match=r"point \d+: is \(.*inf.*\) once deformed \(expected finite points"):
            deformer.evaluate(inplace, envelope=3e38, out=inplace)


def test_a_point_that_comes_in_not_finite_is_named_as_the_inputs():
    points = inside_points()
    bad = points.copy()
    bad[17] = [np.nan, 0, 0]
    bad[40] = [np.inf, 0, 0]
    for name, deformer in bound_deformers(points).items():
        with pytest.raises(dk.InvalidInput, match=r"point 17: is \(nan, 0, 0\)"):
            deformer.evaluate(bad)
        later = points.copy()
        later[40] = [np.inf, 0, 0]
        with pytest.raises(dk.InvalidInput, match=r"point 40: is \(inf, 0, 0\)"):
            deformer.evaluate(later)
