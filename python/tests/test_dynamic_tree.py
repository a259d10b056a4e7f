"""`carom.DynamicTree` against numpy brute force: box queries, ray casts (all hits and
closest, slab-test oracle), frustum culling (per-plane box test), the tree invariant checker
after every operation, stale handles and bad input."""

from __future__ import annotations

import numpy as np
import pytest

import carom

from test_broadphase import exact, random_boxes


def slab_entry(lo: np.ndarray, hi: np.ndarray, o: np.ndarray, d: np.ndarray, tmax: float) -> np.ndarray:
    """Entry fraction of the ray o + t d, t in [0, tmax], into each box (NaN on a miss)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t1, t2 = (lo - o) / d, (hi - o) / d
    near, far = np.minimum(t1, t2), np.maximum(t1, t2)
    # Axes where the ray is parallel: inside the slab -> no constraint, outside -> miss.
    par = d == 0
    inside = (lo <= o) & (o <= hi)
    near = np.where(par, np.where(inside, -np.inf, np.inf), near)
    far = np.where(par, np.where(inside, np.inf, -np.inf), far)
    t0, t1 = np.maximum(near.max(axis=1), 0.0), np.minimum(far.min(axis=1), tmax)
    return np.where(t0 <= t1, t0, np.nan)


class Model:
    """The tree plus the boxes it should hold, by handle."""

    def __init__(self, strategy: str, margin: float) -> None:
        self.tree = carom.DynamicTree(margin=margin, strategy=strategy)
        self.boxes: dict[int, tuple[np.ndarray, np.ndarray]] = {}

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        hs = np.array(sorted(self.boxes), dtype=np.int64)
        lo = np.array([self.boxes[h][0] for h in hs]).reshape(-1, 3)
        hi = np.array([self.boxes[h][1] for h in hs]).reshape(-1, 3)
        return hs, lo, hi


@pytest.mark.parametrize("strategy", ["sah", "manhattan"])
@pytest.mark.parametrize("kind", ["uniform", "mixed", "far", "degenerate"])
def test_tree_queries_match_brute_force(strategy: str, kind: str) -> None:
    rng = np.random.default_rng(len(kind) * 7 + len(strategy))
    m = Model(strategy, margin=0.05 if kind != "mixed" else 1.0)
    lo, hi = random_boxes(rng, 150, kind)
    for h, a, b in zip(m.tree.insert(lo, hi), lo, hi):
        m.boxes[int(h)] = (a, b)
    m.tree.validate()
    for step in range(30):
        op = rng.integers(0, 3)
        live = sorted(m.boxes)
        if op == 0:  # insert one
            a, b = random_boxes(rng, 1, kind)
            h = m.tree.insert(a[0], b[0])
            assert isinstance(h, int) and h not in m.boxes
            m.boxes[h] = (a[0], b[0])
        elif op == 1 and len(live) > 10:  # remove a few
            gone = rng.choice(live, size=3, replace=False)
            m.tree.remove(gone)
            for h in gone:
                del m.boxes[int(h)]
        else:  # move a batch, some far, some by a small step
            moving = rng.choice(live, size=20, replace=False)
            a, b = random_boxes(rng, 20, kind)
            small = rng.random(20) < 0.5
            d = exact(rng.normal(scale=0.1, size=(20, 3)))
            cur_lo = np.array([m.boxes[int(h)][0] for h in moving])
            cur_hi = np.array([m.boxes[int(h)][1] for h in moving])
            a = exact(np.where(small[:, None], cur_lo + d, a))
            b = exact(np.where(small[:, None], np.maximum(cur_hi + d, a), b))
            m.tree.update(moving, a, b, displacement=d)
            for k, h in enumerate(moving):
                m.boxes[int(h)] = (a[k], b[k])
        m.tree.validate()
        assert len(m.tree) == len(m.boxes)
        hs, blo, bhi = m.arrays()
        # Box query.
        qa, qb = random_boxes(rng, 1, kind)
        want = hs[np.all((blo <= qb[0]) & (qa[0] <= bhi), axis=1)]
        np.testing.assert_array_equal(m.tree.query_aabb(qa[0], qb[0]), want)
        # Ray casts: all hits and closest.
        center = (blo + bhi).mean(axis=0) / 2
        o = exact(center + rng.normal(scale=np.abs(bhi - blo).max() + 1, size=3))
        d = exact(center - o + rng.normal(size=3))
        if step % 5 == 0:
            d[rng.integers(0, 3)] = 0.0  # axis-parallel slabs
        t = slab_entry(blo, bhi, o, d, 1.5)
        got_h, got_t = m.tree.raycast(o, d, max_fraction=1.5)
        hit = ~np.isnan(t)
        assert set(got_h.tolist()) == set(hs[hit].tolist())
        np.testing.assert_allclose(
            got_t, np.sort(t[hit]), rtol=1e-4 if carom.REAL_BITS == 32 else 1e-9, atol=1e-9
        )
        assert np.all(np.diff(got_t) >= 0)
        ch, ct = m.tree.raycast(o, d, max_fraction=1.5, closest=True)
        assert len(ch) == (1 if hit.any() else 0)
        if hit.any():
            np.testing.assert_allclose(ct[0], np.nanmin(t), rtol=1e-4, atol=1e-9)
            assert ch[0] in set(hs[hit].tolist())


def test_raycast_edges() -> None:
    tree = carom.DynamicTree()
    h = tree.insert([0, 0, 0], [1, 1, 1])
    # Origin inside: fraction 0; zero max_fraction still reports it.
    assert tree.raycast([0.5, 0.5, 0.5], [1, 0, 0], 0.0)[0].tolist() == [h]
    assert tree.raycast([0.5, 0.5, 0.5], [1, 0, 0], closest=True)[1].tolist() == [0.0]
    # Too short to reach the box, then long enough.
    assert len(tree.raycast([-2, 0.5, 0.5], [1, 0, 0], 1.0)[0]) == 0
    hs, ts = tree.raycast([-2, 0.5, 0.5], [1, 0, 0], 3.0)
    assert hs.tolist() == [h] and ts.tolist() == [2.0]
    # Grazing a face counts (touching).
    assert tree.raycast([-2, 1.0, 0.5], [1, 0, 0], 3.0)[0].tolist() == [h]
    assert tree.raycast([-2, 1.5, 0.5], [1, 0, 0], 3.0)[0].tolist() == []


def frustum_oracle(lo: np.ndarray, hi: np.ndarray, planes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(inside, ambiguous): boxes meeting every half-space n·x + d >= 0, and boxes within a
    rounding tolerance of some plane (left out of the comparison)."""
    n, d = planes[:, :3], planes[:, 3]
    far = np.where(n[None, :, :] >= 0, hi[:, None, :], lo[:, None, :])  # (B, P, 3)
    s = np.einsum("bpk,pk->bp", far, n) + d
    tol = 1e-4 * ((np.abs(far) * np.abs(n)).sum(axis=2).max(initial=0.0) + np.abs(d).max(initial=0.0)) + 1e-6
    return np.all(s >= 0, axis=1), np.any(np.abs(s) <= tol, axis=1)


@pytest.mark.parametrize("kind", ["uniform", "mixed", "far"])
def test_query_frustum_matches_brute_force(kind: str) -> None:
    rng = np.random.default_rng(len(kind))
    tree = carom.DynamicTree()
    lo, hi = random_boxes(rng, 300, kind)
    hs = tree.insert(lo, hi)
    center = (lo + hi).mean(axis=0) / 2
    for p in (0, 1, 4, 6):
        n = rng.normal(size=(p, 3))
        # Planes through points near the scene centre, so that some boxes are in and some out.
        pts = center + rng.normal(scale=np.abs(hi - lo).mean() * 3 + 1, size=(p, 3))
        planes = exact(np.hstack([n, -np.einsum("pk,pk->p", n, pts)[:, None]]))
        inside, ambiguous = frustum_oracle(lo, hi, planes)
        got = set(tree.query_frustum(planes).tolist())
        for k in range(len(hs)):
            if not ambiguous[k]:
                assert (int(hs[k]) in got) == bool(inside[k])
    # A box frustum: exactly the boxes meeting the region x, y, z in [-5, 5].
    planes = np.array([[1, 0, 0, 5], [-1, 0, 0, 5], [0, 1, 0, 5], [0, -1, 0, 5], [0, 0, 1, 5], [0, 0, -1, 5]], float)
    want = hs[np.all((lo <= 5) & (hi >= -5), axis=1)]
    np.testing.assert_array_equal(tree.query_frustum(planes), np.sort(want))


def test_stale_handles_and_bad_input() -> None:
    tree = carom.DynamicTree(margin=0.0, strategy="manhattan")
    assert len(tree) == 0 and tree.height == 0
    assert tree.query_aabb([0, 0, 0], [1, 1, 1]).tolist() == []
    a = tree.insert([0, 0, 0], [1, 1, 1])
    b = tree.insert([2, 2, 2], [3, 3, 3])
    tree.remove(a)
    c = tree.insert([0, 0, 0], [1, 1, 1])  # may reuse a's node, with a new generation
    assert c != a
    for call in (
        lambda: tree.remove(a),
        lambda: tree.update(a, [0, 0, 0], [1, 1, 1]),
        lambda: tree.aabb(a),
        lambda: tree.remove([b, b]),
        lambda: tree.remove(-5),
    ):
        with pytest.raises(carom.CaromError):
            call()
    assert len(tree) == 2
    with pytest.raises(carom.CaromError, match="inverted"):
        tree.insert([0, 0, 0], [-1, 1, 1])
    with pytest.raises(carom.CaromError, match="finite"):
        tree.insert([[0, 0, np.nan]], [[1, 1, 1]])
    with pytest.raises(carom.CaromError, match="shape"):
        tree.query_frustum(np.zeros((2, 3)))
    with pytest.raises(carom.CaromError, match="finite"):
        tree.query_frustum([[0, 0, 1, np.inf]])
    with pytest.raises(carom.CaromError, match="max_fraction"):
        tree.raycast([0, 0, 0], [1, 0, 0], -1.0)
    with pytest.raises(carom.CaromError):
        tree.raycast([0, 0, np.nan], [1, 0, 0])
    with pytest.raises(carom.CaromError, match="one box"):
        tree.query_aabb(np.zeros((2, 3)), np.ones((2, 3)))
    with pytest.raises(carom.CaromError, match="strategy"):
        carom.DynamicTree(strategy="median")
    with pytest.raises(carom.CaromError, match="margin"):
        carom.DynamicTree(margin=-1.0)
    with pytest.raises(TypeError):
        tree.insert(None, [1, 1, 1])
    with pytest.raises(TypeError):
        tree.remove("b")
    tree.validate()
    lo, hi = tree.aabb(b)
    assert lo.tolist() == [2.0, 2.0, 2.0] and hi.tolist() == [3.0, 3.0, 3.0]
    assert "DynamicTree" in repr(tree)
