"""Per-body options of carom.World.add_body: gravity scale, speed limits, user data."""

import numpy as np
import pytest

import carom


def _world() -> carom.World:
    return carom.World(gravity=[0, -10, 0], dt=1 / 60)


def test_gravity_scale_scales_the_free_fall() -> None:
    w = _world()
    ball = carom.Sphere(0.1)
    scales = [0.0, 1.0, 2.0, -0.5]
    hs = [
        w.add_body(ball, [3.0 * i, 100, 0, 0, 0, 0, 1], mass=1.0, gravity_scale=s)
        for i, s in enumerate(scales)
    ]
    w.step(30)
    drop = 100.0 - w.poses(hs)[:, 1]
    # Free fall is linear in g whatever the integrator: the drop scales with gravity_scale.
    assert drop[0] == 0.0
    assert drop[1] > 0.0
    np.testing.assert_allclose(drop, np.array(scales) * drop[1], rtol=1e-5, atol=1e-6)


def test_speed_limits_clamp_after_the_solve() -> None:
    w = carom.World(gravity=[0, 0, 0], dt=1 / 60)
    h = w.add_body(
        carom.Box([0.5, 0.5, 0.5]),
        [0, 0, 0, 0, 0, 0, 1],
        mass=1.0,
        linear_velocity=[30.0, 40.0, 0.0],
        angular_velocity=[0.0, 0.0, 50.0],
        max_linear_speed=10.0,
        max_angular_speed=5.0,
    )
    w.step()
    lin, ang = w.velocities([h])
    assert np.linalg.norm(lin[0]) == pytest.approx(10.0, rel=1e-5)
    np.testing.assert_allclose(lin[0] / np.linalg.norm(lin[0]), [0.6, 0.8, 0.0], atol=1e-5)
    assert np.linalg.norm(ang[0]) == pytest.approx(5.0, rel=1e-5)


def test_user_data_round_trips_and_survives_snapshots() -> None:
    w = _world()
    a = w.add_body(carom.Sphere(0.5), [0, 1, 0, 0, 0, 0, 1], user_data=2**64 - 1)
    b = w.add_body(carom.Sphere(0.5), [3, 1, 0, 0, 0, 0, 1])
    assert w.user_data(a) == 2**64 - 1
    assert w.user_data(b) == 0
    r = carom.World.from_bytes(w.to_bytes())
    assert r.user_data(a) == 2**64 - 1
    w.remove_body(a)
    with pytest.raises(carom.CaromError):
        w.user_data(a)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"gravity_scale": float("nan")},
        {"max_linear_speed": 0.0},
        {"max_linear_speed": -1.0},
        {"max_angular_speed": float("inf")},
    ],
)
def test_bad_options_raise_and_change_nothing(kwargs: dict) -> None:
    w = _world()
    with pytest.raises(carom.CaromError):
        w.add_body(carom.Sphere(0.5), [0, 1, 0, 0, 0, 0, 1], **kwargs)
    assert w.handles() == []


def test_wrong_type_is_a_type_error() -> None:
    w = _world()
    with pytest.raises(TypeError):
        w.add_body(carom.Sphere(0.5), [0, 1, 0, 0, 0, 0, 1], user_data="seven")
