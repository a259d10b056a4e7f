"""Broadphase bindings (`carom.overlapping_pairs`, `carom.BroadPhase`) against a numpy
brute-force all-pairs oracle: random scenes with uniform and wildly mixed sizes, far from the
origin, zero-extent and touching boxes; many frames of motion with adds and removes; filters;
stale handles and bad input."""

from __future__ import annotations

import zlib

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import carom

METHODS = ["tree", "tree_manhattan", "sap", "sort_sweep", "grid", "hgrid", "brute_force"]


def seed(*parts: str) -> int:
    """A per-test seed stable across runs (unlike `hash`, which Python randomises)."""
    return zlib.crc32("/".join(parts).encode())


def exact(a: np.ndarray) -> np.ndarray:
    """Values exactly representable in the build's precision, so that numpy's float64
    comparisons decide every overlap the same way as Carom's."""
    return np.asarray(a, dtype=np.float32 if carom.REAL_BITS == 32 else np.float64).astype(np.float64)


def brute_pairs(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """All (i, j), i < j, of overlapping boxes (touching included), sorted: the oracle."""
    n = len(lo)
    if n < 2:
        return np.zeros((0, 2), dtype=np.int64)
    ov = np.all((lo[:, None, :] <= hi[None, :, :]) & (lo[None, :, :] <= hi[:, None, :]), axis=2)
    i, j = np.nonzero(np.triu(ov, k=1))
    return np.stack([i, j], axis=1).astype(np.int64)


def random_boxes(rng: np.random.Generator, n: int, kind: str) -> tuple[np.ndarray, np.ndarray]:
    if kind == "uniform":
        c = rng.uniform(-20, 20, size=(n, 3))
        h = rng.uniform(0.5, 2.0, size=(n, 3))
    elif kind == "mixed":  # half extents 1e-3 .. 1e3
        c = rng.uniform(-2000, 2000, size=(n, 3))
        h = 10.0 ** rng.uniform(-3, 3, size=(n, 1)) * rng.uniform(0.5, 1.0, size=(n, 3))
    elif kind == "far":
        c = np.array([1.0e5, -3.0e5, 2.0e5]) + rng.uniform(-50, 50, size=(n, 3))
        h = rng.uniform(0.5, 4.0, size=(n, 3))
    elif kind == "degenerate":  # integer lattice: zero extents, touching faces and corners
        c = rng.integers(-4, 5, size=(n, 3)).astype(float)
        h = rng.integers(0, 2, size=(n, 3)) * 0.5
        h[rng.random(n) < 0.3] = 0.0
    else:
        raise ValueError(kind)
    return exact(c - h), exact(c + h)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("kind", ["uniform", "mixed", "far", "degenerate"])
def test_overlapping_pairs_matches_brute_force(method: str, kind: str) -> None:
    rng = np.random.default_rng(seed(method, kind))
    for n in (0, 1, 2, 50, 400):
        lo, hi = random_boxes(rng, n, kind)
        got = carom.overlapping_pairs(lo, hi, method=method)
        assert got.dtype == np.int64 and got.shape[1] == 2
        np.testing.assert_array_equal(got, brute_pairs(lo, hi))


def test_overlapping_pairs_large_batch_all_methods_agree() -> None:
    # Large enough for the parallel radix sort and sweeps (the GIL is released).
    rng = np.random.default_rng(3)
    c, h = rng.uniform(-150, 150, size=(20000, 3)), rng.uniform(0.5, 4.0, size=(20000, 3))
    lo, hi = exact(c - h), exact(c + h)
    ref = carom.overlapping_pairs(lo, hi, method="hgrid")
    assert len(ref) > 1000
    # The pairs among the first 1500 boxes are the brute-force pairs of those boxes.
    sub = ref[ref[:, 1] < 1500]
    np.testing.assert_array_equal(sub, brute_pairs(lo[:1500], hi[:1500]))
    for m in ("tree", "sap", "sort_sweep", "grid"):
        np.testing.assert_array_equal(carom.overlapping_pairs(lo, hi, method=m), ref)
    # Sorted lexicographically, i < j.
    assert np.all(ref[:, 0] < ref[:, 1])
    keys = ref[:, 0] * 20000 + ref[:, 1]
    assert np.all(np.diff(keys) > 0)


box_arrays = st.integers(0, 40).flatmap(
    lambda n: st.tuples(
        hnp.arrays(np.float64, (n, 3), elements=st.integers(-6, 6).map(float)),
        hnp.arrays(np.float64, (n, 3), elements=st.sampled_from([0.0, 0.5, 1.0, 2.0, 1e-3, 30.0])),
    )
)


@settings(max_examples=60, deadline=None)
@given(boxes=box_arrays, method=st.sampled_from(METHODS[:-1]))
def test_overlapping_pairs_property(boxes: tuple[np.ndarray, np.ndarray], method: str) -> None:
    c, h = boxes
    lo, hi = exact(c - h), exact(c + h)
    np.testing.assert_array_equal(carom.overlapping_pairs(lo, hi, method=method), brute_pairs(lo, hi))


def pair_set(a: np.ndarray) -> set[tuple[int, int]]:
    return {(int(x), int(y)) for x, y in a}


def check_against_oracle(bp: carom.BroadPhase, boxes: dict[int, tuple[np.ndarray, np.ndarray]]) -> set:
    handles = sorted(boxes)
    lo = np.array([boxes[h][0] for h in handles]).reshape(-1, 3)
    hi = np.array([boxes[h][1] for h in handles]).reshape(-1, 3)
    return {tuple(sorted((handles[i], handles[j]))) for i, j in brute_pairs(lo, hi)}


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("kind", ["uniform", "mixed", "degenerate"])
def test_broadphase_frames_match_brute_force(method: str, kind: str) -> None:
    rng = np.random.default_rng(seed(method, kind, "frames"))
    bp = carom.BroadPhase(method)
    assert bp.method == method
    lo, hi = random_boxes(rng, 120, kind)
    hs = bp.add(lo, hi)
    boxes = {int(h): (lo[i], hi[i]) for i, h in enumerate(hs)}
    tracked: set[tuple[int, int]] = set()
    for frame in range(25):
        added, removed = bp.update_pairs()
        assert pair_set(added).isdisjoint(tracked)
        assert pair_set(removed) <= tracked
        tracked = (tracked - pair_set(removed)) | pair_set(added)
        truth = check_against_oracle(bp, boxes)
        assert tracked == truth, f"frame {frame}"
        assert pair_set(bp.pairs()) == truth
        assert len(bp) == len(boxes)
        # Move a random subset (with a predicted displacement for the trees).
        live = np.array(sorted(boxes), dtype=np.int64)
        moving = rng.choice(live, size=len(live) // 2, replace=False)
        new_lo, new_hi = random_boxes(rng, len(moving), kind)
        step = exact(rng.normal(scale=0.5, size=(len(moving), 3)))
        cur_lo = np.array([boxes[int(h)][0] for h in moving])
        cur_hi = np.array([boxes[int(h)][1] for h in moving])
        # Half the moving boxes jump, half drift.
        jump = rng.random(len(moving)) < 0.5
        nl = exact(np.where(jump[:, None], new_lo, cur_lo + step))
        nh = exact(np.where(jump[:, None], new_hi, np.maximum(cur_hi + step, nl)))
        bp.update(moving, nl, nh, displacement=step)
        for k, h in enumerate(moving):
            boxes[int(h)] = (nl[k], nh[k])
        # Remove a few, add a few (slots are reused after the update).
        gone = rng.choice(sorted(boxes), size=3, replace=False)
        bp.remove(np.array(gone))
        for h in gone:
            del boxes[int(h)]
        alo, ahi = random_boxes(rng, 4, kind)
        for k in range(4):
            h = bp.add(alo[k], ahi[k])
            assert isinstance(h, int)
            boxes[h] = (alo[k], ahi[k])
        if method in ("tree", "tree_manhattan") and frame % 5 == 2:
            for h in rng.choice(sorted(boxes), size=10, replace=False):
                bp.set_resting(int(h), bool(rng.random() < 0.7))


@pytest.mark.parametrize("method", METHODS)
def test_filters_and_static(method: str) -> None:
    bp = carom.BroadPhase(method)
    z, o = np.zeros(3), np.ones(3)
    a = bp.add(z, o, group=0b01, mask=0b10)
    b = bp.add(z, o, group=0b10, mask=0b01)
    c = bp.add(z, o, group=0b01, mask=0b01)  # pairs with the static d and e only
    d = bp.add(z, o, group=0b01, mask=0xFFFFFFFF, is_static=True)
    e = bp.add(z, o, group=0b01, mask=0xFFFFFFFF, is_static=True)
    added, removed = bp.update_pairs()
    expected = {tuple(sorted(p)) for p in [(a, b), (b, d), (b, e), (c, d), (c, e), (a, c)]}
    # Not a-c (c.group & a.mask = 0), a-d/a-e (d.group & a.mask = 0), b-c, d-e (both static).
    expected -= {tuple(sorted((a, c)))}
    assert pair_set(added) == expected and len(removed) == 0
    bp.set_filter(b, group=0, mask=0)
    added, removed = bp.update_pairs()
    assert len(added) == 0
    assert pair_set(removed) == {p for p in expected if b in p}
    assert bp.aabb(a)[1].tolist() == [1.0, 1.0, 1.0]
    assert a in bp and 12345678 not in bp


def test_stale_handles_rejected() -> None:
    bp = carom.BroadPhase("hgrid")
    h0 = bp.add([0, 0, 0], [1, 1, 1])
    h1 = bp.add([0.5, 0.5, 0.5], [2, 2, 2])
    assert pair_set(bp.update_pairs()[0]) == {(min(h0, h1), max(h0, h1))}
    bp.remove(h0)
    with pytest.raises(carom.CaromError, match="unknown handle"):
        bp.remove(h0)
    added, removed = bp.update_pairs()
    assert pair_set(removed) == {(min(h0, h1), max(h0, h1))} and len(added) == 0
    h2 = bp.add([0, 0, 0], [1, 1, 1])  # reuses h0's slot with a new generation
    assert h2 != h0
    for bad in (h0, -1, 2**40, np.array([h1, h0])):
        with pytest.raises(carom.CaromError):
            bp.update(bad, np.zeros((np.size(bad), 3)) if np.ndim(bad) else [0, 0, 0],
                      np.ones((np.size(bad), 3)) if np.ndim(bad) else [1, 1, 1])
    with pytest.raises(carom.CaromError):
        bp.set_resting(h0, True)
    with pytest.raises(carom.CaromError, match="twice"):
        bp.remove([h1, h1])
    assert len(bp) == 2  # nothing was removed by the failed calls


def test_bad_input() -> None:
    nan = [np.nan, 0, 0]
    for f in (lambda lo, hi: carom.overlapping_pairs(lo, hi), lambda lo, hi: carom.BroadPhase().add(lo, hi)):
        with pytest.raises(carom.CaromError, match="finite"):
            f([nan], [[1, 1, 1]])
        with pytest.raises(carom.CaromError, match="inverted"):
            f([[0, 2, 0]], [[1, 1, 1]])
        with pytest.raises(carom.CaromError, match="shape"):
            f(np.zeros((2, 2)), np.zeros((2, 2)))
        with pytest.raises(carom.CaromError, match="same shape"):
            f(np.zeros((2, 3)), np.zeros((3, 3)))
        with pytest.raises(TypeError):
            f("abc", [[1, 1, 1]])
        with pytest.raises(carom.CaromError):
            f([[0, 0, 0]], [[np.inf, 1, 1]])
    with pytest.raises(carom.CaromError, match="method"):
        carom.overlapping_pairs(np.zeros((1, 3)), np.ones((1, 3)), method="octree")
    with pytest.raises(ValueError, match="method"):
        carom.BroadPhase("quadtree")
    bp = carom.BroadPhase("sap")
    h = bp.add([0, 0, 0], [1, 1, 1])
    with pytest.raises(carom.CaromError, match="group"):
        bp.add([0, 0, 0], [1, 1, 1], group=-1)
    with pytest.raises(carom.CaromError, match="mask"):
        bp.add([0, 0, 0], [1, 1, 1], mask=2**32)
    with pytest.raises(TypeError):
        bp.remove(True)
    with pytest.raises(TypeError):
        bp.remove(np.array([0.5]))
    with pytest.raises(TypeError):
        bp.remove("x")
    with pytest.raises(carom.CaromError):
        bp.update(h, [0, 0, 0], [1, 1, np.nan])
    with pytest.raises(carom.CaromError, match="match"):
        bp.update(np.array([h]), [0, 0, 0], [1, 1, 1])
    with pytest.raises(carom.CaromError):
        bp.update(h, [0, 0, 0], [1, 1, 1], displacement=[np.nan, 0, 0])
    assert bp.aabb(h)[0].tolist() == [0.0, 0.0, 0.0]  # unchanged by the failed updates
    assert "sap" in repr(bp)
