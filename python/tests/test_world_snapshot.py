"""Snapshots of `carom.World`: `to_bytes()` / `World.from_bytes()` and pickling continue bit
for bit (stacked contacts with warm starts, joints, sleeping bodies, the step_simulation
accumulator); corrupt or truncated bytes raise `CaromError`."""

from __future__ import annotations

import copy
import pickle

import numpy as np
import pytest

import carom


def scene() -> carom.World:
    w = carom.World(dt=1 / 60)
    w.add_body(carom.Box([20, 0.5, 20]), [0, -0.5, 0, 0, 0, 0, 1], is_static=True)
    box = carom.Box([0.25] * 3)
    for i in range(6):
        w.add_body(box, [2, 0.25 + 0.5 * i, 0, 0, 0, 0, 1], friction=0.6)
    anchor = w.add_body(carom.Box([0.05] * 3), [0, 4, -2, 0, 0, 0, 1], is_static=True)
    prev = anchor
    for i, kind in enumerate(["hinge", "ball", "fixed"]):
        link = w.add_body(carom.Box([0.3, 0.08, 0.08]), [0.6 * (i + 1), 4, -2, 0, 0, 0, 1])
        opts = {"limits": (-0.5, 0.5)} if kind == "hinge" else {}
        w.add_joint(kind, prev, link, [0.0 if i == 0 else 0.3, 0, 0, 0, 0, 0, 1],
                    [-0.3, 0, 0, 0, 0, 0, 1], **opts)
        prev = link
    gone = w.add_body(carom.Sphere(0.2), [5, 0.2, 5, 0, 0, 0, 1])
    w.step()
    w.remove_body(gone)
    return w


def advance(w: carom.World, n: int) -> list[np.ndarray]:
    out = []
    for _ in range(n):
        w.step_simulation(1 / 50, max_sub_steps=4)
        out.append(np.concatenate([w.poses().ravel(), *[v.ravel() for v in w.velocities()]]))
    return out


def test_continuing_from_bytes_is_bit_identical() -> None:
    w = scene()
    advance(w, 90)
    assert any(w.is_sleeping(h) for h in w.handles()), "nothing sleeps yet"
    data = w.to_bytes()
    assert isinstance(data, bytes)
    r = carom.World.from_bytes(data)
    assert r.handles() == w.handles() and r.joints() == w.joints() and r.dt == w.dt
    assert r.to_bytes() == data
    for a, b in zip(advance(w, 60), advance(r, 60)):
        np.testing.assert_array_equal(a, b)
    # Wake the stack in both: warm starts matter again.
    for world in (w, r):
        world.apply_impulse(w.handles()[3], [3, 0, 0], [2, 1.0, 0])
    for a, b in zip(advance(w, 60), advance(r, 60)):
        np.testing.assert_array_equal(a, b)


def test_pickle_and_deepcopy_use_the_snapshot() -> None:
    w = scene()
    advance(w, 30)
    for clone in (lambda x: pickle.loads(pickle.dumps(x)), copy.deepcopy):
        c = clone(w)
        assert isinstance(c, carom.World) and c is not w
        for a, b in zip(advance(w, 20), advance(c, 20)):
            np.testing.assert_array_equal(a, b)


def test_corrupt_or_truncated_bytes_raise() -> None:
    w = scene()
    data = w.to_bytes()
    for cut in (0, 5, 13, 21, 40, len(data) // 2, len(data) - 1):
        with pytest.raises(carom.CaromError):
            carom.World.from_bytes(data[:cut])
    for k in range(0, len(data), max(1, len(data) // 40)):
        b = bytearray(data)
        b[k] ^= 0x5A
        with pytest.raises(carom.CaromError):
            carom.World.from_bytes(bytes(b))
    with pytest.raises(carom.CaromError, match="header"):
        carom.World.from_bytes(b"not a world at all")
    with pytest.raises(TypeError):
        carom.World.from_bytes("text")  # type: ignore[arg-type]
    v = carom.World()
    with pytest.raises(carom.CaromError):
        v.__setstate__(data[:30])
    assert len(v) == 0, "a failed restore changes nothing"


def test_restored_world_saves_the_same_bytes() -> None:
    # Saved before its first step, a world has no contact pairs yet; the restored copy's
    # rebuild made them (empty), and its bytes were longer until the next step.
    w = carom.World()
    cap = carom.Capsule(0.2, 0.3)
    w.add_body(cap, [0, 0, 0, 0, 0, 0, 1])
    w.add_body(cap, [0, 0.7, 0, 0, 0, 0, 1])
    s = w.to_bytes()
    r = carom.World.from_bytes(s)
    assert r.to_bytes() == s
    w.step()
    r.step()
    assert w.to_bytes() == r.to_bytes()
