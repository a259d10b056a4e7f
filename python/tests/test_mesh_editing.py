"""Mesh and compound features beyond the basic queries, each against a numpy oracle:
any/all-hit rays, refit (`TriMesh.with_vertices`) against a fresh build, BVH-vs-BVH triangle
pairs against all pairs of boxes, welding, edge adjacency and dihedral angles, closed-mesh
mass properties, and copy-on-write compound editing (`with_child`, `without_child`,
`with_child_pose`) against brute force of the child queries, with bad input."""

from __future__ import annotations

import numpy as np
import pytest

import carom

from conftest import TOL
from test_mesh_queries import closest_on_triangle, grid_mesh, heightfield_triangles, moller_trumbore

CUBE_V = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
# Outward counter-clockwise triangles of the cube above (vertex i = 4x + 2y + z bits).
CUBE_T = np.array(
    [
        [0, 1, 3], [0, 3, 2],  # x = -1
        [4, 6, 7], [4, 7, 5],  # x = +1
        [0, 4, 5], [0, 5, 1],  # y = -1
        [2, 3, 7], [2, 7, 6],  # y = +1
        [0, 2, 6], [0, 6, 4],  # z = -1
        [1, 5, 7], [1, 7, 3],  # z = +1
    ]
)  # fmt: skip


def random_rays(rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray]:
    origins = rng.uniform(-1.5, 1.5, (n, 3))
    origins[:, 1] = rng.uniform(0.5, 2.0, n) * rng.choice([-1, 1], n)
    targets = rng.uniform(-1.5, 1.5, (n, 3))
    targets[:, 1] = 0.0
    d = targets - origins
    return origins, d / np.linalg.norm(d, axis=1, keepdims=True)


def test_raycast_any_and_all_against_brute_force() -> None:
    verts, idx = grid_mesh(7, seed=11)
    # A second sheet above the first, so rays have several hits.
    verts2 = verts + [0, 0.5, 0]
    mesh = carom.TriMesh(np.vstack([verts, verts2]), np.vstack([idx, idx + len(verts)]))
    tri = mesh.vertices[mesh.indices]
    rng = np.random.default_rng(12)
    origins, dirs = random_rays(rng, 120)
    anyhit = mesh.raycast_any(origins, dirs)
    closest = mesh.raycast(origins, dirs)
    multi = 0
    for i in range(len(origins)):
        t = moller_trumbore(origins[i], dirs[i], tri)
        finite = np.sort(t[np.isfinite(t)])
        assert anyhit.hit[i] == closest.hit[i] == (len(finite) > 0)
        if anyhit.hit[i]:
            # Some real hit: its distance is the parameter of the triangle it reports.
            assert t[anyhit.triangle[i]] == pytest.approx(anyhit.distance[i], abs=20 * TOL)
        if closest.hit[i]:
            # The barycentric weights rebuild the hit point from the triangle's corners.
            w = closest.barycentric[i]
            assert (w >= -1e-6).all() and w.sum() == pytest.approx(1.0, abs=1e-5)
            corners = tri[closest.triangle[i]]
            np.testing.assert_allclose(w @ corners, closest.point[i], atol=20 * TOL)
        else:
            assert np.isnan(closest.barycentric[i]).all()
        every = mesh.raycast_all(origins[i], dirs[i])
        assert every.hit.all() and len(every.distance) == len(finite)
        np.testing.assert_allclose(every.distance, finite, atol=20 * TOL)
        assert (np.diff(every.distance) >= 0).all()
        multi += len(finite) >= 2
    assert multi >= 20
    none = mesh.raycast_all([0, 5, 0], [0, 1, 0])
    assert none.distance.shape == (0,) and none.point.shape == (0, 3)
    short = mesh.raycast_all(origins[0], dirs[0], max_distance=1e-3)
    assert len(short.distance) == 0
    with pytest.raises(carom.CaromError, match="direction"):
        mesh.raycast_all([0, 1, 0], [0, 0, 0])
    with pytest.raises(carom.CaromError, match="max_distance"):
        mesh.raycast_any(origins, dirs, max_distance=float("nan"))


def test_with_vertices_refits_like_a_fresh_build() -> None:
    verts, idx = grid_mesh(9, seed=13)
    mesh = carom.TriMesh(verts, idx)
    rng = np.random.default_rng(14)
    moved = verts * [1.5, 1.0, 0.8] + [3.0, -1.0, 2.0] + rng.uniform(-0.05, 0.05, verts.shape)
    refit = mesh.with_vertices(moved)
    fresh = carom.TriMesh(moved, idx)
    # Same geometry (the refitted BVH keeps the old topology, so the shapes differ as values).
    np.testing.assert_array_equal(refit.vertices, fresh.vertices)
    np.testing.assert_array_equal(refit.edge_angles, fresh.edge_angles)
    assert refit != mesh
    np.testing.assert_array_equal(mesh.vertices, carom.TriMesh(verts, idx).vertices)  # unchanged
    origins, dirs = random_rays(rng, 200)
    origins = origins * [1.5, 1.0, 0.8] + [3.0, -1.0, 2.0]
    a, b = refit.raycast(origins, dirs), fresh.raycast(origins, dirs)
    np.testing.assert_array_equal(a.triangle, b.triangle)
    np.testing.assert_array_equal(a.distance, b.distance)
    assert 40 <= a.hit.sum() <= 180
    pts = rng.uniform(-1, 4, (50, 3))
    for x, y in zip(refit.closest_points(pts), fresh.closest_points(pts)):
        np.testing.assert_array_equal(x, y)
    lo, hi = moved.min(axis=0), moved.max(axis=0)
    np.testing.assert_array_equal(
        refit.overlapping_triangles(lo, (lo + hi) / 2), fresh.overlapping_triangles(lo, (lo + hi) / 2)
    )
    with pytest.raises(carom.CaromError, match="vertices"):
        mesh.with_vertices(moved[:-1])
    bad = moved.copy()
    bad[3, 1] = np.nan
    with pytest.raises(carom.CaromError, match=r"vertices\[3\]"):
        mesh.with_vertices(bad)


def test_triangle_pairs_against_all_pairs() -> None:
    va, ia = grid_mesh(6, seed=15)
    vb, ib = grid_mesh(5, seed=16)
    a, b = carom.TriMesh(va, ia), carom.TriMesh(vb * 0.7, ib)
    angle = 0.4
    q = [0, np.sin(angle / 2), 0, np.cos(angle / 2)]
    pose = carom.Pose([0.3, 0.05, -0.2], q)
    got = a.overlapping_triangle_pairs(b, pose)
    c, s = np.cos(angle), np.sin(angle)
    rot = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    tb = (vb * 0.7) @ rot.T + [0.3, 0.05, -0.2]
    ta = va[ia]
    tbt = tb[ib]
    lo_a, hi_a = ta.min(axis=1), ta.max(axis=1)
    lo_b, hi_b = tbt.min(axis=1), tbt.max(axis=1)
    overlap = ((lo_a[:, None] <= hi_b[None] + 1e-9) & (hi_a[:, None] >= lo_b[None] - 1e-9)).all(axis=2)
    expected = np.argwhere(overlap)
    assert got.dtype == np.int64 and got.shape[1] == 2
    np.testing.assert_array_equal(got, expected)
    assert len(expected) > 20
    far = a.overlapping_triangle_pairs(b, [0, 100, 0, 0, 0, 0, 1])
    assert far.shape == (0, 2)
    with pytest.raises(TypeError):
        a.overlapping_triangle_pairs(carom.Sphere(1.0))  # type: ignore[arg-type]


def test_welding_edges_and_closed_mass() -> None:
    # The cube with every triangle on its own three vertices: no adjacency until welded.
    split_v = CUBE_V[CUBE_T].reshape(-1, 3)
    split_t = np.arange(len(split_v)).reshape(-1, 3)
    split = carom.TriMesh(split_v, split_t)
    assert (split.edge_neighbors == -1).all() and (split.edge_angles == 0).all()
    welded = carom.TriMesh(split_v, split_t, weld_tolerance=1e-6)
    assert welded.vertices.shape == (8, 3) and welded.num_triangles == 12
    nb = welded.edge_neighbors
    angles = welded.edge_angles
    assert (nb >= 0).all()
    tri = welded.vertices[welded.indices]
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    for t in range(12):
        for k in range(3):
            n = nb[t, k]
            # The neighbour shares the edge's two vertices.
            edge = {welded.indices[t, k], welded.indices[t, (k + 1) % 3]}
            assert edge <= set(welded.indices[n])
            # Oracle: the angle between the face normals, convex everywhere on a cube.
            cos = np.clip(normals[t] @ normals[n], -1, 1)
            assert angles[t, k] == pytest.approx(np.arccos(cos), abs=1e-5)
    # 12 cube edges seen from both sides, and the 6 face diagonals (flat) from both sides.
    assert np.isclose(angles, np.pi / 2, atol=1e-5).sum() == 24
    assert np.isclose(angles, 0, atol=1e-5).sum() == 12
    # Closed mesh: the solid cube's mass properties (side 2).
    mass, com, inertia = welded.mass_properties(density=3.0)
    assert mass == pytest.approx(24.0, rel=1e-5)
    np.testing.assert_allclose(com, 0, atol=1e-6)
    np.testing.assert_allclose(inertia, np.eye(3) * mass * (4 + 4) / 12, rtol=1e-5, atol=1e-6)
    with pytest.raises(carom.CaromError, match="weld_tolerance"):
        carom.TriMesh(split_v, split_t, weld_tolerance=-1.0)


def sphere_compound(centers: np.ndarray, r: float = 0.3) -> carom.Compound:
    return carom.Compound([(carom.Sphere(r), [*c, 0, 0, 0, 1]) for c in centers])


def brute_children(centers: np.ndarray, lo: np.ndarray, hi: np.ndarray, r: float = 0.3) -> np.ndarray:
    return np.nonzero(((centers - r <= hi) & (centers + r >= lo)).all(axis=1))[0]


def test_compound_editing_against_brute_force() -> None:
    rng = np.random.default_rng(17)
    centers = rng.uniform(-3, 3, (12, 3))
    comp = sphere_compound(centers)
    assert comp.num_children == 12
    # Apply a random sequence of edits, mirrored on a plain list of centres.
    model = [c.copy() for c in centers]
    current = comp
    for step in range(40):
        op = step % 3
        if op == 0:
            c = rng.uniform(-3, 3, 3)
            current = current.with_child(carom.Sphere(0.3), carom.Pose(c))
            model.append(c)
        elif op == 1 and len(model) > 1:
            i = int(rng.integers(len(model)))
            current = current.without_child(i)
            model[i] = model[-1]  # the last child takes its index
            model.pop()
        else:
            i = int(rng.integers(len(model)))
            c = rng.uniform(-3, 3, 3)
            current = current.with_child_pose(i, [*c, 0, 0, 0, 1])
            model[i] = c
        cs = np.array(model)
        assert current.num_children == len(model)
        np.testing.assert_allclose([p.position for _, p in current.children], cs, atol=TOL)
        lo_b, hi_b = current.aabb()
        np.testing.assert_allclose(lo_b, cs.min(axis=0) - 0.3, atol=10 * TOL)
        np.testing.assert_allclose(hi_b, cs.max(axis=0) + 0.3, atol=10 * TOL)
        for _ in range(3):
            c, h = rng.uniform(-3, 3, 3), rng.uniform(0.1, 1.5, 3)
            np.testing.assert_array_equal(current.overlapping_children(c - h, c + h), brute_children(cs, c - h, c + h))
        other_c = rng.uniform(-3, 3, (6, 3))
        other = sphere_compound(other_c)
        got = current.overlapping_child_pairs(other)
        overlap = (np.abs(cs[:, None, :] - other_c[None, :, :]) <= 0.6 + 1e-6).all(axis=2)
        np.testing.assert_array_equal(got, np.argwhere(overlap))
    # Copy-on-write: the original never changed.
    assert comp == sphere_compound(centers) and comp.num_children == 12


def test_compound_editing_bad_input_changes_nothing() -> None:
    comp = sphere_compound(np.array([[0.0, 0, 0], [2.0, 0, 0]]))
    before = comp.children
    with pytest.raises(carom.CaromError, match="index = 2"):
        comp.without_child(2)
    with pytest.raises(carom.CaromError, match="index = -1"):
        comp.with_child_pose(-1, carom.Pose([0, 0, 0]))
    with pytest.raises(carom.CaromError, match="pose"):
        comp.with_child_pose(0, [np.nan, 0, 0, 0, 0, 0, 1])
    with pytest.raises(carom.CaromError, match="pose"):
        comp.with_child(carom.Sphere(1.0), [0, 0, 0, 0, 0, 0, 2.0])  # not a unit quaternion
    with pytest.raises(carom.CaromError, match="plane"):
        comp.with_child(carom.Plane([0, 1, 0], 0.0))
    with pytest.raises(TypeError):
        comp.with_child("sphere")  # type: ignore[arg-type]
    with pytest.raises(TypeError):
        comp.without_child("0")  # type: ignore[arg-type]
    single = sphere_compound(np.zeros((1, 3)))
    with pytest.raises(carom.CaromError, match="only child"):
        single.without_child(0)
    assert comp.children == before and comp.num_children == 2
    # A compound placed in a world keeps its shape when the Python object is "edited".
    cw = carom.CollisionWorld()
    h = cw.add(comp, carom.Pose([0, 0, 0]))
    probe = cw.add(carom.Sphere(0.1), carom.Pose([2.0, 0.35, 0]))
    moved = comp.with_child_pose(1, [10, 0, 0, 0, 0, 0, 1])
    assert moved.num_children == 2
    cw.step()
    assert len(cw.pairs()) == 1 and set(cw.pairs()[0].tolist()) == {h, probe}


def test_heightfield_closest_points_against_brute_force() -> None:
    rng = np.random.default_rng(18)
    heights = rng.uniform(-0.4, 0.4, (5, 6))
    hf = carom.HeightField(heights, cell_size=(0.5, 0.3))
    tri = heightfield_triangles(heights, 0.5, 0.3)
    pts = rng.uniform(-2, 2, (40, 3))
    cp, dist, tris = hf.closest_points(pts)
    for i, p in enumerate(pts):
        d = np.linalg.norm(np.array([closest_on_triangle(p, *t) for t in tri]) - p, axis=1)
        assert dist[i] == pytest.approx(d.min(), abs=10 * TOL)
        assert np.linalg.norm(cp[i] - p) == pytest.approx(d.min(), abs=10 * TOL)
        assert d[tris[i]] == pytest.approx(d.min(), abs=10 * TOL)
    _, far, ft = hf.closest_points(pts + [0, 20, 0], max_distance=1.0)
    assert np.isnan(far).all() and (ft == -1).all()
    with pytest.raises(carom.CaromError, match="points"):
        hf.closest_points([[np.nan, 0, 0]])
