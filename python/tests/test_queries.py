"""Module-level queries against independent numpy oracles: analytic sphere/box distances and
ray intersections, the A/B swap invariant, batch == single, and bad input."""

from __future__ import annotations

import math
import pickle

import numpy as np
import pytest

import carom

from conftest import TOL

Q_ID = [0.0, 0.0, 0.0, 1.0]


def pose(p, q=Q_ID) -> np.ndarray:
    return np.array([*p, *q], dtype=float)


def check_witness(c: carom.Contact) -> None:
    np.testing.assert_allclose(c.point_b, c.point_a + c.normal * c.distance, atol=10 * TOL)
    assert abs(np.linalg.norm(c.normal) - 1.0) < 10 * TOL


def box_point_distance(h: np.ndarray, p: np.ndarray) -> float:
    """Signed distance from a point to an axis-aligned box centred at the origin."""
    q = np.abs(p) - h
    outside = np.linalg.norm(np.maximum(q, 0.0))
    return float(outside + min(q.max(), 0.0))


def test_sphere_sphere_distance_and_penetration() -> None:
    rng = np.random.default_rng(1)
    a, b = carom.Sphere(0.5), carom.Sphere(0.75)
    for _ in range(50):
        pa, pb = rng.uniform(-2, 2, 3), rng.uniform(-2, 2, 3)
        d = np.linalg.norm(pb - pa)
        if d < 1e-3:
            continue
        c = carom.distance(a, pose(pa), b, pose(pb))
        assert c.distance == pytest.approx(d - 1.25, abs=10 * TOL)
        np.testing.assert_allclose(c.normal, (pb - pa) / d, atol=10 * TOL)
        np.testing.assert_allclose(c.point_a, pa + 0.5 * (pb - pa) / d, atol=10 * TOL)
        check_witness(c)


def test_sphere_box_against_numpy() -> None:
    rng = np.random.default_rng(2)
    h = np.array([0.5, 1.0, 1.5])
    box, sph = carom.Box(h), carom.Sphere(0.3)
    for _ in range(50):
        p = rng.uniform(-3, 3, 3)
        c = carom.distance(box, pose([0, 0, 0]), sph, pose(p))
        assert c.distance == pytest.approx(box_point_distance(h, p) - 0.3, abs=20 * TOL)
        check_witness(c)


def test_box_box_axis_aligned_against_numpy() -> None:
    rng = np.random.default_rng(3)
    ha, hb = np.array([0.5, 0.5, 0.5]), np.array([1.0, 0.25, 0.5])
    a, b = carom.Box(ha), carom.Box(hb)
    for _ in range(50):
        t = rng.uniform(-3, 3, 3)
        gap = np.abs(t) - ha - hb
        # Separated: Euclidean distance between the boxes; overlapping: minus the smallest
        # axis overlap (axis-aligned boxes: the face axes are the separating candidates).
        expected = np.linalg.norm(np.maximum(gap, 0)) if (gap > 0).any() else gap.max()
        c = carom.distance(a, pose([0, 0, 0]), b, pose(t))
        assert c.distance == pytest.approx(expected, abs=20 * TOL)
        check_witness(c)


def test_swap_flips_normal() -> None:
    rng = np.random.default_rng(4)
    shapes = [carom.Sphere(0.4), carom.Box([0.3, 0.6, 0.2]), carom.Capsule(0.2, 0.5)]
    for _ in range(30):
        a, b = rng.choice(len(shapes), 2)
        pa = pose(rng.uniform(-1, 1, 3), rng.normal(size=4) / 2)
        pb = pose(rng.uniform(-1, 1, 3), rng.normal(size=4) / 2)
        pa[3:] /= np.linalg.norm(pa[3:])
        pb[3:] /= np.linalg.norm(pb[3:])
        ab = carom.distance(shapes[a], pa, shapes[b], pb)
        ba = carom.distance(shapes[b], pb, shapes[a], pa)
        assert ab.distance == pytest.approx(ba.distance, abs=1e-3)
        if abs(ab.distance) > 1e-2:
            np.testing.assert_allclose(ab.normal, -ba.normal, atol=1e-2)


def test_contact_and_intersects() -> None:
    s = carom.Sphere(1.0)
    assert carom.contact(s, pose([0, 0, 0]), s, pose([3, 0, 0])) is None
    c = carom.contact(s, pose([0, 0, 0]), s, pose([1.5, 0, 0]))
    assert c is not None and c.distance == pytest.approx(-0.5, abs=10 * TOL)
    np.testing.assert_allclose(c.normal, [1, 0, 0], atol=10 * TOL)
    assert carom.contact(s, pose([0, 0, 0]), s, pose([2.5, 0, 0]), prediction=1.0) is not None
    assert carom.intersects(s, pose([0, 0, 0]), s, pose([1.9, 0, 0]))
    assert not carom.intersects(s, pose([0, 0, 0]), s, pose([2.1, 0, 0]))


def test_contact_small_box_just_above_huge_ground() -> None:
    """A 1 m box 0.2 mm above a 250x50x250 ground box (and hull), far from the origin: the
    answer is the gap along +Y (GJK alone called it touching in f32)."""
    ground = carom.Box([250.0, 50.0, 250.0])
    corners = [[sx * 250.0, sy * 50.0, sz * 250.0] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]
    small = carom.ConvexHull([[sx * 0.5, sy * 0.5, sz * 0.5] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    gap = 2e-4
    for g in (ground, carom.ConvexHull(corners)):
        for off in (0.0, 700.0):
            c = carom.contact(g, pose([off, -50.0, 0.0]), small, pose([off + 20.0, 0.5 + gap, 0.0]), prediction=0.01)
            assert c is not None
            assert c.distance == pytest.approx(gap, abs=1e-4)
            np.testing.assert_allclose(c.normal, [0, 1, 0], atol=1e-3)


def test_batch_equals_single() -> None:
    rng = np.random.default_rng(5)
    a, b = carom.Box([0.5, 0.4, 0.3]), carom.Sphere(0.5)
    poses = np.zeros((40, 7))
    poses[:, :3] = rng.uniform(-2, 2, (40, 3))
    q = rng.normal(size=(40, 4))
    poses[:, 3:] = q / np.linalg.norm(q, axis=1, keepdims=True)
    origin = pose([0, 0, 0])
    batch = carom.distance(a, origin, b, poses)
    assert batch.distance.shape == (40,) and batch.normal.shape == (40, 3)
    hits = carom.intersects(a, origin, b, poses)
    cb = carom.contact(a, origin, b, poses)
    assert cb is not None
    for i in range(40):
        one = carom.distance(a, origin, b, poses[i])
        assert batch.distance[i] == one.distance
        np.testing.assert_array_equal(batch.point_a[i], one.point_a)
        np.testing.assert_array_equal(batch.normal[i], one.normal)
        assert bool(hits[i]) == carom.intersects(a, origin, b, poses[i])
        c = carom.contact(a, origin, b, poses[i])
        assert (c is None) == bool(np.isnan(cb.distance[i]))


def ray_sphere(o: np.ndarray, d: np.ndarray, r: float) -> float | None:
    b = o @ d
    disc = b * b - (o @ o - r * r)
    if disc < 0:
        return None
    t0, t1 = -b - math.sqrt(disc), -b + math.sqrt(disc)
    if t1 < 0:
        return None
    return max(t0, 0.0)


def ray_box(o: np.ndarray, d: np.ndarray, h: np.ndarray) -> float | None:
    with np.errstate(divide="ignore", invalid="ignore"):
        t1, t2 = (-h - o) / d, (h - o) / d
    lo, hi = np.nanmax(np.minimum(t1, t2)), np.nanmin(np.maximum(t1, t2))
    if lo > hi or hi < 0:
        return None
    return max(float(lo), 0.0)


@pytest.mark.parametrize("kind", ["sphere", "box"])
def test_raycast_against_numpy(kind: str) -> None:
    rng = np.random.default_rng(6)
    h = np.array([0.5, 1.0, 0.75])
    shape = carom.Sphere(1.0) if kind == "sphere" else carom.Box(h)
    hits = 0
    origins, dirs = [], []
    for _ in range(100):
        o = rng.uniform(-3, 3, 3)
        d = rng.uniform(-0.4, 0.4, 3) - o / np.linalg.norm(o)
        d /= np.linalg.norm(d)
        origins.append(o)
        dirs.append(d)
        t = ray_sphere(o, d, 1.0) if kind == "sphere" else ray_box(o, d, h)
        hit = carom.raycast(shape, None, o, d)
        assert (hit is None) == (t is None), (o, d, t)
        if hit is not None and t is not None:
            hits += 1
            assert hit.distance == pytest.approx(t, abs=20 * TOL)
            np.testing.assert_allclose(hit.point, o + t * d, atol=20 * TOL)
            assert hit.inside == (t == 0.0)
    assert 20 <= hits <= 80
    batch = carom.raycast(shape, None, np.array(origins), np.array(dirs))
    assert batch is not None and batch.hit.shape == (100,)
    for i in range(100):
        one = carom.raycast(shape, None, origins[i], dirs[i])
        assert bool(batch.hit[i]) == (one is not None)
        if one is not None:
            assert batch.distance[i] == one.distance
        else:
            assert np.isnan(batch.distance[i])


def test_raycast_max_distance_and_pose() -> None:
    s = carom.Sphere(1.0)
    p = pose([5, 0, 0])
    assert carom.raycast(s, p, [0, 0, 0], [1, 0, 0], max_distance=3.0) is None
    hit = carom.raycast(s, p, [0, 0, 0], [2, 0, 0])
    assert hit is not None and hit.distance == pytest.approx(4.0, abs=10 * TOL)
    np.testing.assert_allclose(hit.normal, [-1, 0, 0], atol=10 * TOL)


def test_project_point_box() -> None:
    rng = np.random.default_rng(7)
    h = np.array([0.5, 1.0, 1.5])
    box = carom.Box(h)
    pts = rng.uniform(-3, 3, (50, 3))
    batch = carom.project_point(box, None, pts)
    for i, p in enumerate(pts):
        one = carom.project_point(box, None, p)
        assert one.distance == pytest.approx(box_point_distance(h, p), abs=10 * TOL)
        assert one.inside == (box_point_distance(h, p) <= 0)
        assert batch.distance[i] == one.distance


def test_shape_cast_and_toi_spheres() -> None:
    s = carom.Sphere(0.5)
    hit = carom.shape_cast(s, pose([0, 0, 0]), [4, 0, 0], s, pose([3, 0, 0]), [0, 0, 0])
    assert hit is not None and hit.toi == pytest.approx(0.5, abs=1e-3)
    np.testing.assert_allclose(hit.normal, [1, 0, 0], atol=1e-3)
    assert carom.shape_cast(s, pose([0, 0, 0]), [1, 0, 0], s, pose([3, 0, 0]), [0, 0, 0]) is None
    toi = carom.time_of_impact(
        s, pose([0, 0, 0]), [4, 0, 0], [0, 0, 1], s, pose([3, 0, 0]), [0, 0, 0], [0, 0, 0]
    )
    assert toi is not None and toi.toi == pytest.approx(0.5, abs=1e-3)


def test_bad_input() -> None:
    s = carom.Sphere(1.0)
    bad = pose([0, 0, 0])
    bad[0] = np.nan
    with pytest.raises(carom.CaromError, match="pose_a"):
        carom.distance(s, bad, s, pose([3, 0, 0]))
    with pytest.raises(carom.CaromError, match="direction"):
        carom.raycast(s, None, [0, 0, 0], [0, 0, 0])
    with pytest.raises(carom.CaromError, match="shape"):
        carom.distance(s, np.zeros((3, 5)), s, None)
    with pytest.raises(carom.CaromError, match="poses_b"):
        carom.distance(s, np.tile(pose([0, 0, 0]), (3, 1)), s, np.tile(pose([3, 0, 0]), (2, 1)))
    with pytest.raises(TypeError, match="must be a carom.Shape"):
        carom.distance("sphere", None, s, None)  # type: ignore[arg-type]
    with pytest.raises(TypeError):
        carom.raycast(s, None, "origin", [1, 0, 0])


def test_heightfield() -> None:
    heights = np.arange(12, dtype=float).reshape(3, 4) * 0.1
    hf = carom.HeightField(heights, cell_size=(0.5, 2.0))
    np.testing.assert_allclose(hf.heights, heights, atol=1e-6)
    assert hf.cell_size == (0.5, 2.0)
    assert hf.num_triangles == 2 * 2 * 3
    assert hf.kind == "heightfield" and not hf.is_convex
    lo, hi = hf.aabb(None)
    np.testing.assert_allclose(lo, [-0.75, 0.0, -2.0], atol=1e-6)
    np.testing.assert_allclose(hi, [0.75, 1.1, 2.0], atol=1e-6)
    assert pickle.loads(pickle.dumps(hf)) == hf
    assert "HeightField" in repr(hf)
    with pytest.raises(carom.CaromError, match="heights"):
        carom.HeightField(np.zeros(5))
    with pytest.raises(carom.CaromError):
        carom.HeightField(np.zeros((1, 4)))
    with pytest.raises(carom.CaromError, match=r"heights"):
        carom.HeightField([[0, 1], [np.nan, 0]])


def test_shape_cast_batch_equals_single() -> None:
    rng = np.random.default_rng(8)
    a, b = carom.Sphere(0.4), carom.Box([0.3, 0.5, 0.2])
    poses_b = np.tile(pose([0, 0, 0]), (30, 1))
    poses_b[:, :3] = rng.uniform(-3, 3, (30, 3))
    vel_a = poses_b[:, :3] * 1.5 + rng.uniform(-1, 1, (30, 3))
    batch = carom.shape_cast(a, pose([0, 0, 0]), vel_a, b, poses_b, [0, 0, 0])
    assert batch is not None and batch.toi.shape == (30,)
    n_hit = 0
    for i in range(30):
        one = carom.shape_cast(a, pose([0, 0, 0]), vel_a[i], b, poses_b[i], [0, 0, 0])
        assert (one is None) == bool(np.isnan(batch.toi[i]))
        if one is not None:
            n_hit += 1
            assert batch.toi[i] == one.toi
            np.testing.assert_array_equal(batch.normal[i], one.normal)
    assert n_hit > 0


def _random_quat(rng: np.random.Generator) -> np.ndarray:
    q = rng.normal(size=4)
    return q / np.linalg.norm(q)


@pytest.mark.parametrize("scale", [1e-4, 1e-3, 1e3])
def test_distance_does_not_depend_on_the_unit_of_length(scale: float) -> None:
    """A configuration scaled by `scale` gives `scale` times the distance of the same one at
    1 m, both argument orders, for curved shapes, polytopes and a triangle, apart and
    overlapping. Sub-millimetre pairs were wrong before session 26: capsule-box distances
    23 % short (an absolute touching test) and cone-triangle depths 13 % deep (EPA's sliver
    test)."""
    rng = np.random.default_rng(26)
    pts = rng.normal(size=(10, 3)) * 0.4

    def shapes(s: float) -> list[carom.Shape]:
        return [
            carom.Capsule(0.2 * s, 0.5 * s),
            carom.Box([0.5 * s, 0.2 * s, 0.3 * s]),
            carom.Cone(0.3 * s, 0.4 * s),
            carom.Cylinder(0.3 * s, 0.4 * s),
            carom.ConvexHull(pts * s),
            carom.Triangle([0, 0, 0], [s, 0, 0], [0, s, 0]),
        ]

    unit, scaled = shapes(1.0), shapes(scale)
    checked = 0
    for i in range(len(unit)):
        for j in range(len(unit)):
            for _ in range(8):
                pa = (rng.normal(size=3) * 0.5, _random_quat(rng))
                pb = (pa[0] + rng.normal(size=3) * 0.8, _random_quat(rng))
                want = carom.distance(unit[i], pose(*pa), unit[j], pose(*pb)).distance
                a_pose = pose(pa[0] * scale, pa[1])
                b_pose = pose(pb[0] * scale, pb[1])
                d1 = carom.distance(scaled[i], a_pose, scaled[j], b_pose)
                d2 = carom.distance(scaled[j], b_pose, scaled[i], a_pose)
                for d in (d1.distance, d2.distance):
                    assert d / scale == pytest.approx(want, abs=1e-3), (i, j, scale)
                if want > 1e-3:
                    gap = np.linalg.norm(np.asarray(d1.point_a) - np.asarray(d1.point_b))
                    assert gap / scale == pytest.approx(want, abs=1e-3)
                checked += 1
    assert checked == 6 * 6 * 8
