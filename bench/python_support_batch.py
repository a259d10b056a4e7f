"""Times carom's batch support queries against a vectorised numpy oracle doing the same work
in the same run (median of 5 runs). Usage: .venv/bin/python bench/python_support_batch.py"""

import timeit

import numpy as np

import carom


def median_seconds(f, number, repeat=5):
    return sorted(timeit.repeat(f, number=number, repeat=repeat))[repeat // 2] / number


rng = np.random.default_rng(0)
box = carom.Box([0.5, 1.0, 2.0])
he = box.half_extents
hull = carom.ConvexHull(rng.normal(size=(32, 3)))
V = hull.vertices
d1 = np.array([1.0, 2.0, 3.0])
for n in (10_000, 100_000, 1_000_000):
    D = rng.normal(size=(n, 3))
    rows = [
        ("box carom", lambda: box.support(D)),
        ("box numpy", lambda: np.where(D < 0, -he, he)),
        (f"hull({len(V)}v) carom", lambda: hull.support(D)),
        (f"hull({len(V)}v) numpy", lambda: V[np.argmax(D @ V.T, axis=1)]),
    ]
    for name, f in rows:
        t = median_seconds(f, max(1, 100_000 // n))
        print(f"N={n:>8}  {name:<18} {t * 1e3:8.2f} ms  {t / n * 1e9:6.1f} ns/query")
print(f"single call box.support((3,) float64): {median_seconds(lambda: box.support(d1), 20000) * 1e6:.2f} us")
print(f"single call numpy np.where(d < 0, -he, he): {median_seconds(lambda: np.where(d1 < 0, -he, he), 20000) * 1e6:.2f} us")
