"""Contact generation from Python: `carom.contact_manifold` against the `carom.contact` /
`carom.distance` oracles and analytic boxes, and `carom.CollisionWorld` against brute-force
pair enumeration (numpy AABB overlap, analytic sphere distances), contact events, sensors,
filters, batch poses, and bad input (ValueError / TypeError, never a panic)."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

import carom

from conftest import TOL, random_quat

Q_ID = [0.0, 0.0, 0.0, 1.0]


def pose(p, q=Q_ID) -> np.ndarray:
    return np.array([*p, *q], dtype=float)


def check_points(m: carom.Contacts) -> None:
    k = len(m)
    assert m.point_a.shape == (k, 3) and m.point_b.shape == (k, 3) and m.normal.shape == (k, 3)
    assert m.distance.shape == (k,) and m.depth.shape == (k,) and m.feature.shape == (k,)
    assert np.all(np.isfinite(m.point_a)) and np.all(np.isfinite(m.normal))
    np.testing.assert_allclose(m.point_b, m.point_a + m.normal * m.distance[:, None], atol=10 * TOL)
    np.testing.assert_allclose(np.linalg.norm(m.normal, axis=1), 1.0, atol=10 * TOL)
    np.testing.assert_allclose(m.depth, -m.distance)


def test_box_resting_on_box_gives_four_corner_points() -> None:
    ground, box = carom.Box([2.0, 0.5, 2.0]), carom.Box([0.5, 0.5, 0.5])
    m = carom.contact_manifold(ground, pose([0, 0, 0]), box, pose([0.3, 0.99, -0.2]))
    check_points(m)
    assert len(m) == 4
    np.testing.assert_allclose(m.depth, 0.01, atol=10 * TOL)
    # Normal from A (ground) towards B (box): +Y, as carom.contact.
    np.testing.assert_allclose(m.normal, np.tile([0.0, 1.0, 0.0], (4, 1)), atol=10 * TOL)
    corners = {(round(x, 3), round(z, 3)) for x, z in m.point_b[:, [0, 2]]}
    assert corners == {(0.3 + sx * 0.5, -0.2 + sz * 0.5) for sx in (-1, 1) for sz in (-1, 1)}
    c = carom.contact(ground, pose([0, 0, 0]), box, pose([0.3, 0.99, -0.2]))
    assert c is not None
    assert m.distance.min() == pytest.approx(c.distance, abs=10 * TOL)


def test_capsule_lying_on_box_gives_two_analytic_points() -> None:
    # A capsule (radius 0.25, half height 0.6) along X, 1 cm into the top face of a box:
    # the closed-form capsule-box manifold clips its segment to the face, one point per end.
    ground = carom.Box([1.0, 0.5, 1.0])
    cap = carom.Capsule(0.25, 0.6)
    s = np.sqrt(0.5)
    along_x = [0.0, 0.0, s, s]  # 90 degrees about Z: the capsule's Y axis onto -X
    for a, pa, b, pb, box_first in [
        (ground, pose([0, 0, 0]), cap, pose([0.1, 0.74, 0.2], along_x), True),
        (cap, pose([0.1, 0.74, 0.2], along_x), ground, pose([0, 0, 0]), False),
    ]:
        m = carom.contact_manifold(a, pa, b, pb)
        check_points(m)
        assert len(m) == 2
        np.testing.assert_allclose(m.depth, 0.01, atol=10 * TOL)
        on_box = m.point_a if box_first else m.point_b
        np.testing.assert_allclose(sorted(on_box[:, 0]), [-0.5, 0.7], atol=10 * TOL)
        np.testing.assert_allclose(on_box[:, 1], 0.5, atol=10 * TOL)
        c = carom.contact(a, pa, b, pb)
        assert c is not None
        assert c.distance == pytest.approx(-0.01, abs=10 * TOL)


def random_shape(rng: np.random.Generator, kind: int) -> carom.Shape:
    if kind == 0:
        return carom.Box(rng.uniform(0.2, 0.6, 3))
    if kind == 1:
        return carom.ConvexHull(rng.normal(size=(16, 3)) * 0.4)
    if kind == 2:
        return carom.Capsule(rng.uniform(0.1, 0.3), rng.uniform(0.1, 0.5))
    return carom.Sphere(rng.uniform(0.2, 0.5))


def test_manifolds_agree_with_the_contact_oracle() -> None:
    rng = np.random.default_rng(3)
    checked = 0
    for _ in range(150):
        a, b = random_shape(rng, rng.integers(4)), random_shape(rng, rng.integers(4))
        pa = pose(rng.uniform(-0.2, 0.2, 3), random_quat(rng))
        pb = pose(rng.uniform(-0.9, 0.9, 3), random_quat(rng))
        c = carom.contact(a, pa, b, pb)
        m = carom.contact_manifold(a, pa, b, pb)
        check_points(m)
        assert len(m) <= 4
        if c is None:
            d = carom.distance(a, pa, b, pb).distance
            assert len(m) == 0 or d < 1e-3, (d, m)
            continue
        if c.distance > -1e-3:
            continue
        checked += 1
        assert len(m) >= 1
        tol = 2e-3 + 0.02 * abs(c.distance)
        assert m.distance.min() == pytest.approx(c.distance, abs=tol)
        deepest = int(np.argmin(m.distance))
        assert np.dot(m.normal[deepest], c.normal) > 0.98
        # Swapping A and B gives the same depth and the opposite normal.
        s = carom.contact_manifold(b, pb, a, pa)
        assert s.distance.min() == pytest.approx(m.distance.min(), abs=tol)
    assert checked > 30


def test_prediction_keeps_near_points_only() -> None:
    a, b = carom.Box([0.5, 0.5, 0.5]), carom.Box([0.5, 0.5, 0.5])
    apart = pose([0, 1.05, 0])
    assert len(carom.contact_manifold(a, None, b, apart)) == 0
    m = carom.contact_manifold(a, None, b, apart, prediction=0.1)
    assert len(m) == 4
    np.testing.assert_allclose(m.distance, 0.05, atol=10 * TOL)


def test_heightfield_and_equivalent_mesh_give_the_same_manifold() -> None:
    rng = np.random.default_rng(4)
    heights = rng.uniform(0.0, 0.3, (5, 6))
    hf = carom.HeightField(heights, cell_size=(1.0, 1.0))
    rows, cols = heights.shape
    xs, zs = np.arange(cols) - (cols - 1) / 2, np.arange(rows) - (rows - 1) / 2
    verts = np.array([[xs[c], heights[r, c], zs[r]] for r in range(rows) for c in range(cols)])
    idx = []
    for r in range(rows - 1):
        for c in range(cols - 1):
            i = r * cols + c
            idx += [[i, i + cols, i + 1], [i + 1, i + cols, i + cols + 1]]
    mesh = carom.TriMesh(verts, np.array(idx))
    ball, box = carom.Sphere(0.4), carom.Box([0.3, 0.2, 0.4])
    touching = 0
    for _ in range(40):
        for s in (ball, box):
            p = pose([rng.uniform(-2, 2), rng.uniform(0.1, 0.6), rng.uniform(-1.5, 1.5)], random_quat(rng))
            m1 = carom.contact_manifold(hf, None, s, p, prediction=0.01)
            m2 = carom.contact_manifold(mesh, None, s, p, prediction=0.01)
            assert len(m1) == len(m2)
            assert sorted(m1.feature.tolist()) == sorted(m2.feature.tolist())
            for i in range(len(m1)):
                j = m2.feature.tolist().index(m1.feature[i])
                np.testing.assert_allclose(m1.point_b[i], m2.point_b[j], atol=10 * TOL)
                np.testing.assert_allclose(m1.normal[i], m2.normal[j], atol=10 * TOL)
                assert m1.distance[i] == pytest.approx(m2.distance[j], abs=10 * TOL)
            touching += len(m1) > 0
    assert touching > 10


def sphere_world(rng: np.random.Generator, n: int, method: str):
    w = carom.CollisionWorld(method)
    radii = rng.uniform(0.2, 0.5, n)
    centres = rng.uniform(-2.0, 2.0, (n, 3))
    handles = [w.add(carom.Sphere(r), pose(c)) for r, c in zip(radii, centres)]
    return w, handles, radii, centres


@pytest.mark.parametrize("method", ["hgrid", "tree", "sap", "brute_force"])
def test_world_contacts_match_brute_force_pairs(method: str) -> None:
    rng = np.random.default_rng(5)
    w, handles, radii, centres = sphere_world(rng, 40, method)
    for frame in range(3):
        if frame:
            centres = centres + rng.uniform(-0.2, 0.2, centres.shape)
            w.set_poses(handles, np.hstack([centres, np.tile(Q_ID, (len(handles), 1))]))
        contacts = w.step()
        check_points(contacts)
        # Broadphase: exactly the pairs whose boxes overlap (numpy oracle).
        lo, hi = centres - radii[:, None], centres + radii[:, None]
        expected = {
            (handles[i], handles[j])
            for i, j in itertools.combinations(range(len(handles)), 2)
            if np.all(lo[i] <= hi[j]) and np.all(lo[j] <= hi[i])
        }
        got = {tuple(sorted(p)) for p in w.pairs().tolist()}
        assert got == {tuple(sorted(p)) for p in expected}
        # Narrowphase: every overlapping pair has one point at the analytic depth.
        index = {h: i for i, h in enumerate(handles)}
        depth_of = {}
        for (ha, hb), d in zip(contacts.pairs.tolist(), contacts.depth):
            depth_of[tuple(sorted((ha, hb)))] = d
        for i, j in itertools.combinations(range(len(handles)), 2):
            gap = np.linalg.norm(centres[i] - centres[j]) - radii[i] - radii[j]
            key = tuple(sorted((handles[i], handles[j])))
            if gap < -1e-3:
                assert key in depth_of
                assert depth_of[key] == pytest.approx(-gap, abs=20 * TOL)
            elif gap > 0.03:
                assert key not in depth_of
        for ha, hb in contacts.pairs.tolist():
            i, j = index[ha], index[hb]
            c = carom.distance(carom.Sphere(radii[i]), pose(centres[i]), carom.Sphere(radii[j]), pose(centres[j]))
            assert c.distance <= 0.02 + 10 * TOL
        # Normals from A towards B.
        for (ha, hb), n in zip(contacts.pairs.tolist(), contacts.normal):
            dirn = centres[index[hb]] - centres[index[ha]]
            assert np.dot(n, dirn / np.linalg.norm(dirn)) > 0.999


def test_events_begin_persist_end_and_remove() -> None:
    w = carom.CollisionWorld("tree")
    ground = w.add(carom.Box([5.0, 0.5, 5.0]), None, is_static=True)
    box = w.add(carom.Box([0.5, 0.5, 0.5]), pose([0, 3, 0]))
    assert len(w.step()) == 0
    assert w.events().begin.shape == (0, 2)
    w.set_pose(box, pose([0, 0.99, 0]))
    c = w.step()
    assert len(c) == 4
    assert set(map(tuple, c.pairs.tolist())) == {(ground, box)}
    np.testing.assert_allclose(w.pose(box), pose([0, 0.99, 0]))
    assert w.events().begin.tolist() == [[ground, box]]
    w.set_pose(box, pose([0.01, 0.99, 0]))
    w.step()
    e = w.events()
    assert e.persist.tolist() == [[ground, box]] and e.begin.shape == (0, 2)
    w.set_pose(box, pose([0, 3, 0]))
    w.step()
    assert w.events().end.tolist() == [[ground, box]]
    w.set_pose(box, pose([0, 0.99, 0]))
    w.step()
    w.remove(box)
    w.step()
    assert w.events().end.tolist() == [[ground, box]]
    assert len(w) == 1 and w.handles() == [ground]
    assert len(w.contacts()) == 0


def test_sensors_report_events_without_points_and_filters_exclude_pairs() -> None:
    w = carom.CollisionWorld()
    assert w.method == "tree"
    a = w.add(carom.Sphere(0.5), pose([0, 0, 0]))
    s = w.add(carom.Sphere(0.5), pose([0.5, 0, 0]), sensor=True)
    f = w.add(carom.Sphere(0.5), pose([-0.5, 0, 0]), group=2, mask=2)
    g = w.add(carom.Sphere(0.5), pose([0, 0.5, 0]), group=2, mask=1)
    c = w.step()
    pairs = {tuple(p) for p in c.pairs.tolist()}
    assert all(s not in p for p in pairs)
    assert (a, s) in {tuple(p) for p in w.events().begin.tolist()}
    assert all(f not in p for p in pairs)  # group 2 / mask 2 meets no one with group 1
    assert (a, g) in pairs or (g, a) in pairs


def test_set_poses_matches_individual_updates() -> None:
    rng = np.random.default_rng(6)
    w1, h1, _, _ = sphere_world(np.random.default_rng(9), 20, "hgrid")
    w2, h2, _, _ = sphere_world(np.random.default_rng(9), 20, "hgrid")
    poses = np.hstack([rng.uniform(-1.5, 1.5, (20, 3)), np.tile(Q_ID, (20, 1))])
    w1.set_poses(h1, poses)
    for h, p in zip(h2, poses):
        w2.set_pose(h, p)
    c1, c2 = w1.step(), w2.step()
    np.testing.assert_array_equal(c1.pairs, c2.pairs)
    np.testing.assert_array_equal(c1.point_b, c2.point_b)


def test_unsupported_pairs_are_rejected_when_added() -> None:
    mesh = carom.TriMesh([[0, 0, 0], [1, 0, 0], [0, 0, 1]], [[0, 1, 2]])
    w = carom.CollisionWorld()
    w.add(mesh, None, is_static=True)
    with pytest.raises(carom.CaromError, match="mesh"):
        w.add(mesh, pose([0, 1, 0]))
    plane = carom.Plane([0, 1, 0])
    with pytest.raises(ValueError, match="plane"):
        w.add(plane)
    assert len(w) == 1
    with pytest.raises(carom.CaromError, match="mesh"):
        carom.contact_manifold(mesh, None, mesh, None)


def test_bad_input_raises_value_or_type_errors() -> None:
    with pytest.raises(ValueError, match="method"):
        carom.CollisionWorld("octree")
    w = carom.CollisionWorld()
    h = w.add(carom.Sphere(1.0))
    with pytest.raises(TypeError):
        w.add("sphere")
    with pytest.raises(TypeError):
        carom.CollisionWorld(3)
    with pytest.raises(ValueError):
        w.add(carom.Sphere(1.0), [0, 0, 0])
    with pytest.raises(ValueError):
        w.add(carom.Sphere(1.0), pose([np.nan, 0, 0]))
    with pytest.raises(ValueError):
        w.set_pose(h + 12345, pose([0, 0, 0]))
    with pytest.raises(ValueError):
        w.remove(h + 7)
    with pytest.raises(ValueError, match="poses"):
        w.set_poses([h], np.zeros((2, 7)) + Q_ID[-1])
    with pytest.raises(TypeError):
        w.set_poses("ab", np.zeros((2, 7)))
    with pytest.raises(ValueError):
        w.set_poses([h], [[0, 0, 0, 0, 0, 0, 0]])  # zero quaternion
    with pytest.raises((ValueError, OverflowError)):
        w.add(carom.Sphere(1.0), group=-1)
    with pytest.raises(TypeError):
        carom.contact_manifold(1, None, carom.Sphere(1.0), None)
    with pytest.raises(ValueError, match="prediction"):
        carom.contact_manifold(carom.Sphere(1.0), None, carom.Sphere(1.0), None, prediction=-1.0)
    with pytest.raises(ValueError):
        carom.contact_manifold(carom.Sphere(1.0), None, carom.Sphere(1.0), None, prediction=np.inf)
    # The world is unchanged by the failed calls.
    assert w.handles() == [h]
    np.testing.assert_allclose(w.pose(h), pose([0, 0, 0]))
