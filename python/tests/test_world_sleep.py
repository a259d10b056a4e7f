"""Sleep settings of carom.World: the velocity thresholds, the drift rule and the rest time."""

from __future__ import annotations

import math

import pytest

import carom

DT = 1.0 / 60.0


def _drifter(speed: float, **sleep: float) -> tuple[carom.World, int]:
    # A box gliding through empty space (no gravity, no damping) at `speed` m/s.
    w = carom.World(gravity=[0, 0, 0], dt=DT, **sleep)
    h = w.add_body(carom.Box([0.5, 0.5, 0.5]), [0, 0, 0, 0, 0, 0, 1], mass=1.0)
    w.set_velocities([h], [[speed, 0, 0]], [[0, 0, 0]])
    return w, h


def _steps_to_sleep(w: carom.World, h: int, limit: int = 240) -> int | None:
    for k in range(limit):
        w.step()
        if w.is_sleeping(h):
            return k
    return None


def test_a_slow_body_sleeps_after_the_rest_time() -> None:
    # 0.04 m/s is under the 0.05 m/s threshold: at rest from the first step, asleep once
    # 0.5 s (30 steps) or the chosen rest time has passed.
    w, h = _drifter(0.04)
    assert _steps_to_sleep(w, h) in (29, 30)
    w, h = _drifter(0.04, sleep_time=1.0)
    assert _steps_to_sleep(w, h) in (59, 60)


def test_the_drift_rule_lets_a_body_rest_while_it_stays_near() -> None:
    # Under a 0.01 m/s threshold the 0.04 m/s body is not slow. It travels 2 cm in 0.5 s:
    # more than the default drift of 1.5 cm, so it never rests; within a drift of 5 cm it
    # rests from the first step.
    w, h = _drifter(0.04, sleep_linear=0.01)
    assert _steps_to_sleep(w, h) is None
    w, h = _drifter(0.04, sleep_linear=0.01, sleep_drift=0.05)
    assert _steps_to_sleep(w, h) in (29, 30)
    w, h = _drifter(0.04, sleep_linear=0.01, sleep_drift=0.0)
    assert _steps_to_sleep(w, h) is None


def test_a_resting_box_sleeps_and_its_pose_stays() -> None:
    w = carom.World(gravity=[0, -10, 0], dt=DT, sleep_time=0.25)
    w.add_body(carom.Box([5, 0.5, 5]), [0, -0.5, 0, 0, 0, 0, 1], is_static=True)
    h = w.add_body(carom.Box([0.5, 0.5, 0.5]), [0, 0.5, 0, 0, 0, 0, 1], mass=1.0)
    k = _steps_to_sleep(w, h)
    assert k is not None and k >= 14
    assert abs(w.poses([h])[0, 1] - 0.5) < 0.015


@pytest.mark.parametrize(
    "name", ["sleep_linear", "sleep_angular", "sleep_drift", "sleep_time"]
)
@pytest.mark.parametrize("value", [-0.1, math.nan, math.inf])
def test_bad_sleep_settings_are_rejected_by_name(name: str, value: float) -> None:
    with pytest.raises(ValueError, match=name):
        carom.World(**{name: value})
