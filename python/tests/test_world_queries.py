"""Contact events, contact points and ray / shape casts through `carom.World`, against the
brute force over every body with `carom.raycast` / `carom.shape_cast` and against physics
(the normal impulses under a resting box add up to m g dt)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import carom


def random_world(seed: int, offset=(0.0, 0.0, 0.0)) -> tuple[carom.World, dict[int, carom.Shape]]:
    rng = np.random.default_rng(seed)
    off = np.asarray(offset)
    w = carom.World()
    shapes: dict[int, carom.Shape] = {}
    ground = carom.Box([20, 0.5, 20])
    shapes[w.add_body(ground, list(off + [0, -0.5, 0]) + [0, 0, 0, 1], is_static=True)] = ground
    for i in range(50):
        s = [carom.Sphere(rng.uniform(0.1, 0.6)), carom.Box(rng.uniform(0.1, 0.6, 3)),
             carom.Capsule(0.2, 0.4), carom.ConvexHull(rng.uniform(-0.4, 0.4, (12, 3)))][i % 4]
        q = rng.normal(size=4)
        q /= np.linalg.norm(q)
        p = off + [rng.uniform(-8, 8), rng.uniform(0.5, 6), rng.uniform(-8, 8)]
        shapes[w.add_body(s, list(p) + list(q), group=2 if i % 5 == 0 else 1)] = s
    return w, shapes


def brute_ray(w, shapes, o, d, max_distance, mask=0xFFFFFFFF, groups=None):
    best = None
    for h, pose in zip(w.handles(), w.poses()):
        if groups is not None and groups[h] & mask == 0:
            continue
        hit = carom.raycast(shapes[h], pose, o, d, max_distance=max_distance)
        if hit is not None and (best is None or hit.distance < best[1]):
            best = (h, hit.distance)
    return best


@pytest.mark.parametrize("offset", [(0.0, 0.0, 0.0), (3000.0, -100.0, 500.0)])
def test_batch_rays_equal_the_brute_force(offset) -> None:
    w, shapes = random_world(3, offset)
    rng = np.random.default_rng(4)
    n = 300
    origins = np.asarray(offset) + np.column_stack(
        [rng.uniform(-10, 10, n), rng.uniform(0.2, 8, n), np.full(n, -12.0)]
    )
    dirs = np.column_stack([rng.uniform(-0.3, 0.3, n), rng.uniform(-0.4, 0.1, n), np.ones(n)])
    hits = w.raycast(origins, dirs, max_distance=30.0)
    assert hits.hit.shape == (n,) and hits.point.shape == (n, 3) and hits.body.dtype == np.int64
    tol = 1e-4 * (1 + np.linalg.norm(offset))
    for i in range(n):
        want = brute_ray(w, shapes, origins[i], dirs[i], 30.0)
        assert bool(hits.hit[i]) == (want is not None), i
        if want is None:
            assert hits.body[i] == -1 and math.isnan(hits.distance[i])
            continue
        assert hits.distance[i] == pytest.approx(want[1], abs=tol)
        u = dirs[i] / np.linalg.norm(dirs[i])
        np.testing.assert_allclose(hits.point[i], origins[i] + u * hits.distance[i], atol=10 * tol)
        single = w.raycast(origins[i], dirs[i], max_distance=30.0)
        assert single is not None and single.body == hits.body[i]
        assert single.distance == hits.distance[i]
    rate = hits.hit.mean()
    assert 0.2 < rate < 0.9, rate


def test_single_ray_misses_masks_and_infinite_length() -> None:
    w, shapes = random_world(5)
    assert w.raycast([0, 100, 0], [0, 1, 0]) is None
    down = w.raycast([15, 50, 15], [0, -1, 0])
    assert down is not None and down.body == w.handles()[0]
    assert down.distance == pytest.approx(50.0, abs=1e-4)
    np.testing.assert_allclose(down.normal, [0, 1, 0], atol=1e-6)
    assert w.raycast([15, 50, 15], [0, -1, 0], max_distance=49.0) is None
    # Mask 2 sees only the group-2 bodies.
    groups = {h: (2 if (k - 1) % 5 == 0 and k > 0 else 1) for k, h in enumerate(w.handles())}
    rng = np.random.default_rng(9)
    for _ in range(100):
        o = [rng.uniform(-8, 8), 10.0, rng.uniform(-8, 8)]
        got = w.raycast(o, [0, -1, 0], mask=2)
        want = brute_ray(w, shapes, o, [0, -1, 0], math.inf, mask=2, groups=groups)
        assert (got is None) == (want is None)
        if got is not None:
            assert got.body == want[0] and got.distance == pytest.approx(want[1], abs=1e-4)


def test_shape_cast_equals_the_brute_force() -> None:
    w, shapes = random_world(7)
    rng = np.random.default_rng(8)
    probe = carom.Sphere(0.3)
    hits = 0
    for _ in range(80):
        pose = [rng.uniform(-9, 9), rng.uniform(0.5, 7), -11, 0, 0, 0, 1]
        vel = [rng.uniform(-2, 2), rng.uniform(-3, 1), 20.0]
        got = w.shape_cast(probe, pose, vel)
        best = None
        for h, p in zip(w.handles(), w.poses()):
            hit = carom.shape_cast(probe, pose, vel, shapes[h], p, [0, 0, 0])
            if hit is not None and (best is None or hit.toi < best.toi):
                best = hit
        assert (got is None) == (best is None)
        if got is not None:
            hits += 1
            assert got.toi == pytest.approx(best.toi, abs=1e-4)
            assert np.linalg.norm(got.normal) == pytest.approx(1.0, abs=1e-6)
    assert 10 < hits < 75


def test_contact_events_follow_a_bouncing_box() -> None:
    w = carom.World(sleeping=False)
    g = w.add_body(carom.Box([5, 0.5, 5]), [0, -0.5, 0, 0, 0, 0, 1], is_static=True)
    b = w.add_body(carom.Box([0.5] * 3), [0, 1.0, 0, 0, 0, 0, 1])
    pair = sorted((g, b))
    seen = []
    for step in range(200):
        if step == 120:
            w.set_velocities([b], [[0, 6, 0]], [[0, 0, 0]])
        w.step()
        ev = w.contact_events()
        for kind in ("begin", "persist", "end"):
            for p in getattr(ev, kind).tolist():
                assert sorted(p) == pair
                seen.append((step, kind))
    kinds = [k for _, k in seen]
    assert kinds[0] == "begin" and "persist" in kinds
    ends = [s for s, k in seen if k == "end"]
    assert ends and 120 <= ends[0] < 125, ends
    # A second landing begins again.
    assert any(k == "begin" and s > ends[0] for s, k in seen)


def test_resting_box_contact_impulses_carry_its_weight() -> None:
    w = carom.World(dt=1 / 60, sleeping=False)
    g = w.add_body(carom.Box([5, 0.5, 5]), [0, -0.5, 0, 0, 0, 0, 1], is_static=True)
    m = 8.0
    b = w.add_body(carom.Box([0.5] * 3), [0, 0.5, 0, 0, 0, 0, 1], mass=m)
    w.step(120)
    c = w.contacts()
    assert len(c) == 4
    assert c.bodies.shape == (4, 2) and set(c.bodies.ravel().tolist()) == {g, b}
    # Normal from A to B: from the ground up when A is the ground.
    a_is_ground = c.bodies[0, 0] == g
    np.testing.assert_allclose(c.normal[0], [0, 1 if a_is_ground else -1, 0], atol=1e-5)
    np.testing.assert_allclose(c.point_b, c.point_a + c.normal * c.distance[:, None], atol=1e-6)
    assert c.normal_impulse.sum() == pytest.approx(m * 9.81 * w.dt, rel=0.02)


def test_query_bad_input_raises() -> None:
    w, _ = random_world(1)
    with pytest.raises(ValueError, match="direction"):
        w.raycast([0, 0, 0], [0, 0, 0])
    with pytest.raises(ValueError, match="max_distance"):
        w.raycast([0, 0, 0], [1, 0, 0], max_distance=-1.0)
    with pytest.raises(ValueError, match="ray 1"):
        w.raycast([[0, 0, 0], [0, 0, 0]], [[1, 0, 0], [math.nan, 0, 0]])
    with pytest.raises(ValueError, match="directions"):
        w.raycast(np.zeros((3, 3)), np.ones((2, 3)))
    with pytest.raises(ValueError, match="origins"):
        w.raycast(np.zeros((3, 2)), np.ones((3, 3)))
    with pytest.raises(ValueError, match="velocity"):
        w.shape_cast(carom.Sphere(1.0), None, [math.inf, 0, 0])
    with pytest.raises(ValueError, match="max_time"):
        w.shape_cast(carom.Sphere(1.0), None, [1, 0, 0], max_time=math.inf)
    with pytest.raises(TypeError):
        w.shape_cast("sphere", None, [1, 0, 0])  # type: ignore[arg-type]
    assert carom.World().raycast([0, 0, 0], [1, 0, 0]) is None
