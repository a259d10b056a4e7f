"""Joints of `carom.World` against physics: a pendulum on a ball joint keeps the analytic
period of a physical pendulum, a hinge holds its limits, motors reach their target speed, a
fixed joint keeps the relative pose, a cone-twist joint holds its swing, a 6-DOF joint locks
the axes it should, breakable joints break, jointed bodies do not collide when asked, a joint
to a removed body goes with it; bad input raises and changes nothing."""

from __future__ import annotations

import math

import numpy as np
import pytest

import carom

G = 9.81


def z_angle(q: np.ndarray) -> float:
    """Rotation angle about Z of a quaternion (x, y, z, w) that turns about Z only."""
    return 2.0 * math.atan2(q[2], q[3])


def anchored(dt: float = 1 / 120, gravity=(0.0, -G, 0.0)) -> tuple[carom.World, int]:
    w = carom.World(gravity=list(gravity), dt=dt, sleeping=False)
    anchor = w.add_body(carom.Box([0.05] * 3), [0, 5, 0, 0, 0, 0, 1], is_static=True)
    return w, anchor


@pytest.mark.parametrize("solver, tol", [("sequential_impulse", 0.005), ("soft_step", 0.04)])
def test_pendulum_on_a_ball_joint_keeps_its_period(solver: str, tol: float) -> None:
    length, r, theta0 = 1.0, 0.05, 0.08
    w = carom.World(gravity=[0, -G, 0], dt=1 / 120, sleeping=False, solver=solver)
    anchor = w.add_body(carom.Box([0.05] * 3), [0, 5, 0, 0, 0, 0, 1], is_static=True)
    bob_pos = [length * math.sin(theta0), 5 - length * math.cos(theta0), 0]
    bob = w.add_body(carom.Sphere(r), bob_pos + [0, 0, 0, 1], mass=1.0)
    # The joint point is the pivot: anchor origin, and pivot - bob in the bob's frame.
    w.add_joint("ball", anchor, bob, None, [-bob_pos[0], 5 - bob_pos[1], 0, 0, 0, 0, 1])
    xs = []
    for _ in range(int(6.0 / w.dt)):
        w.step()
        xs.append(w.poses([bob])[0, 0])
    xs = np.array(xs)
    # Times of upward zero crossings, linearly interpolated.
    idx = np.nonzero((xs[:-1] < 0) & (xs[1:] >= 0))[0]
    t = (idx + 1 + (-xs[idx]) / (xs[idx + 1] - xs[idx])) * w.dt
    assert len(t) >= 2, "the pendulum does not swing"
    period = float(np.mean(np.diff(t)))
    # Physical pendulum: T = 2π √(I_pivot / (m g L)), I_pivot = 2/5 m r² + m L².
    analytic = 2 * math.pi * math.sqrt((0.4 * r * r + length * length) / (G * length))
    # Sequential impulses: 0.04 % off. The default soft step's 60 Hz soft joints make it
    # 3.4 % long at every dt from 1/60 to 1/480 s (0.3 % at 240 Hz), hence its bound.
    assert period == pytest.approx(analytic, rel=tol)
    assert period == pytest.approx(2 * math.pi * math.sqrt(length / G), rel=tol + 0.001)
    # The bob stays on the sphere of radius L about the pivot.
    p = w.poses([bob])[0, :3]
    assert np.linalg.norm(p - [0, 5, 0]) == pytest.approx(length, abs=0.01)


def test_hinge_holds_its_limits() -> None:
    w, anchor = anchored()
    # A bar along +X, hinged at its left end about Z; gravity turns it clockwise (negative).
    bar = w.add_body(carom.Box([0.5, 0.05, 0.05]), [0.5, 5, 0, 0, 0, 0, 1], mass=2.0)
    j = w.add_joint(
        "hinge", anchor, bar, None, [-0.5, 0, 0, 0, 0, 0, 1], limits=(-0.3, 0.5)
    )
    angles = []
    for _ in range(240):
        w.step()
        angles.append(z_angle(w.poses([bar])[0, 3:]))
    assert min(angles) > -0.3 - 0.03, min(angles)
    assert angles[-1] == pytest.approx(-0.3, abs=0.03)
    # The pivot end stays at the anchor.
    pose = carom.Pose(w.poses([bar])[0, :3], w.poses([bar])[0, 3:])
    end = pose.transform_points([-0.5, 0, 0])
    np.testing.assert_allclose(end, [0, 5, 0], atol=0.01)
    assert not w.is_joint_broken(j)
    assert w.joint_bodies(j) == (anchor, bar)


@pytest.mark.parametrize("kind", ["hinge", "slider"])
def test_motor_reaches_its_target_speed(kind: str) -> None:
    w, anchor = anchored(gravity=(0, 0, 0))
    body = w.add_body(carom.Box([0.3, 0.3, 0.3]), [0, 5, 0, 0, 0, 0, 1], mass=3.0)
    w.add_joint(kind, anchor, body, motor=(2.0, 500.0))
    for _ in range(60):
        w.step()
    lin, ang = w.velocities([body])
    if kind == "hinge":
        assert abs(ang[0, 2]) == pytest.approx(2.0, rel=0.02)
        assert np.linalg.norm(ang[0, :2]) < 1e-3 and np.linalg.norm(lin) < 1e-2
    else:
        assert abs(lin[0, 0]) == pytest.approx(2.0, rel=0.02)
        assert np.linalg.norm(lin[0, 1:]) < 1e-3 and np.linalg.norm(ang) < 1e-3


def test_weak_motor_is_limited_by_its_force() -> None:
    # Torque τ on inertia I from rest: ω = τ t / I until the target speed.
    w, anchor = anchored(gravity=(0, 0, 0))
    body = w.add_body(carom.Sphere(0.5), [0, 5, 0, 0, 0, 0, 1], mass=2.0)
    inertia = 0.4 * 2.0 * 0.25
    w.add_joint("hinge", anchor, body, motor=(50.0, 0.1))
    n = 30
    w.step(n)
    _, ang = w.velocities([body])
    assert abs(ang[0, 2]) == pytest.approx(0.1 * n * w.dt / inertia, rel=0.05)


def test_fixed_joint_keeps_the_relative_pose() -> None:
    w = carom.World(gravity=[0, -G, 0], dt=1 / 60, sleeping=False)
    w.add_body(carom.Box([20, 0.5, 20]), [0, -0.5, 0, 0, 0, 0, 1], is_static=True)
    a = w.add_body(carom.Box([0.3] * 3), [0, 2, 0, 0, 0, 0, 1])
    b = w.add_body(carom.Box([0.2] * 3), [0.6, 2.3, 0, 0, 0, 0, 1])
    w.add_joint("fixed", a, b, [0.3, 0.15, 0, 0, 0, 0, 1], [-0.3, -0.15, 0, 0, 0, 0, 1])
    w.apply_impulse(a, [30, 60, -20], [0.1, 2.2, 0.2])
    def relative() -> carom.Pose:
        pa, pb = w.poses([a, b])
        return carom.Pose(pa[:3], pa[3:]).inverse() * carom.Pose(pb[:3], pb[3:])
    start = relative()
    worst_d, worst_a = 0.0, 0.0
    for _ in range(180):
        w.step()
        rel = relative()
        worst_d = max(worst_d, float(np.linalg.norm(rel.position - start.position)))
        dq = abs(float(np.dot(rel.rotation, start.rotation)))
        worst_a = max(worst_a, 2 * math.acos(min(1.0, dq)))
    # Soft joints (60 Hz) give a little under impacts: measured 1.9 cm and 0.013 rad at most.
    assert worst_d < 0.025 and worst_a < 0.02, (worst_d, worst_a)
    # It tumbled and landed: the test moved something.
    assert w.poses([a])[0, 1] < 1.0


def test_cone_twist_holds_its_swing() -> None:
    w, anchor = anchored()
    # Twist axis X along the bar; gravity swings it down about Z, held at swing1 = 0.4.
    bar = w.add_body(carom.Box([0.5, 0.05, 0.05]), [0.5, 5, 0, 0, 0, 0, 1], mass=1.0)
    w.add_joint(
        "cone_twist", anchor, bar, None, [-0.5, 0, 0, 0, 0, 0, 1], swing1=0.4, swing2=0.4, twist=0.1
    )
    tilt = []
    for _ in range(240):
        w.step()
        p = w.poses([bar])[0]
        axis = carom.Pose(p[:3], p[3:]).transform_vectors([1, 0, 0])
        tilt.append(math.asin(max(-1.0, min(1.0, -axis[1]))))
    assert max(tilt) < 0.4 + 0.04, max(tilt)
    assert tilt[-1] == pytest.approx(0.4, abs=0.04)


def test_6dof_locks_and_frees_the_axes_it_is_told() -> None:
    w, anchor = anchored(gravity=(0, -G, 0))
    body = w.add_body(carom.Box([0.2] * 3), [0, 5, 0, 0, 0, 0, 1], mass=1.0)
    # Only X translation free (limited to ±0.5), everything else locked: gravity holds no sway.
    j = w.add_joint(
        "6dof", anchor, body, linear=[(-0.5, 0.5), "locked", "locked"], angular=["locked"] * 3
    )
    w.apply_impulse(body, [3.0, 0, 2.0], [0, 5, 0])
    xs = []
    for _ in range(120):
        w.step()
        xs.append(w.poses([body])[0, 0])
    p = w.poses([body])[0]
    assert abs(p[1] - 5) < 0.01 and abs(p[2]) < 0.01
    assert max(xs) == pytest.approx(0.5, abs=0.03) and max(xs) < 0.53
    assert w.has_joint(j)
    # A spring on Y pulls the body back to rest = 0 (a damped oscillation about the anchor).
    w2, anchor2 = anchored(gravity=(0, 0, 0))
    b2 = w2.add_body(carom.Box([0.2] * 3), [0, 5.3, 0, 0, 0, 0, 1], mass=1.0)
    w2.add_joint(
        "6dof",
        anchor2,
        b2,
        linear=["locked", {"limits": "free", "spring": (2.0, 1.0, 0.0)}, "locked"],
        angular=["locked"] * 3,
    )
    w2.step(240)
    assert w2.poses([b2])[0, 1] == pytest.approx(5.0, abs=0.01)


def test_breakable_joint_breaks_and_lets_go() -> None:
    w, anchor = anchored()
    heavy = w.add_body(carom.Sphere(0.2), [0, 4, 0, 0, 0, 0, 1], mass=50.0)
    strong = w.add_body(carom.Sphere(0.2), [2, 4, 0, 0, 0, 0, 1], mass=50.0)
    anchor2 = w.add_body(carom.Box([0.05] * 3), [2, 5, 0, 0, 0, 0, 1], is_static=True)
    weak = w.add_joint("ball", anchor, heavy, None, [0, 1, 0, 0, 0, 0, 1], break_impulse=0.5)
    keep = w.add_joint("ball", anchor2, strong, None, [0, 1, 0, 0, 0, 0, 1])
    w.step(60)
    assert w.is_joint_broken(weak) and not w.is_joint_broken(keep)
    assert w.poses([heavy])[0, 1] < 3.5, "the broken joint still holds"
    assert w.poses([strong])[0, 1] == pytest.approx(4.0, abs=0.01)


def test_jointed_bodies_do_not_collide_unless_asked() -> None:
    for disable in (True, False):
        w = carom.World(gravity=[0, 0, 0], sleeping=False)
        a = w.add_body(carom.Box([0.5] * 3), [0, 0, 0, 0, 0, 0, 1])
        b = w.add_body(carom.Box([0.5] * 3), [0.8, 0, 0, 0, 0, 0, 1])
        w.add_joint("ball", a, b, [0.4, 0, 0, 0, 0, 0, 1], [-0.4, 0, 0, 0, 0, 0, 1],
                    disable_collisions=disable)
        w.step()
        pairs = {tuple(sorted(p)) for p in w.contacts().bodies.tolist()}
        assert (tuple(sorted((a, b))) in pairs) == (not disable)


def test_joint_to_a_removed_body_is_removed_and_the_world_stays_sound() -> None:
    w, anchor = anchored()
    links = [
        w.add_body(carom.Box([0.2, 0.05, 0.05]), [0.4 * i + 0.2, 5, 0, 0, 0, 0, 1], mass=1.0)
        for i in range(4)
    ]
    joints = [w.add_joint("ball", anchor, links[0], None, [-0.2, 0, 0, 0, 0, 0, 1])]
    for p, q in zip(links, links[1:]):
        joints.append(w.add_joint("ball", p, q, [0.2, 0, 0, 0, 0, 0, 1], [-0.2, 0, 0, 0, 0, 0, 1]))
    w.step(20)
    w.remove_body(links[2])
    assert not w.has_joint(joints[2]) and not w.has_joint(joints[3])
    assert w.joints() == joints[:2]
    with pytest.raises(ValueError):
        w.is_joint_broken(joints[2])
    with pytest.raises(ValueError):
        w.remove_joint(joints[3])
    # A new body may take the freed slot; the stale joint never comes back to life.
    fresh = w.add_body(carom.Sphere(0.1), [5, 5, 0, 0, 0, 0, 1])
    assert not w.has_joint(joints[2])
    w.step(60)
    poses = w.poses()
    assert np.isfinite(poses).all()
    # Links 0-1 still hang from the anchor; link 3 and the fresh body fall freely.
    p0 = w.poses([links[0]])[0]
    end = carom.Pose(p0[:3], p0[3:]).transform_points([-0.2, 0, 0])
    np.testing.assert_allclose(end, [0, 5, 0], atol=0.02)
    assert w.poses([links[3]])[0, 1] < 4.0 and w.poses([fresh])[0, 1] < 4.0
    w.remove_joint(joints[1])
    assert w.joints() == joints[:1]


def test_bad_solver_name_raises() -> None:
    with pytest.raises(ValueError, match="solver"):
        carom.World(solver="magic")


def test_bad_joint_input_raises_and_changes_nothing() -> None:
    w, anchor = anchored()
    b = w.add_body(carom.Sphere(0.2), [0, 4, 0, 0, 0, 0, 1])
    s = w.add_body(carom.Sphere(0.2), [3, 4, 0, 0, 0, 0, 1], is_static=True)
    bad = [
        (dict(kind="rope"), "kind"),
        (dict(kind="ball", limits=(0, 1)), "limits"),
        (dict(kind="hinge", swing1=0.3), "swing1"),
        (dict(kind="cone_twist", swing1=0.3, swing2=0.3), "twist"),
        (dict(kind="cone_twist", swing1=-0.3, swing2=0.3, twist=0.1), "swing1"),
        (dict(kind="hinge", limits=(1.0, -1.0)), "limits"),
        (dict(kind="hinge", limits=(0.0, math.nan)), "limits"),
        (dict(kind="slider", motor=(1.0, -5.0)), "max_force"),
        (dict(kind="6dof", linear=["free", "free"]), "linear"),
        (dict(kind="6dof", angular=["free", "wobbly", "free"]), "angular"),
        (dict(kind="6dof", linear=[{"stiffness": 1}, "free", "free"]), "stiffness"),
        (dict(kind="ball", break_impulse=0.0), "break_impulse"),
        (dict(kind="ball", frame_a=[0, math.nan, 0, 0, 0, 0, 1]), "frame_a"),
    ]
    for kw, name in bad:
        kind = kw.pop("kind")
        with pytest.raises(ValueError, match=name):
            w.add_joint(kind, anchor, b, **kw)
    with pytest.raises(ValueError, match="body"):
        w.add_joint("ball", b, b)
    with pytest.raises(ValueError, match="dynamic"):
        w.add_joint("ball", anchor, s)
    with pytest.raises(ValueError):
        w.add_joint("ball", anchor, 12345)
    with pytest.raises(TypeError):
        w.add_joint("6dof", anchor, b, linear=[1, 2, 3])
    with pytest.raises(ValueError):
        w.remove_joint(99)
    assert w.joints() == []
    w.step(5)
    assert np.isfinite(w.poses()).all()
