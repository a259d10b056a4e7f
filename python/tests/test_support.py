"""Support points against independent oracles: the support point maximises the dot product
over a dense sample of the surface, lies on the shape, and batch/single/world forms agree."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import carom
from conftest import TOL, inside_distance, quat_matrix, random_directions, random_quat, surface_samples


def scale_of(shape: carom.Shape) -> float:
    lo, hi = shape.local_aabb
    return float(np.max(np.abs(np.concatenate([lo, hi])))) + 1.0


def test_support_maximises_dot_over_surface(convex_shape: carom.Shape) -> None:
    rng = np.random.default_rng(1)
    dirs = random_directions(rng, 300)
    sup = convex_shape.support(dirs)
    assert sup.shape == dirs.shape and sup.dtype == np.float64
    samples = surface_samples(convex_shape)
    best = (dirs @ samples.T).max(axis=1)
    got = np.einsum("ij,ij->i", sup, dirs)
    tol = TOL * scale_of(convex_shape) * np.linalg.norm(dirs, axis=1)
    assert np.all(got >= best - tol)
    # The sampled maximum is close to the exact one (the sample is dense).
    if isinstance(convex_shape, (carom.Box, carom.ConvexHull, carom.Triangle)):
        assert np.all(got <= best + tol)


def test_support_point_lies_on_shape(convex_shape: carom.Shape) -> None:
    rng = np.random.default_rng(2)
    dirs = random_directions(rng, 200)
    sup = convex_shape.support(dirs)
    tol = TOL * scale_of(convex_shape)
    shape = convex_shape
    if isinstance(shape, carom.Scaled):
        inner = shape.inner
        if isinstance(inner, (carom.ConvexHull, carom.Triangle)):
            verts = inner.vertices * shape.scale
            assert np.min(np.linalg.norm(sup[:, None, :] - verts[None], axis=2), axis=1).max() < tol
            return
        outside, gap = inside_distance(inner, sup / shape.scale)
        assert outside.max() < tol and gap.max() < tol
    elif isinstance(shape, (carom.ConvexHull, carom.Triangle)):
        verts = shape.vertices
        assert np.min(np.linalg.norm(sup[:, None, :] - verts[None], axis=2), axis=1).max() < tol
    else:
        outside, gap = inside_distance(shape, sup)
        assert outside.max() < tol and gap.max() < tol


def test_batch_single_and_input_types_agree(convex_shape: carom.Shape) -> None:
    rng = np.random.default_rng(3)
    dirs = random_directions(rng, 20)
    batch = convex_shape.support(dirs)
    for i, d in enumerate(dirs):
        single = convex_shape.support(d)
        assert single.shape == (3,)
        np.testing.assert_array_equal(single, batch[i])
    np.testing.assert_array_equal(convex_shape.support(dirs.tolist()), batch)
    np.testing.assert_array_equal(convex_shape.support(dirs.astype(np.float32)), convex_shape.support(dirs.astype(np.float32).astype(np.float64)))
    np.testing.assert_array_equal(convex_shape.support(tuple(map(tuple, dirs))), batch)
    assert convex_shape.support(np.zeros((0, 3))).shape == (0, 3)


def test_large_batch_matches_small_batches(convex_shape: carom.Shape) -> None:
    # Above the parallel threshold the batch releases the GIL and runs on rayon.
    rng = np.random.default_rng(4)
    dirs = rng.normal(size=(5000, 3))
    big = convex_shape.support(dirs)
    small = np.vstack([convex_shape.support(dirs[i : i + 100]) for i in range(0, 5000, 100)])
    np.testing.assert_array_equal(big, small)


def test_integer_directions_and_zero_direction(convex_shape: carom.Shape) -> None:
    p = convex_shape.support([0, 0, 0])
    assert np.all(np.isfinite(p))
    np.testing.assert_array_equal(convex_shape.support(np.array([1, 2, 3])), convex_shape.support([1.0, 2.0, 3.0]))


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), index=st.integers(0, 9))
def test_world_support_matches_transformed_local(seed: int, index: int) -> None:
    from conftest import convex_shapes

    shape = convex_shapes()[index]
    rng = np.random.default_rng(seed)
    q = random_quat(rng)
    t = rng.uniform(-50, 50, size=3)
    pose = carom.Pose(t, q)
    dirs = rng.normal(size=(16, 3))
    world = shape.support(dirs, pose=pose)
    r = quat_matrix(q)
    local = shape.support(dirs @ r)  # R^T d for each row
    expected = local @ r.T + t
    tol = TOL * (scale_of(shape) + 50)
    # Support points can jump between equally good points; compare the dot products.
    assert np.all(np.abs(np.einsum("ij,ij->i", world - expected, dirs)) < tol * np.linalg.norm(dirs, axis=1))
    # The (7,) array form of the pose gives the same answer.
    np.testing.assert_array_equal(shape.support(dirs, pose=np.concatenate([t, q])), shape.support(dirs, pose=pose))


def test_support_core_plus_margin(convex_shape: carom.Shape) -> None:
    rng = np.random.default_rng(5)
    dirs = rng.normal(size=(50, 3))
    core = convex_shape.support_core(dirs)
    full = convex_shape.support(dirs)
    m = convex_shape.margin
    assert m is not None and m >= 0
    n = dirs / np.linalg.norm(dirs, axis=1, keepdims=True)
    # The core swept by the margin is inside the shape and reaches at most as far.
    swept = np.einsum("ij,ij->i", core + m * n, n)
    exact = np.einsum("ij,ij->i", full, n)
    assert np.all(swept <= exact + TOL * scale_of(convex_shape))
    if isinstance(convex_shape, (carom.Sphere, carom.Capsule)):
        np.testing.assert_allclose(swept, exact, atol=TOL * scale_of(convex_shape))


def test_sphere_core_is_centre_and_margin_radius() -> None:
    s = carom.Sphere(0.7)
    assert s.margin == pytest.approx(0.7)
    np.testing.assert_array_equal(s.support_core([[1, 2, 3], [0, -1, 0]]), np.zeros((2, 3)))
    c = carom.Capsule(0.3, 0.8)
    assert c.margin == pytest.approx(0.3)
    np.testing.assert_allclose(c.support_core([0.2, 1.0, 0.0]), [0, 0.8, 0], atol=1e-6)


@pytest.mark.parametrize(
    "shape",
    [
        carom.Plane([0, 1, 0], 0.0),
        carom.TriMesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]]),
        carom.Compound([(carom.Sphere(1.0), None)]),
    ],
)
def test_non_convex_support_raises(shape: carom.Shape) -> None:
    assert not shape.is_convex and shape.margin is None
    with pytest.raises(carom.CaromError, match="convex"):
        shape.support([1, 0, 0])
    with pytest.raises(carom.CaromError, match="convex"):
        shape.support_core([[1, 0, 0]])


@pytest.mark.parametrize(
    "dirs, message",
    [
        (np.zeros((4, 2)), r"directions must have shape \(3,\) or \(N, 3\), got \(4, 2\)"),
        (np.zeros(4), r"got \(4,\)"),
        (np.zeros((2, 3, 1)), r"got \(2, 3, 1\)"),
        ([[1.0, np.nan, 0.0]], r"(?i)directions\[0\].*nan"),
        ([[1.0, 0.0, 0.0], [np.inf, 0.0, 0.0]], r"(?i)directions\[1\].*inf"),
    ],
)
def test_bad_directions(dirs: object, message: str) -> None:
    with pytest.raises(carom.CaromError, match=message):
        carom.Sphere(1.0).support(dirs)


@pytest.mark.parametrize("dirs", ["abc", None, [["a", "b", "c"]], {"x": 1}, [1 + 2j, 0, 0]])
def test_wrong_direction_types(dirs: object) -> None:
    with pytest.raises(TypeError, match="directions"):
        carom.Sphere(1.0).support(dirs)
