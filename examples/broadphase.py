"""The broadphase from Python: one-call pairs, an incremental broadphase over a few frames of
motion, and a dynamic AABB tree with box, ray and frustum queries.

Run with `python examples/broadphase.py` after `make develop`."""

import numpy as np

import carom


def main() -> None:
    rng = np.random.default_rng(0)
    n = 20_000
    centers = rng.uniform(-100, 100, size=(n, 3))
    half = rng.uniform(0.5, 2.0, size=(n, 3))

    # 1. All overlapping pairs at once: (M, 2) int64 rows (i, j), i < j, sorted.
    pairs = carom.overlapping_pairs(centers - half, centers + half, method="hgrid")
    print(f"{n} boxes: {len(pairs)} overlapping pairs, first {pairs[:3].tolist()}")

    # 2. An incremental broadphase: handles in, added/removed pairs of handles out.
    bp = carom.BroadPhase("hgrid")
    handles = bp.add(centers - half, centers + half)
    added, removed = bp.update_pairs()
    print(f"frame 0: +{len(added)} -{len(removed)} pairs")
    velocity = rng.normal(scale=0.5, size=(n, 3))
    for frame in range(1, 4):
        centers += velocity
        bp.update(handles, centers - half, centers + half, displacement=velocity)
        added, removed = bp.update_pairs()
        print(f"frame {frame}: +{len(added)} -{len(removed)} pairs, {len(bp.pairs())} current")

    # 3. A dynamic AABB tree: box, ray and frustum queries return handles (exact boxes).
    tree = carom.DynamicTree()
    th = tree.insert(centers - half, centers + half)
    inside = tree.query_aabb([-5, -5, -5], [5, 5, 5])
    hit, t = tree.raycast([-200, 0, 0], [400, 0, 0], max_fraction=1.0, closest=True)
    # Frustum planes as rows (nx, ny, nz, d): inside where n.x + d >= 0.
    planes = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [-1, -1, -1, 50]], dtype=float)
    culled = tree.query_frustum(planes)
    print(f"tree of {len(tree)} boxes, height {tree.height}: {len(inside)} in the centre box, "
          f"ray hits handle {hit.tolist()} at t={np.round(t, 4).tolist()}, {len(culled)} in the frustum")
    assert np.isin(inside, th).all()
    tree.validate()


if __name__ == "__main__":
    main()
