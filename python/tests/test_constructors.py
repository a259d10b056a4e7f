"""Every constructor: accepted input forms, properties, and bad input raising CaromError or
TypeError with the bad value in the message."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import carom

BAD_SIZES = [(-1.0, "-1"), (0.0, "0"), (math.nan, "nan"), (math.inf, "inf"), (-math.inf, "-inf")]


@pytest.mark.parametrize("value, shown", BAD_SIZES)
def test_sphere_bad_radius(value: float, shown: str) -> None:
    with pytest.raises(carom.CaromError, match="radius") as e:
        carom.Sphere(value)
    assert shown in str(e.value).lower()


@pytest.mark.parametrize("cls", [carom.Capsule, carom.Cylinder, carom.Cone])
@pytest.mark.parametrize("value, shown", BAD_SIZES)
def test_radius_half_height_bad_values(cls: type, value: float, shown: str) -> None:
    with pytest.raises(carom.CaromError, match="radius") as e:
        cls(value, 1.0)
    assert shown in str(e.value).lower()
    with pytest.raises(carom.CaromError, match="half_height") as e:
        cls(1.0, value)
    assert shown in str(e.value).lower()


@pytest.mark.parametrize("cls", [carom.Sphere, carom.Capsule, carom.Cylinder, carom.Cone])
def test_scalar_wrong_types(cls: type) -> None:
    args = (1.0,) if cls is carom.Sphere else (1.0, 1.0)
    for bad in ["1.0", None, [1.0], object()]:
        with pytest.raises(TypeError, match="radius"):
            cls(bad, *args[1:])


def test_out_of_precision_range_is_named() -> None:
    if carom.REAL_BITS == 32:
        with pytest.raises(carom.CaromError, match=r"radius = 1e\+?300"):
            carom.Sphere(1e300)
        with pytest.raises(carom.CaromError, match="radius = 1e-300"):
            carom.Sphere(1e-300)


def test_scalar_like_inputs_accepted() -> None:
    assert carom.Sphere(2).radius == 2.0
    assert carom.Sphere(np.float32(0.5)).radius == 0.5
    assert carom.Sphere(np.int64(3)).radius == 3.0
    assert carom.Capsule(np.float64(0.25), 1).half_height == 1.0


@pytest.mark.parametrize(
    "he",
    [[0.5, 1.0, 2.0], (0.5, 1, 2), np.array([0.5, 1.0, 2.0], dtype=np.float32), np.array([1, 2, 3])],
)
def test_box_accepts_array_likes(he: object) -> None:
    b = carom.Box(he)
    np.testing.assert_array_equal(b.half_extents, np.asarray(he, dtype=np.float64))
    assert b.half_extents.dtype == np.float64


@pytest.mark.parametrize(
    "he, message",
    [
        ([1.0, -2.0, 1.0], r"half_extents.*-2"),
        ([1.0, 0.0, 1.0], r"half_extents.*0\.0"),
        ([1.0, math.nan, 1.0], r"(?i)half_extents.*nan"),
        ([math.inf, 1.0, 1.0], r"(?i)half_extents.*inf"),
        ([1.0, 1.0], r"half_extents must have shape \(3,\), got \(2,\)"),
        ([[1.0, 1.0, 1.0]], r"half_extents must have shape \(3,\), got \(1, 3\)"),
        (1.0, r"half_extents must have shape \(3,\), got \(\)"),
    ],
)
def test_box_bad_values(he: object, message: str) -> None:
    with pytest.raises(carom.CaromError, match=message):
        carom.Box(he)


@pytest.mark.parametrize("he", ["abc", None, ["a", "b", "c"], [1 + 1j, 1, 1], {"a": 1}])
def test_box_wrong_types(he: object) -> None:
    with pytest.raises(TypeError, match="half_extents"):
        carom.Box(he)


CUBE = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)


def test_convex_hull_properties() -> None:
    rng = np.random.default_rng(0)
    pts = np.vstack([CUBE, rng.uniform(-0.9, 0.9, size=(10, 3)), CUBE[:3]])  # interior + duplicates
    h = carom.ConvexHull(pts)
    assert len(h.vertices) == 8
    assert sorted(map(tuple, h.vertices)) == sorted(map(tuple, CUBE))
    assert len(h.faces) == 6 and all(len(f) == 4 and f.dtype == np.int64 for f in h.faces)
    assert h.triangles.shape == (12, 3)
    assert h.volume == pytest.approx(8.0, rel=1e-5)
    assert h.margin == 0.0
    # Faces are counter-clockwise seen from outside: the Newell normal points away from 0.
    for f in h.faces:
        poly = h.vertices[f]
        n = np.cross(poly[1] - poly[0], poly[2] - poly[0])
        assert n @ poly.mean(axis=0) > 0


@pytest.mark.parametrize(
    "points, message",
    [
        (CUBE[:3], r"points = 3"),
        (np.zeros((0, 3)), r"points = 0"),
        ([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [0.5, 0.3, 0]], r"coplanar"),
        ([[0, 0, 0], [1, 1, 1], [2, 2, 2], [3, 3, 3]], r"coplanar|collinear"),
        (np.ones((5, 3)), r"coplanar|collinear|coincide"),
        (np.vstack([CUBE, [[0, math.nan, 0]]]), r"(?i)points\[8\].*nan"),
        (np.vstack([CUBE, [[math.inf, 0, 0]]]), r"(?i)points\[8\].*inf"),
        (np.zeros((4, 2)), r"points must have shape \(N, 3\), got \(4, 2\)"),
        ([1.0, 2.0, 3.0], r"points must have shape \(N, 3\), got \(3,\)"),
    ],
)
def test_convex_hull_bad_input(points: object, message: str) -> None:
    with pytest.raises(carom.CaromError, match=message):
        carom.ConvexHull(points)


def test_convex_hull_wrong_type() -> None:
    with pytest.raises(TypeError, match="points"):
        carom.ConvexHull("cube")


def test_triangle() -> None:
    t = carom.Triangle([0, 0, 0], (1, 0, 0), np.array([0, 1, 0], dtype=np.float32))
    np.testing.assert_array_equal(t.vertices, [[0, 0, 0], [1, 0, 0], [0, 1, 0]])
    np.testing.assert_allclose(t.normal, [0, 0, 1])
    assert t.volume == 0.0 and t.mass_properties()[0] == 0.0
    assert carom.Triangle([0, 0, 0], [1, 1, 1], [2, 2, 2]).normal is None
    with pytest.raises(carom.CaromError, match=r"(?i)invalid b = .*nan"):
        carom.Triangle([0, 0, 0], [math.nan, 0, 0], [0, 1, 0])
    with pytest.raises(carom.CaromError, match=r"c must have shape \(3,\), got \(2,\)"):
        carom.Triangle([0, 0, 0], [1, 0, 0], [0, 1])
    with pytest.raises(TypeError, match="a must"):
        carom.Triangle(None, [1, 0, 0], [0, 1, 0])


def test_trimesh() -> None:
    verts = CUBE
    tris = carom.ConvexHull(CUBE).triangles
    hull = carom.ConvexHull(CUBE)
    m = carom.TriMesh(hull.vertices, tris)
    assert m.indices.dtype == np.int64 and m.indices.shape == (12, 3)
    assert m.volume == pytest.approx(8.0, rel=1e-5)
    assert not m.is_convex
    np.testing.assert_array_equal(carom.TriMesh(verts, tris.astype(np.uint32)).indices, tris)
    np.testing.assert_array_equal(carom.TriMesh(verts.tolist(), tris.tolist()).vertices, verts)


@pytest.mark.parametrize(
    "vertices, indices, error, message",
    [
        (CUBE, [[0, 1, 8]], carom.CaromError, r"indices\[0\]\[2\] = 8.*out of range"),
        (CUBE, [[0, 1, 2], [0, -1, 2]], carom.CaromError, r"indices\[1\]\[1\] = -1"),
        (CUBE, [[0, 1, 2**33]], carom.CaromError, r"indices\[0\]\[2\] = 8589934592"),
        (CUBE, np.zeros((0, 3), dtype=int), carom.CaromError, r"indices = 0"),
        (CUBE, [[0, 1]], carom.CaromError, r"indices must have shape \(M, 3\), got \(1, 2\)"),
        (np.vstack([CUBE, [[math.nan, 0, 0]]]), [[0, 1, 2]], carom.CaromError, r"(?i)vertices\[8\].*nan"),
        (np.zeros((3, 2)), [[0, 1, 2]], carom.CaromError, r"vertices must have shape \(N, 3\), got \(3, 2\)"),
        (CUBE, [[0.0, 1.0, 2.0]], TypeError, r"indices must contain integers"),
        (CUBE, "abc", TypeError, r"indices"),
        ("abc", [[0, 1, 2]], TypeError, r"vertices"),
    ],
)
def test_trimesh_bad_input(vertices: object, indices: object, error: type, message: str) -> None:
    with pytest.raises(error, match=message):
        carom.TriMesh(vertices, indices)


def test_plane() -> None:
    p = carom.Plane([0, 2, 0], 1.5)
    np.testing.assert_array_equal(p.normal, [0, 1, 0])
    assert p.offset == 1.5 and p.volume == 0.0 and p.kind == "plane"
    lo, hi = p.local_aabb
    assert hi[1] == 1.5 and lo[1] < -1e10
    assert carom.Plane([1, 0, 0]).offset == 0.0
    with pytest.raises(carom.CaromError, match=r"normal.*non-zero"):
        carom.Plane([0, 0, 0], 1.0)
    with pytest.raises(carom.CaromError, match=r"(?i)normal.*nan"):
        carom.Plane([0, math.nan, 1], 1.0)
    with pytest.raises(carom.CaromError, match=r"(?i)offset = inf"):
        carom.Plane([0, 1, 0], math.inf)
    with pytest.raises(TypeError, match="offset"):
        carom.Plane([0, 1, 0], "1")


def test_compound() -> None:
    s = carom.Sphere(1.0)
    b = carom.Box([1, 1, 1])
    c = carom.Compound([(s, carom.Pose([2, 0, 0])), [b, [0, 0, 0, 0, 0, 0, 1]], (s, None), b])
    assert c.kind == "compound" and not c.is_convex
    kids = c.children
    assert len(kids) == 4
    assert kids[0][0] == s and isinstance(kids[0][0], carom.Sphere)
    assert kids[0][1] == carom.Pose([2, 0, 0])
    assert kids[3][1] == carom.Pose.identity()
    lo, hi = c.aabb()
    np.testing.assert_allclose(lo, [-1, -1, -1])
    np.testing.assert_allclose(hi, [3, 1, 1])
    nested = carom.Compound([(c, carom.Pose([0, 5, 0]))])
    np.testing.assert_allclose(nested.aabb()[1], [3, 6, 1])


@pytest.mark.parametrize(
    "children, error, message",
    [
        ([], carom.CaromError, r"children = 0"),
        ([(carom.Plane([0, 1, 0], 0), None)], carom.CaromError, r"children\[0\] is a plane"),
        ([(carom.Sphere(1), [0, 0, 0, 0, 0, 0, 2])], carom.CaromError, r"children\[0\]\.pose\.rotation.*length is 2"),
        ([(carom.Sphere(1), [0, 0, 0])], carom.CaromError, r"children\[0\]\.pose must be a carom.Pose or an array of shape \(7,\)"),
        ([(1.0, None)], TypeError, r"children\[0\]\[0\] must be a carom.Shape, got float"),
        ([(carom.Sphere(1), None, None)], TypeError, r"children\[0\] must be a \(shape, pose\) pair"),
        ([42], TypeError, r"children\[0\] must be a \(shape, pose\) pair, got int"),
        (5, TypeError, r"children must be a sequence"),
    ],
)
def test_compound_bad_input(children: object, error: type, message: str) -> None:
    with pytest.raises(error, match=message):
        carom.Compound(children)


def test_scaled() -> None:
    b = carom.Box([1, 2, 3])
    s = b.scaled([2, 1, 0.5])
    assert isinstance(s, carom.Scaled) and s.kind == "scaled"
    assert s.inner == b
    np.testing.assert_array_equal(s.scale, [2, 1, 0.5])
    np.testing.assert_allclose(s.local_aabb[1], [2, 2, 1.5])
    assert s.volume == pytest.approx(b.volume)
    np.testing.assert_array_equal(b.scaled(2).scale, [2, 2, 2])
    # Scaling a scaled shape multiplies the factors.
    np.testing.assert_array_equal(s.scaled([0.5, 3, 2]).scale, [1, 3, 1])
    assert s.scaled([0.5, 3, 2]).inner == b
    assert carom.Scaled(b, [2, 1, 0.5]) == s
    with pytest.raises(carom.CaromError, match=r"scale.*non-zero"):
        b.scaled([1, 0, 1])
    with pytest.raises(carom.CaromError, match=r"(?i)scale.*nan"):
        b.scaled([1, math.nan, 1])
    with pytest.raises(carom.CaromError, match=r"factors must be a scalar or have shape \(3,\), got \(2,\)"):
        b.scaled([1, 2])
    with pytest.raises(carom.CaromError, match="only convex shapes can be scaled, not a plane"):
        carom.Plane([0, 1, 0], 0).scaled(2)
    with pytest.raises(TypeError, match="factors"):
        b.scaled("big")
    with pytest.raises(TypeError, match="shape must be a carom.Shape"):
        carom.Scaled("box", 2)


def test_shape_base_class_and_kinds() -> None:
    shapes = {
        "sphere": carom.Sphere(1),
        "box": carom.Box([1, 1, 1]),
        "capsule": carom.Capsule(1, 1),
        "cylinder": carom.Cylinder(1, 1),
        "cone": carom.Cone(1, 1),
        "convex_hull": carom.ConvexHull(CUBE),
        "triangle": carom.Triangle([0, 0, 0], [1, 0, 0], [0, 1, 0]),
        "plane": carom.Plane([0, 1, 0], 0),
        "trimesh": carom.TriMesh(CUBE, [[0, 1, 2]]),
        "compound": carom.Compound([carom.Sphere(1)]),
        "scaled": carom.Sphere(1).scaled(2),
    }
    for kind, s in shapes.items():
        assert isinstance(s, carom.Shape)
        assert s.kind == kind
        assert type(s).__doc__
    with pytest.raises(TypeError):
        carom.Shape()


def test_axis_is_y() -> None:
    for s in [carom.Capsule(0.5, 2.0), carom.Cylinder(0.5, 2.0), carom.Cone(0.5, 2.0)]:
        lo, hi = s.local_aabb
        assert hi[1] > hi[0] and hi[1] > hi[2]
    np.testing.assert_allclose(carom.Cone(0.5, 2.0).support([0, 1, 0]), [0, 2, 0])


def test_repr() -> None:
    assert repr(carom.Sphere(0.1)) == "Sphere(radius=0.1)"
    assert repr(carom.Box([0.5, 1, 2])) == "Box(half_extents=[0.5, 1.0, 2.0])"
    assert repr(carom.Capsule(0.5, 1)) == "Capsule(radius=0.5, half_height=1.0)"
    assert repr(carom.Cone(0.5, 1)) == "Cone(radius=0.5, half_height=1.0)"
    assert repr(carom.Plane([0, 1, 0], 2)) == "Plane(normal=[0.0, 1.0, 0.0], offset=2.0)"
    assert repr(carom.ConvexHull(CUBE)) == "ConvexHull(<8 vertices, 6 faces>)"
    assert repr(carom.Sphere(1).scaled([1, 2, 3])) == "Sphere(radius=1.0).scaled([1.0, 2.0, 3.0])"
    assert "2 children: Sphere, Box" in repr(carom.Compound([carom.Sphere(1), carom.Box([1, 1, 1])]))
    # Parametric reprs evaluate back to an equal shape.
    for s in [carom.Sphere(0.1), carom.Box([0.5, 1, 2]), carom.Cylinder(0.3, 0.7), carom.Triangle([0, 0, 0], [1, 0, 0], [0, 1, 0])]:
        assert eval(repr(s), {**vars(carom)}) == s


@settings(max_examples=200, deadline=None)
@given(x=st.floats(allow_nan=True, allow_infinity=True, allow_subnormal=True))
def test_any_float_radius_is_accepted_or_named(x: float) -> None:
    try:
        s = carom.Sphere(x)
    except carom.CaromError as e:
        assert "radius" in str(e)
        assert not 1e-30 < x < 1e30
        return
    assert x > 0 and s.radius == pytest.approx(x, rel=1e-6)
    assert s.volume == pytest.approx(4 / 3 * math.pi * s.radius**3, rel=1e-5) or math.isinf(s.volume)


@settings(max_examples=100, deadline=None)
@given(
    v=st.lists(st.floats(allow_nan=True, allow_infinity=True), min_size=3, max_size=3),
)
def test_any_half_extents_are_accepted_or_named(v: list[float]) -> None:
    try:
        b = carom.Box(v)
    except carom.CaromError as e:
        assert "half_extents" in str(e)
        assert not all(1e-30 < x < 1e30 for x in v)
        return
    assert all(x > 0 for x in v)
    np.testing.assert_allclose(b.half_extents, v, rtol=1e-6)
