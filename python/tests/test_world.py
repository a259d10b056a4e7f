"""Rigid-body simulation from Python: `carom.World` against analytic oracles (symplectic-Euler
free fall, resting contact, Coulomb sliding distance, momentum conservation, Bullet's
fixed-step accumulator), bulk numpy state round trips, and bad input (ValueError /
TypeError, nothing changed, never a panic)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import carom

G = 9.81
DT = 1.0 / 60.0


def ground_world(**kw) -> tuple[carom.World, int]:
    w = carom.World(**kw)
    g = w.add_body(carom.Box([20.0, 0.5, 20.0]), [0, -0.5, 0, 0, 0, 0, 1], is_static=True)
    return w, g


def test_free_fall_matches_symplectic_euler() -> None:
    w = carom.World(gravity=[0, -G, 0], dt=DT)
    h = w.add_body(carom.Sphere(0.5), [1.0, 100.0, -2.0, 0, 0, 0, 1])
    n = 30
    w.step(n)
    # The default soft-step solver integrates in 4 substeps of h = dt / 4 (Box2D v3):
    # symplectic Euler over N = 4 n substeps gives y_N = y_0 - g h² N (N + 1) / 2.
    h_sub, big_n = DT / 4, 4 * n
    y = 100.0 - G * h_sub * h_sub * big_n * (big_n + 1) / 2
    p = w.poses([h])[0]
    assert p[1] == pytest.approx(y, abs=1e-3)
    assert p[0] == pytest.approx(1.0, abs=1e-5) and p[2] == pytest.approx(-2.0, abs=1e-5)
    lin, ang = w.velocities([h])
    assert lin[0, 1] == pytest.approx(-G * n * DT, rel=1e-4)
    np.testing.assert_allclose(ang, 0.0, atol=1e-6)


def test_box_comes_to_rest_on_the_ground() -> None:
    w, _ = ground_world()
    h = w.add_body(carom.Box([0.5, 0.5, 0.5]), [0, 1.5, 0, 0, 0, 0, 1])
    w.step(180)
    p = w.poses([h])[0]
    assert p[1] == pytest.approx(0.5, abs=0.01)
    lin, _ = w.velocities([h])
    assert np.linalg.norm(lin) < 0.05
    stats = w.last_step()
    assert stats["pairs"] >= 1 and stats["total"] >= 0.0
    # No query since the last step: the step kept no query tree current.
    assert stats["query_tree"] == 0.0
    # A ray cast, then a step: the step refreshes the tree the ray used.
    hit = w.raycast([0.0, 3.0, 0.0], [0.0, -1.0, 0.0], 10.0)
    assert hit is not None
    w.step(1)
    assert w.last_step()["query_tree"] > 0.0
    again = w.raycast([0.0, 3.0, 0.0], [0.0, -1.0, 0.0], 10.0)
    assert again is not None and again.distance == pytest.approx(hit.distance, abs=1e-3)


def test_sliding_box_stops_where_coulomb_says() -> None:
    mu, v0 = 0.5, 4.0
    w, _ = ground_world(sleeping=False)
    h = w.add_body(
        carom.Box([0.5, 0.5, 0.5]),
        [0, 0.5, 0, 0, 0, 0, 1],
        friction=mu,
        linear_velocity=[v0, 0, 0],
    )
    # The ground's friction is 0.5 too: the geometric mean is mu.
    w.step(150)
    x = w.poses([h])[0][0]
    d = v0 * v0 / (2 * mu * G)
    assert x == pytest.approx(d, rel=0.08)


def test_momentum_is_conserved_without_gravity() -> None:
    w = carom.World(gravity=[0, 0, 0], sleeping=False)
    a = w.add_body(carom.Sphere(0.5), [-2, 0, 0, 0, 0, 0, 1], mass=2.0, linear_velocity=[3, 0, 0])
    b = w.add_body(carom.Sphere(0.5), [2, 0.2, 0, 0, 0, 0, 1], mass=1.0, linear_velocity=[-1, 0, 0])
    p0 = 2.0 * np.array([3.0, 0, 0]) + 1.0 * np.array([-1.0, 0, 0])
    e0 = 0.5 * 2.0 * 9.0 + 0.5 * 1.0 * 1.0
    w.step(120)
    lin, _ = w.velocities([a, b])
    p1 = 2.0 * lin[0] + 1.0 * lin[1]
    np.testing.assert_allclose(p1, p0, atol=1e-3)
    e1 = 0.5 * 2.0 * lin[0] @ lin[0] + 0.5 * 1.0 * lin[1] @ lin[1]
    assert e1 <= e0 * (1 + 1e-4)
    # They met: B now moves in +x.
    assert lin[1, 0] > 0.0


def test_step_simulation_accumulates_fixed_steps() -> None:
    w = carom.World(dt=DT)
    w.add_body(carom.Sphere(0.5), [0, 10, 0, 0, 0, 0, 1])
    assert w.step_simulation(2.5 * DT, max_sub_steps=5) == 2
    # 0.5 dt left over + 0.6 dt = 1.1 dt: one more step.
    assert w.step_simulation(0.6 * DT, max_sub_steps=5) == 1
    # Capped: at most max_sub_steps.
    assert w.step_simulation(10 * DT, max_sub_steps=3) == 3


def test_bulk_state_round_trips() -> None:
    w = carom.World(gravity=[0, 0, 0])
    hs = [w.add_body(carom.Sphere(0.2), [3 * i, 0, 0, 0, 0, 0, 1]) for i in range(5)]
    assert w.handles() == hs and len(w) == 5 and hs[2] in w
    rng = np.random.default_rng(1)
    q = rng.normal(size=(5, 4))
    q /= np.linalg.norm(q, axis=1)[:, None]
    poses = np.hstack([rng.uniform(-50, 50, size=(5, 3)), q])
    w.set_poses(hs, poses)
    got = w.poses()
    np.testing.assert_allclose(got[:, :3], poses[:, :3], atol=1e-4)
    # Quaternions up to sign.
    dots = np.abs(np.sum(got[:, 3:] * poses[:, 3:], axis=1))
    np.testing.assert_allclose(dots, 1.0, atol=1e-5)
    lin = rng.normal(size=(5, 3))
    ang = rng.normal(size=(5, 3))
    w.set_velocities(hs, lin, ang)
    l2, a2 = w.velocities(hs)
    np.testing.assert_allclose(l2, lin, atol=1e-5)
    np.testing.assert_allclose(a2, ang, atol=1e-5)


def test_impulse_changes_velocity_by_j_over_m() -> None:
    w = carom.World(gravity=[0, 0, 0])
    h = w.add_body(carom.Sphere(0.5), None, mass=4.0)
    w.apply_impulse(h, [8.0, 0, 0], [0, 0, 0])
    lin, ang = w.velocities([h])
    np.testing.assert_allclose(lin[0], [2.0, 0, 0], atol=1e-5)
    np.testing.assert_allclose(ang[0], 0.0, atol=1e-5)


def test_bodies_fall_asleep_and_removal_invalidates_handles() -> None:
    w, g = ground_world()
    h = w.add_body(carom.Box([0.5, 0.5, 0.5]), [0, 0.5, 0, 0, 0, 0, 1])
    w.step(240)
    assert w.is_sleeping(h)
    w.remove_body(h)
    assert h not in w and len(w) == 1
    with pytest.raises(ValueError):
        w.poses([h])
    with pytest.raises(ValueError):
        w.remove_body(h)
    # The slot is reused with a new generation: the old handle stays dead.
    h2 = w.add_body(carom.Sphere(0.5), [0, 3, 0, 0, 0, 0, 1])
    assert h2 != h and h not in w and g in w


def test_bad_input_is_rejected_and_changes_nothing() -> None:
    with pytest.raises(ValueError, match="dt"):
        carom.World(dt=0.0)
    with pytest.raises(ValueError, match="dt"):
        carom.World(dt=math.nan)
    with pytest.raises(ValueError):
        carom.World(method="octree")
    with pytest.raises(ValueError):
        carom.World(gravity=[0, math.nan, 0])
    w, _ = ground_world()
    n = len(w)
    with pytest.raises(ValueError, match="mass"):
        w.add_body(carom.Sphere(0.5), None, mass=-1.0)
    with pytest.raises(ValueError, match="mass"):
        w.add_body(carom.Sphere(0.5), None, mass=0.0)
    with pytest.raises(ValueError):
        w.add_body(carom.Sphere(0.5), [0, math.nan, 0, 0, 0, 0, 1])
    with pytest.raises(ValueError):
        w.add_body(carom.Sphere(0.5), None, is_static=True, kinematic=True)
    with pytest.raises(TypeError):
        w.add_body("not a shape")  # type: ignore[arg-type]
    assert len(w) == n
    h = w.add_body(carom.Sphere(0.5), [0, 2, 0, 0, 0, 0, 1])
    before = w.poses()
    with pytest.raises(ValueError):
        w.set_poses([h], np.zeros((2, 7)))
    with pytest.raises(ValueError):
        w.set_poses([h], [[0, math.inf, 0, 0, 0, 0, 1]])
    with pytest.raises(ValueError):
        w.set_velocities([h], [[0, 0, 0]], [[math.nan, 0, 0]])
    with pytest.raises(ValueError):
        w.apply_impulse(h, [math.nan, 0, 0], [0, 0, 0])
    with pytest.raises(ValueError):
        w.step_simulation(-1.0)
    np.testing.assert_array_equal(w.poses(), before)
    with pytest.raises(ValueError):
        w.poses([12345])
