"""Forces, torques and bad input on `carom.World`: a constant force gives v = F t / m, a
torque ω = τ t / I; NaN forces, torques, poses and times are rejected and change nothing; a
body removed from another thread while `step` runs (GIL released) cannot corrupt the world."""

from __future__ import annotations

import math
import threading

import numpy as np
import pytest

import carom


def test_force_and_torque_accelerate_as_newton_says() -> None:
    w = carom.World(gravity=[0, 0, 0], dt=1 / 60, sleeping=False)
    m, r = 2.0, 0.5
    h = w.add_body(carom.Sphere(r), None, mass=m)
    n = 30
    for _ in range(n):
        w.add_force(h, [4.0, 0, 0])
        w.add_torque(h, [0, 0, 0.3])
        w.step()
    lin, ang = w.velocities([h])
    assert lin[0, 0] == pytest.approx(4.0 * n * w.dt / m, rel=1e-4)
    assert ang[0, 2] == pytest.approx(0.3 * n * w.dt / (0.4 * m * r * r), rel=1e-4)
    # A force off the centre of mass adds its torque (p - com) x f.
    g = w.add_body(carom.Sphere(r), [10, 0, 0, 0, 0, 0, 1], mass=m)
    w.add_force(g, [0, 1.0, 0], point=[10.5, 0, 0])
    w.step()
    _, ang = w.velocities([g])
    assert ang[0, 2] == pytest.approx(0.5 * 1.0 * w.dt / (0.4 * m * r * r), rel=1e-4)


def test_non_finite_input_is_rejected_and_changes_nothing() -> None:
    w = carom.World()
    h = w.add_body(carom.Box([0.5] * 3), [0, 2, 0, 0, 0, 0, 1])
    before = w.to_bytes()
    for bad in ([math.nan, 0, 0], [0, math.inf, 0]):
        with pytest.raises(ValueError, match="force"):
            w.add_force(h, bad)
        with pytest.raises(ValueError, match="point"):
            w.add_force(h, [1, 0, 0], point=bad)
        with pytest.raises(ValueError, match="torque"):
            w.add_torque(h, bad)
    with pytest.raises(ValueError):
        w.add_force(12345, [1, 0, 0])
    with pytest.raises(ValueError, match="elapsed"):
        w.step_simulation(math.nan)
    with pytest.raises(ValueError, match="fixed_step"):
        w.step_simulation(0.1, 4, fixed_step=math.inf)
    with pytest.raises(ValueError, match="mass"):
        w.add_body(carom.Sphere(0.5), None, mass=math.nan)
    with pytest.raises(ValueError, match="density"):
        w.add_body(carom.Sphere(0.5), None, density=-3.0)
    assert w.to_bytes() == before, "a rejected call changed the world"


def test_removing_a_body_while_step_runs_cannot_corrupt() -> None:
    w = carom.World(sleeping=False)
    w.add_body(carom.Box([20, 0.5, 20]), [0, -0.5, 0, 0, 0, 0, 1], is_static=True)
    hs = [w.add_body(carom.Box([0.3] * 3), [0, 0.3 + 0.7 * i, 0, 0, 0, 0, 1]) for i in range(20)]
    anchor = w.add_body(carom.Box([0.05] * 3), [3, 5, 0, 0, 0, 0, 1], is_static=True)
    bob = w.add_body(carom.Sphere(0.2), [3, 4, 0, 0, 0, 0, 1])
    j = w.add_joint("ball", anchor, bob, None, [0, 1, 0, 0, 0, 0, 1])
    errors: list[BaseException] = []

    def run() -> None:
        try:
            w.step(400)
        except BaseException as e:  # noqa: BLE001
            errors.append(e)

    t = threading.Thread(target=run)
    t.start()
    outcomes = []
    for victim in (hs[5], bob):
        try:
            w.remove_body(victim)
            outcomes.append("removed")
        except RuntimeError:
            outcomes.append("busy")  # the world is borrowed by the running step
    t.join()
    assert errors == []
    for victim, outcome in zip((hs[5], bob), outcomes):
        if outcome == "busy":
            w.remove_body(victim)
    assert hs[5] not in w and bob not in w and not w.has_joint(j)
    w.step(60)
    assert np.isfinite(w.poses()).all()
    assert all(w.poses([h])[0, 1] > 0 for h in hs if h != hs[5])


def test_out_of_range_ints_are_value_errors_and_bools_type_errors() -> None:
    # Session 27's sweep: pyo3 raised OverflowError (neither ValueError nor TypeError) for
    # negative or too large ints, and True was taken for body 1.
    w = carom.World()
    b = w.add_body(carom.Sphere(1.0))
    cw = carom.CollisionWorld()
    calls = [
        lambda: w.remove_body(-1),
        lambda: w.poses([2**64]),
        lambda: w.add_body(carom.Sphere(1.0), group=-1),
        lambda: w.add_body(carom.Sphere(1.0), mask=2**32),
        lambda: w.add_body(carom.Sphere(1.0), user_data=-1),
        lambda: w.step(-1),
        lambda: w.raycast([0, 0, 5], [0, 0, -1], mask=-1),
        lambda: carom.World(substeps=2**70),
        lambda: cw.add(carom.Sphere(1.0), group=-1),
        lambda: cw.remove(-1),
        lambda: carom.BroadPhase().add([0, 0, 0], [1, 1, 1], group=2**70),
    ]
    before = w.to_bytes()
    for call in calls:
        with pytest.raises(carom.CaromError, match="invalid"):
            call()
    with pytest.raises(TypeError, match="bool"):
        w.remove_body(True)
    assert w.to_bytes() == before
    assert -1 not in w and True not in w and "x" not in w and b in w


def test_rejected_velocities_change_nothing_and_huge_speeds_are_refused() -> None:
    w = carom.World(gravity=[0, -9.81, 0])
    ground = w.add_body(carom.Box([5, 0.5, 5]), [0, -0.5, 0, 0, 0, 0, 1], is_static=True)
    ball = w.add_body(carom.Sphere(0.5), [0, 2, 0, 0, 0, 0, 1])
    before = w.to_bytes()
    with pytest.raises(ValueError, match=r"handles\[1\]"):
        w.set_velocities([ball, ground], [[1, 0, 0], [1, 0, 0]], [[0, 0, 0], [0, 0, 0]])
    with pytest.raises(ValueError, match="overflows"):
        w.set_velocities([ball], [[1e25, 0, 0]], [[0, 0, 0]])
    with pytest.raises(ValueError, match="overflows"):
        w.apply_impulse(ball, [1e38, 1e38, 0], [0, 2, 0])
    with pytest.raises(ValueError, match="gravity_scale"):
        w.add_body(carom.Sphere(0.5), gravity_scale=1e30)
    assert w.to_bytes() == before
    # A speed just under the overflow is clamped to the body's limit, keeping its direction.
    w.set_velocities([ball], [[0, 0, 1e19]], [[0, 0, 0]])
    w.step()
    v = w.velocities([ball])[0][0]
    assert np.all(np.isfinite(v)) and abs(np.linalg.norm(v) - 400.0) < 0.1 and v[2] > 399.0
