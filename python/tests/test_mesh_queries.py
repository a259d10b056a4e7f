"""TriMesh BVH queries against numpy brute force over all triangles: closest ray hits
(Möller–Trumbore), closest points (Ericson's closest point on a triangle), AABB overlap;
loading OBJ/STL files and bytes; bad input."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import carom

from conftest import TOL


def grid_mesh(n: int = 8, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """A bumpy n x n grid over [-1, 1]^2 (XZ), heights in Y."""
    rng = np.random.default_rng(seed)
    xs = np.linspace(-1, 1, n)
    x, z = np.meshgrid(xs, xs)
    y = 0.2 * rng.uniform(-1, 1, x.shape)
    verts = np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1)
    tris = []
    for r in range(n - 1):
        for c in range(n - 1):
            i = r * n + c
            tris.append([i, i + n, i + 1])
            tris.append([i + 1, i + n, i + n + 1])
    return verts, np.array(tris)


def moller_trumbore(o: np.ndarray, d: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """Ray parameters of one ray against all triangles (inf for misses)."""
    v0, v1, v2 = tri[:, 0], tri[:, 1], tri[:, 2]
    e1, e2 = v1 - v0, v2 - v0
    p = np.cross(d, e2)
    det = np.einsum("ij,ij->i", e1, p)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / det
        s = o - v0
        u = np.einsum("ij,ij->i", s, p) * inv
        q = np.cross(s, e1)
        v = (q @ d) * inv
        t = np.einsum("ij,ij->i", e2, q) * inv
    ok = (np.abs(det) > 1e-12) & (u >= 0) & (v >= 0) & (u + v <= 1) & (t >= 0)
    return np.where(ok, t, np.inf)


def closest_on_triangle(p: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Ericson, Real-Time Collision Detection, 5.1.5."""
    ab, ac, ap = b - a, c - a, p - a
    d1, d2 = ab @ ap, ac @ ap
    if d1 <= 0 and d2 <= 0:
        return a
    bp = p - b
    d3, d4 = ab @ bp, ac @ bp
    if d3 >= 0 and d4 <= d3:
        return b
    vc = d1 * d4 - d3 * d2
    if vc <= 0 and d1 >= 0 and d3 <= 0:
        return a + d1 / (d1 - d3) * ab
    cp = p - c
    d5, d6 = ab @ cp, ac @ cp
    if d6 >= 0 and d5 <= d6:
        return c
    vb = d5 * d2 - d1 * d6
    if vb <= 0 and d2 >= 0 and d6 <= 0:
        return a + d2 / (d2 - d6) * ac
    va = d3 * d6 - d5 * d4
    if va <= 0 and (d4 - d3) >= 0 and (d5 - d6) >= 0:
        return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b)
    denom = 1.0 / (va + vb + vc)
    return a + ab * (vb * denom) + ac * (vc * denom)


def test_mesh_raycast_against_brute_force() -> None:
    verts, idx = grid_mesh()
    mesh = carom.TriMesh(verts, idx)
    tri = verts[idx]
    rng = np.random.default_rng(1)
    n = 200
    origins = rng.uniform(-1.5, 1.5, (n, 3))
    origins[:, 1] = rng.uniform(0.5, 2.0, n) * rng.choice([-1, 1], n)
    targets = rng.uniform(-1.5, 1.5, (n, 3))
    targets[:, 1] = 0.0
    dirs = targets - origins
    res = mesh.raycast(origins, dirs * 3.0)  # unnormalised directions are normalised
    assert res.hit.shape == (n,) and res.point.shape == (n, 3) and res.triangle.dtype == np.int64
    unit = dirs / np.linalg.norm(dirs, axis=1, keepdims=True)
    hits = 0
    for i in range(n):
        t = moller_trumbore(origins[i], unit[i], tri)
        best = t.min()
        if not np.isfinite(best):
            assert not res.hit[i] and res.triangle[i] == -1 and np.isnan(res.distance[i])
            continue
        hits += 1
        assert res.hit[i]
        assert res.distance[i] == pytest.approx(best, abs=20 * TOL)
        np.testing.assert_allclose(res.point[i], origins[i] + best * unit[i], atol=20 * TOL)
        # The reported triangle is one whose hit is (within round-off) the closest.
        assert t[res.triangle[i]] == pytest.approx(best, abs=20 * TOL)
        a, b, c = tri[res.triangle[i]]
        nrm = np.cross(b - a, c - a)
        np.testing.assert_allclose(res.normal[i], nrm / np.linalg.norm(nrm), atol=10 * TOL)
    assert 0.3 * n <= hits <= 0.7 * n
    short = mesh.raycast(origins, dirs, max_distance=0.1)
    assert not short.hit.any()


def test_mesh_closest_points_against_brute_force() -> None:
    verts, idx = grid_mesh(6, seed=2)
    mesh = carom.TriMesh(verts, idx)
    rng = np.random.default_rng(3)
    pts = rng.uniform(-1.5, 1.5, (60, 3))
    cp, dist, tris = mesh.closest_points(pts)
    assert cp.shape == (60, 3) and dist.shape == (60,) and tris.shape == (60,)
    for i, p in enumerate(pts):
        cands = np.array([closest_on_triangle(p, *verts[t]) for t in idx])
        d = np.linalg.norm(cands - p, axis=1)
        assert dist[i] == pytest.approx(d.min(), abs=10 * TOL)
        assert np.linalg.norm(cp[i] - p) == pytest.approx(d.min(), abs=10 * TOL)
        assert d[tris[i]] == pytest.approx(d.min(), abs=10 * TOL)
    _, far, ft = mesh.closest_points(pts + [0, 10, 0], max_distance=1.0)
    assert np.isnan(far).all() and (ft == -1).all()


def test_overlapping_triangles_against_brute_force() -> None:
    verts, idx = grid_mesh(7, seed=4)
    mesh = carom.TriMesh(verts, idx)
    tri = verts[idx]
    lo_t, hi_t = tri.min(axis=1), tri.max(axis=1)
    rng = np.random.default_rng(5)
    for _ in range(20):
        c = rng.uniform(-1, 1, 3)
        h = rng.uniform(0.05, 0.5, 3)
        got = mesh.overlapping_triangles(c - h, c + h)
        expected = np.nonzero(((lo_t <= c + h) & (hi_t >= c - h)).all(axis=1))[0]
        np.testing.assert_array_equal(got, expected)


def test_load_obj_and_stl(tmp_path: Path) -> None:
    obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
    (tmp_path / "t.obj").write_text(obj)
    m = carom.TriMesh.load(tmp_path / "t.obj")
    assert isinstance(m, carom.TriMesh) and m.num_triangles == 4
    assert carom.TriMesh.from_obj_bytes(obj.encode()) == m
    stl = "solid t\n" + "".join(
        f"facet normal 0 0 0\nouter loop\nvertex {a}\nvertex {b}\nvertex {c}\nendloop\nendfacet\n"
        for a, b, c in [("0 0 0", "0 1 0", "1 0 0"), ("0 0 0", "1 0 0", "0 0 1")]
    ) + "endsolid t\n"
    (tmp_path / "t.STL").write_text(stl)
    s = carom.TriMesh.load(str(tmp_path / "t.STL"))
    assert s.num_triangles == 2
    (tmp_path / "bad.obj").write_text("v 0 0 nope\nf 1 2 3\n")
    with pytest.raises(carom.CaromError):
        carom.TriMesh.load(tmp_path / "bad.obj")
    with pytest.raises(carom.CaromError):
        carom.TriMesh.load(tmp_path / "missing.obj")
    (tmp_path / "x.ply").write_text("ply\n")
    with pytest.raises(carom.CaromError):
        carom.TriMesh.load(tmp_path / "x.ply")


def test_mesh_bad_input() -> None:
    verts, idx = grid_mesh(4)
    mesh = carom.TriMesh(verts, idx)
    with pytest.raises(carom.CaromError, match=r"directions\[1\]"):
        mesh.raycast([[0, 1, 0], [0, 1, 0]], [[0, -1, 0], [0, 0, 0]])
    with pytest.raises(carom.CaromError, match="origins"):
        mesh.raycast(np.zeros((3, 2)), np.zeros((3, 2)))
    with pytest.raises(carom.CaromError, match="same length"):
        mesh.raycast(np.zeros((3, 3)), np.ones((2, 3)))
    with pytest.raises(carom.CaromError, match="origins"):
        mesh.raycast([[np.nan, 0, 0]], [[0, 1, 0]])
    with pytest.raises(carom.CaromError, match="max_distance"):
        mesh.raycast([[0, 1, 0]], [[0, -1, 0]], max_distance=-1.0)
    with pytest.raises(TypeError):
        mesh.closest_points("points")
    with pytest.raises(carom.CaromError, match="aabb_min"):
        mesh.overlapping_triangles([1, 1, 1], [0, 0, 0])


def heightfield_triangles(heights: np.ndarray, dx: float, dz: float) -> np.ndarray:
    """The triangles of a heightfield, numbered as documented on carom.HeightField."""
    rows, cols = heights.shape

    def p(r: int, c: int) -> np.ndarray:
        return np.array([c * dx - (cols - 1) * dx / 2, heights[r, c], r * dz - (rows - 1) * dz / 2])

    out = []
    for r in range(rows - 1):
        for c in range(cols - 1):
            out.append([p(r, c), p(r + 1, c), p(r, c + 1)])
            out.append([p(r, c + 1), p(r + 1, c), p(r + 1, c + 1)])
    return np.array(out)


def test_heightfield_raycast_and_overlap_against_brute_force() -> None:
    rng = np.random.default_rng(8)
    heights = rng.uniform(-0.3, 0.3, (6, 7))
    hf = carom.HeightField(heights, cell_size=(0.4, 0.5))
    tri = heightfield_triangles(heights, 0.4, 0.5)
    n = 150
    origins = rng.uniform(-2, 2, (n, 3))
    origins[:, 1] = rng.uniform(1.0, 2.0, n)
    targets = rng.uniform(-2, 2, (n, 3))
    targets[:, 1] = 0.0
    dirs = targets - origins
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    res = hf.raycast(origins, dirs)
    hits = 0
    for i in range(n):
        t = moller_trumbore(origins[i], dirs[i], tri)
        if not np.isfinite(t.min()):
            assert not res.hit[i]
            continue
        hits += 1
        assert res.hit[i] and res.distance[i] == pytest.approx(t.min(), abs=20 * TOL)
        assert t[res.triangle[i]] == pytest.approx(t.min(), abs=20 * TOL)
    assert 0.2 * n <= hits <= 0.8 * n
    lo_t, hi_t = tri.min(axis=1), tri.max(axis=1)
    for _ in range(10):
        c, h = rng.uniform(-1.5, 1.5, 3), rng.uniform(0.05, 0.6, 3)
        c[1] = 0.0
        got = hf.overlapping_triangles(c - h, c + h)
        expected = np.nonzero(((lo_t <= c + h) & (hi_t >= c - h)).all(axis=1))[0]
        np.testing.assert_array_equal(got, expected)


def test_compound_overlapping_children_against_brute_force() -> None:
    rng = np.random.default_rng(9)
    centers = rng.uniform(-3, 3, (20, 3))
    comp = carom.Compound([(carom.Sphere(0.3), [*c, 0, 0, 0, 1]) for c in centers])
    for _ in range(20):
        c, h = rng.uniform(-3, 3, 3), rng.uniform(0.1, 1.5, 3)
        got = comp.overlapping_children(c - h, c + h)
        expected = np.nonzero(((centers - 0.3 <= c + h) & (centers + 0.3 >= c - h)).all(axis=1))[0]
        np.testing.assert_array_equal(got, expected)


def test_compound_child_pairs_against_brute_force() -> None:
    rng = np.random.default_rng(10)
    ca, cb = rng.uniform(-3, 3, (25, 3)), rng.uniform(-3, 3, (15, 3))
    a = carom.Compound([(carom.Sphere(0.4), [*c, 0, 0, 0, 1]) for c in ca])
    b = carom.Compound([(carom.Sphere(0.4), [*c, 0, 0, 0, 1]) for c in cb])
    shift = np.array([0.5, -0.25, 0.0])
    got = a.overlapping_child_pairs(b, [*shift, 0, 0, 0, 1])
    moved = cb + shift
    overlap = (np.abs(ca[:, None, :] - moved[None, :, :]) <= 0.8 + 1e-6).all(axis=2)
    expected = np.argwhere(overlap)
    assert got.shape == expected.shape and got.dtype == np.int64
    np.testing.assert_array_equal(got, expected)
    assert a.overlapping_child_pairs(b).shape[1] == 2
    with pytest.raises(TypeError):
        a.overlapping_child_pairs(carom.Sphere(1.0))  # type: ignore[arg-type]
    with pytest.raises(ValueError):
        a.overlapping_child_pairs(b, [np.nan, 0, 0, 0, 0, 0, 1])
