"""Shared oracles for the Python tests: numpy samplers of each shape's surface, inside /
on-surface tests, and quaternion rotation matrices, all written independently of Carom."""

from __future__ import annotations

import numpy as np
import pytest

import carom

# Carom's core computes in single precision by default: tolerances in length units.
TOL = 2e-4 if carom.REAL_BITS == 32 else 1e-9


def quat_matrix(q: np.ndarray) -> np.ndarray:
    """Rotation matrix of a unit quaternion (x, y, z, w), the textbook formula."""
    x, y, z, w = q / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def random_quat(rng: np.random.Generator) -> np.ndarray:
    q = rng.normal(size=4)
    return q / np.linalg.norm(q)


def random_directions(rng: np.random.Generator, n: int) -> np.ndarray:
    d = rng.normal(size=(n, 3))
    # Include the axes and diagonals: they hit faces, edges and corners exactly.
    axes = np.array(
        [[1, 0, 0], [0, 1, 0], [0, 0, 1], [-1, 0, 0], [0, -1, 0], [0, 0, -1], [1, 1, 1], [-1, 1, -1]],
        dtype=float,
    )
    return np.vstack([axes, d])


def unit_circle(n: int) -> np.ndarray:
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.stack([np.cos(t), np.sin(t)], axis=1)


def surface_samples(shape: carom.Shape, n: int = 4000, seed: int = 0) -> np.ndarray:
    """Dense points on the surface of a convex shape, from its parameters alone."""
    rng = np.random.default_rng(seed)
    if isinstance(shape, carom.Sphere):
        d = rng.normal(size=(n, 3))
        return shape.radius * d / np.linalg.norm(d, axis=1, keepdims=True)
    if isinstance(shape, carom.Box):
        h = shape.half_extents
        corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * h
        p = rng.uniform(-1, 1, size=(n, 3))
        axis = rng.integers(0, 3, size=n)
        p[np.arange(n), axis] = np.sign(p[np.arange(n), axis])
        return np.vstack([corners, p * h])
    if isinstance(shape, (carom.Cylinder, carom.Cone)):
        r, h = shape.radius, shape.half_height
        c = unit_circle(n // 2)
        base = np.stack([r * c[:, 0], np.full(len(c), -h), r * c[:, 1]], axis=1)
        if isinstance(shape, carom.Cylinder):
            top = base.copy()
            top[:, 1] = h
            return np.vstack([base, top])
        apex = np.array([[0.0, h, 0.0]])
        t = rng.uniform(0, 1, size=(n // 2, 1))
        side = apex + t * (base[rng.integers(0, len(base), n // 2)] - apex)
        return np.vstack([base, apex, side])
    if isinstance(shape, carom.Capsule):
        r, h = shape.radius, shape.half_height
        d = rng.normal(size=(n, 3))
        d = r * d / np.linalg.norm(d, axis=1, keepdims=True)
        d[:, 1] += np.where(d[:, 1] >= 0, h, -h)
        return d
    if isinstance(shape, carom.ConvexHull):
        return shape.vertices
    if isinstance(shape, carom.Triangle):
        return shape.vertices
    if isinstance(shape, carom.Scaled):
        return surface_samples(shape.inner, n, seed) * shape.scale
    raise TypeError(f"no sampler for {shape!r}")


def inside_distance(shape: carom.Shape, p: np.ndarray) -> np.ndarray:
    """How far each point lies outside the shape along a conservative measure (<= 0 inside),
    and how far from the boundary; returns (outside, boundary_gap) arrays."""
    p = np.atleast_2d(p)
    if isinstance(shape, carom.Sphere):
        d = np.linalg.norm(p, axis=1) - shape.radius
        return d, np.abs(d)
    if isinstance(shape, carom.Box):
        q = np.abs(p) - shape.half_extents
        return q.max(axis=1), np.abs(q.max(axis=1))
    if isinstance(shape, carom.Capsule):
        y = np.clip(p[:, 1], -shape.half_height, shape.half_height)
        closest = np.stack([np.zeros(len(p)), y, np.zeros(len(p))], axis=1)
        d = np.linalg.norm(p - closest, axis=1) - shape.radius
        return d, np.abs(d)
    if isinstance(shape, carom.Cylinder):
        radial = np.hypot(p[:, 0], p[:, 2]) - shape.radius
        axial = np.abs(p[:, 1]) - shape.half_height
        m = np.maximum(radial, axial)
        return m, np.abs(m)
    if isinstance(shape, carom.Cone):
        r, h = shape.radius, shape.half_height
        # Outward distances to the base plane and the lateral surface.
        base = -h - p[:, 1]
        slope = np.array([2 * h, r]) / np.hypot(2 * h, r)  # outward normal (radial, y)
        lateral = slope[0] * np.hypot(p[:, 0], p[:, 2]) + slope[1] * (p[:, 1] - h)
        m = np.maximum(base, lateral)
        return m, np.abs(m)
    raise TypeError(f"no inside test for {shape!r}")


def convex_shapes() -> list[carom.Shape]:
    rng = np.random.default_rng(7)
    pts = rng.normal(size=(16, 3)) * [1.0, 0.6, 0.3]
    return [
        carom.Sphere(0.7),
        carom.Box([0.5, 1.0, 0.25]),
        carom.Capsule(0.3, 0.8),
        carom.Cylinder(0.6, 0.4),
        carom.Cone(0.5, 0.9),
        carom.ConvexHull(pts),
        carom.Triangle([0, 0, 0], [1, 0, 0], [0.2, 1, 0.3]),
        carom.Box([0.5, 1.0, 0.25]).scaled([2.0, 0.5, -1.0]),
        carom.Cylinder(0.6, 0.4).scaled([1.5, 1.0, 0.5]),
        carom.Sphere(1.0).scaled([1.0, 2.0, 0.5]),
    ]


@pytest.fixture(params=convex_shapes(), ids=lambda s: s.kind + ":" + repr(s)[:30])
def convex_shape(request: pytest.FixtureRequest) -> carom.Shape:
    return request.param
