"""Pose algebra against numpy rotation matrices built from the quaternion formula."""

from __future__ import annotations

import copy
import math
import pickle

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import carom
from conftest import quat_matrix, random_quat

seeds = st.integers(0, 2**32 - 1)


def random_pose(rng: np.random.Generator) -> tuple[carom.Pose, np.ndarray]:
    q = random_quat(rng)
    t = rng.uniform(-10, 10, size=3)
    m = np.eye(4)
    m[:3, :3] = quat_matrix(q)
    m[:3, 3] = t
    return carom.Pose(t, q), m


def test_defaults_and_identity() -> None:
    p = carom.Pose()
    np.testing.assert_array_equal(p.position, [0, 0, 0])
    np.testing.assert_array_equal(p.rotation, [0, 0, 0, 1])
    assert p == carom.Pose.identity() == carom.Pose(position=(0, 0, 0), rotation=(0, 0, 0, 1))
    np.testing.assert_array_equal(p.matrix(), np.eye(4))
    assert p.position.dtype == np.float64 and p.rotation.dtype == np.float64


@settings(max_examples=50, deadline=None)
@given(seed=seeds)
def test_matrix_and_transform_points(seed: int) -> None:
    rng = np.random.default_rng(seed)
    pose, m = random_pose(rng)
    np.testing.assert_allclose(pose.matrix(), m, atol=1e-12)
    pts = rng.normal(size=(7, 3))
    expected = pts @ m[:3, :3].T + m[:3, 3]
    np.testing.assert_allclose(pose.transform_points(pts), expected, atol=1e-12)
    np.testing.assert_allclose(pose.transform_points(pts[0]), expected[0], atol=1e-12)
    np.testing.assert_allclose(pose.transform_vectors(pts), pts @ m[:3, :3].T, atol=1e-12)
    assert pose.transform_points(pts.tolist()).shape == (7, 3)


@settings(max_examples=50, deadline=None)
@given(seed=seeds)
def test_composition_and_inverse(seed: int) -> None:
    rng = np.random.default_rng(seed)
    a, ma = random_pose(rng)
    b, mb = random_pose(rng)
    np.testing.assert_allclose((a * b).matrix(), ma @ mb, atol=1e-12)
    np.testing.assert_allclose(a.inverse().matrix(), np.linalg.inv(ma), atol=1e-12)
    np.testing.assert_allclose((a * a.inverse()).matrix(), np.eye(4), atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm((a * b).rotation), 1.0, atol=1e-15)


@settings(max_examples=30, deadline=None)
@given(seed=seeds)
def test_array_round_trip_is_exact(seed: int) -> None:
    rng = np.random.default_rng(seed)
    pose, _ = random_pose(rng)
    a = pose.to_array()
    assert a.shape == (7,) and a.dtype == np.float64
    back = carom.Pose.from_array(a)
    assert back == pose
    np.testing.assert_array_equal(back.to_array(), a)
    assert pickle.loads(pickle.dumps(pose)) == pose
    assert copy.deepcopy(pose) == pose
    assert eval(repr(pose), {"Pose": carom.Pose}) == pose
    assert hash(carom.Pose.from_array(a)) == hash(pose)


def test_equality_and_hash() -> None:
    a = carom.Pose([1, 2, 3], [0, 0, 0, 1])
    assert a == carom.Pose([1.0, 2.0, 3.0])
    assert a != carom.Pose([1, 2, 3.5])
    assert a != "pose" and a != [1, 2, 3, 0, 0, 0, 1]
    assert len({a, carom.Pose([1, 2, 3]), carom.Pose()}) == 2
    assert carom.Pose([0.0, 0, 0]) == carom.Pose([-0.0, 0, 0])
    assert hash(carom.Pose([0.0, 0, 0])) == hash(carom.Pose([-0.0, 0, 0]))


def test_input_forms() -> None:
    q = np.array([0, 0, np.sin(0.3), np.cos(0.3)], dtype=np.float32)
    p = carom.Pose(np.array([1, 2, 3], dtype=np.int32), q)
    np.testing.assert_allclose(p.rotation, q.astype(np.float64) / np.linalg.norm(q.astype(np.float64)))
    assert carom.Pose((1, 2, 3), (0, 0, 0, 1)) == carom.Pose([1, 2, 3])
    assert carom.Pose.from_array([1, 2, 3, 0, 0, 0, 1]) == carom.Pose([1, 2, 3])
    # Nearly unit quaternions are renormalised.
    np.testing.assert_allclose(np.linalg.norm(carom.Pose(rotation=[0, 0, 0, 1.0004]).rotation), 1.0)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"rotation": [0, 0, 0, 2]}, r"invalid rotation = \[0\.0, 0\.0, 0\.0, 2\.0\]: must be a unit quaternion.*length is 2"),
        ({"rotation": [0, 0, 0, 0]}, r"rotation.*length is 0"),
        ({"rotation": [0, math.nan, 0, 1]}, r"(?i)rotation = .*nan.*finite"),
        ({"position": [0, math.inf, 0]}, r"(?i)position = .*inf.*finite"),
        ({"position": [0, 0]}, r"position must have shape \(3,\), got \(2,\)"),
        ({"rotation": [0, 0, 1]}, r"rotation must have shape \(4,\), got \(3,\)"),
        ({"rotation": np.eye(3)}, r"rotation must have shape \(4,\), got \(3, 3\)"),
    ],
)
def test_bad_pose(kwargs: dict[str, object], message: str) -> None:
    with pytest.raises(carom.CaromError, match=message):
        carom.Pose(**kwargs)


def test_bad_pose_types_and_arrays() -> None:
    with pytest.raises(TypeError, match="position"):
        carom.Pose("origin")
    with pytest.raises(TypeError, match="rotation"):
        carom.Pose([0, 0, 0], ["a", "b", "c", "d"])
    with pytest.raises(carom.CaromError, match=r"array must have shape \(7,\), got \(6,\)"):
        carom.Pose.from_array(np.zeros(6))
    with pytest.raises(carom.CaromError, match=r"rotation.*length is 0"):
        carom.Pose.from_array(np.zeros(7))
    with pytest.raises(carom.CaromError, match=r"transform_points|points must have shape \(3,\) or \(N, 3\), got \(2, 2\)"):
        carom.Pose().transform_points(np.zeros((2, 2)))
    with pytest.raises(TypeError):
        carom.Pose() * 2  # type: ignore[operator]


def test_pose_arguments_of_queries() -> None:
    s = carom.Box([1, 2, 3])
    q = [0, 0, math.sin(math.pi / 4), math.cos(math.pi / 4)]  # 90 degrees about z
    as_pose = s.aabb(carom.Pose([1, 0, 0], q))
    as_array = s.aabb([1, 0, 0, *q])
    for a, b in zip(as_pose, as_array):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_allclose(as_pose[0], [-1, -1, -3], atol=1e-5)
    np.testing.assert_allclose(as_pose[1], [3, 1, 3], atol=1e-5)
    with pytest.raises(carom.CaromError, match=r"pose must be a carom.Pose or an array of shape \(7,\)"):
        s.support([1, 0, 0], pose=[1, 2, 3])
    with pytest.raises(carom.CaromError, match=r"pose\.rotation.*unit quaternion"):
        s.support([1, 0, 0], pose=[0, 0, 0, 0, 0, 0, 3])
    with pytest.raises(TypeError, match="pose"):
        s.aabb("here")
