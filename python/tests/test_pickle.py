"""Pickling and byte round trips are exact; corrupted bytes raise CaromError, never crash."""

from __future__ import annotations

import copy
import pickle

import numpy as np
import pytest

import carom

CUBE = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)


def all_shapes() -> list[carom.Shape]:
    rng = np.random.default_rng(3)
    hull = carom.ConvexHull(rng.normal(size=(12, 3)))
    return [
        carom.Sphere(0.1),
        carom.Box([0.1, 0.2, 0.3]),
        carom.Capsule(0.3, 0.7),
        carom.Cylinder(0.3, 0.7),
        carom.Cone(0.3, 0.7),
        hull,
        carom.Triangle([0, 0, 0], [1, 0.1, 0], [0.3, 1, -0.0]),
        carom.Plane([1, 2, 3], -0.5),
        carom.TriMesh(hull.vertices, hull.triangles),
        carom.Compound([(carom.Sphere(1), carom.Pose([1, 2, 3], [0, 0.6, 0, 0.8])), (hull, None)]),
        carom.Cone(0.3, 0.7).scaled([1, -2, 3]),
    ]


@pytest.mark.parametrize("shape", all_shapes(), ids=lambda s: s.kind)
def test_round_trips_exact(shape: carom.Shape) -> None:
    for back in [
        pickle.loads(pickle.dumps(shape)),
        pickle.loads(pickle.dumps(shape, protocol=2)),
        copy.deepcopy(shape),
        carom.Shape.from_bytes(shape.to_bytes()),
        type(shape).from_bytes(shape.to_bytes()),
    ]:
        assert type(back) is type(shape)
        assert back == shape and hash(back) == hash(shape)
        assert back.to_bytes() == shape.to_bytes()
        assert repr(back) == repr(shape)
        for a, b in zip(back.local_aabb, shape.local_aabb):
            np.testing.assert_array_equal(a, b)
        assert back.volume == shape.volume


def test_equality_is_by_value() -> None:
    assert carom.Sphere(1) == carom.Sphere(1.0)
    assert carom.Sphere(1) != carom.Sphere(2)
    assert carom.Sphere(1) != carom.Box([1, 1, 1])
    assert carom.Sphere(1) != 1.0
    assert len({carom.Sphere(1), carom.Sphere(1.0), carom.Box([1, 1, 1])}) == 2
    assert carom.Plane([0, 1, 0], 0.0) == carom.Plane([0, 1, 0], -0.0)
    assert hash(carom.Plane([0, 1, 0], 0.0)) == hash(carom.Plane([0, 1, 0], -0.0))


def test_corrupted_bytes_raise() -> None:
    good = carom.ConvexHull(CUBE).to_bytes()
    with pytest.raises(carom.CaromError, match="header"):
        carom.Shape.from_bytes(b"not a shape")
    with pytest.raises(carom.CaromError, match="cannot parse"):
        carom.Shape.from_bytes(good[: len(good) // 2])
    with pytest.raises(carom.CaromError, match="trailing"):
        carom.Shape.from_bytes(good + b"\x00")
    with pytest.raises(carom.CaromError, match="the bytes hold a Sphere, not a Box"):
        carom.Box.from_bytes(carom.Sphere(1).to_bytes())
    with pytest.raises(TypeError):
        carom.Shape.from_bytes("text")  # type: ignore[arg-type]
    # Every single-byte corruption either decodes to a valid shape or raises CaromError.
    rng = np.random.default_rng(0)
    for shape in all_shapes():
        data = bytearray(shape.to_bytes())
        for _ in range(40):
            i = int(rng.integers(11, len(data)))
            bad = bytearray(data)
            bad[i] = int(rng.integers(0, 256))
            try:
                s = carom.Shape.from_bytes(bytes(bad))
            except carom.CaromError:
                continue
            # A decoded shape is usable.
            s.aabb()
            s.volume
            if s.is_convex:
                s.support(np.eye(3))
