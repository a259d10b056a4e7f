"""Solver options of carom.World: substeps, iterations, SIMD lanes and threads."""

import numpy as np
import pytest

import carom

G = 10.0
DT = 1.0 / 60.0


@pytest.mark.parametrize("substeps", [1, 2, 4, 7])
def test_substeps_follow_the_semi_implicit_free_fall(substeps: int) -> None:
    # n substeps of h = dt/n of semi-implicit Euler drop a body by g·dt²·(n+1)/(2n) in one
    # step (velocity first, then position, each substep): the oracle sees the substep count.
    w = carom.World(gravity=[0, -G, 0], dt=DT, substeps=substeps, sleeping=False)
    h = w.add_body(carom.Sphere(0.1), [0, 0, 0, 0, 0, 0, 1], mass=1.0)
    w.step()
    drop = -w.poses([h])[0, 1]
    expected = G * DT * DT * (substeps + 1) / (2 * substeps)
    assert drop == pytest.approx(expected, rel=1e-4)


def _stack(**options: object) -> tuple[carom.World, list[int]]:
    w = carom.World(gravity=[0, -G, 0], dt=DT, sleeping=False, **options)
    w.add_body(carom.Box([20, 0.5, 20]), [0, -0.5, 0, 0, 0, 0, 1], is_static=True)
    hs = [
        w.add_body(carom.Box([0.5, 0.5, 0.5]), [0.01 * i, 0.5 + i, 0, 0, 0, 0, 1], mass=1.0)
        for i in range(6)
    ]
    return w, hs


@pytest.mark.parametrize("solver", ["soft_step", "sequential_impulse"])
def test_threads_do_not_change_the_result(solver: str) -> None:
    a, ha = _stack(solver=solver, parallel=True)
    b, hb = _stack(solver=solver, parallel=False)
    c, hc = _stack(solver=solver, parallel=True, spin_workers=False)
    a.step(90)
    b.step(90)
    c.step(90)
    np.testing.assert_array_equal(a.poses(ha), b.poses(hb))
    np.testing.assert_array_equal(a.poses(ha), c.poses(hc))


def test_simd_and_scalar_contacts_hold_the_same_stack() -> None:
    runs = {}
    for simd in (True, False):
        w, hs = _stack(simd=simd)
        w.step(120)
        runs[simd] = w.poses(hs)
    # Same physics, different float order: both stacks stand, at the same heights.
    for poses in runs.values():
        np.testing.assert_allclose(poses[:, 1], 0.5 + np.arange(6), atol=0.02)
    np.testing.assert_allclose(runs[True], runs[False], atol=1e-3)


def test_more_iterations_hold_a_sequential_impulse_stack_better() -> None:
    sink = {}
    for iterations in (1, 30):
        w, hs = _stack(solver="sequential_impulse", iterations=iterations)
        w.step(120)
        sink[iterations] = float(np.max(np.abs(w.poses(hs)[:, 1] - (0.5 + np.arange(6)))))
    assert sink[30] < 0.02
    assert sink[30] <= sink[1]


@pytest.mark.parametrize(
    ("name", "value"),
    [
        ("substeps", 0),
        ("substeps", 1001),
        ("substeps", -1),
        ("iterations", 0),
        ("iterations", 5000),
        ("iterations", -3),
    ],
)
def test_bad_effort_is_rejected_by_name(name: str, value: int) -> None:
    with pytest.raises(carom.CaromError, match=name):
        carom.World(**{name: value})


def test_non_integer_effort_is_a_type_error() -> None:
    with pytest.raises(TypeError):
        carom.World(substeps=2.5)  # type: ignore[arg-type]
