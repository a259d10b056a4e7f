"""Queries on meshes, heightfields and compounds against the brute force over their convex
pieces, and the cases session 27's adversarial sweep found: heightfield shape casts that
crashed the interpreter, time of impact stepping through a compound's far child, cone rays
off by 0.1, zero normals far from the origin, and plane casts refused."""

from __future__ import annotations

import numpy as np

import carom


def _grid(n: int = 5, size: float = 4.0) -> tuple[np.ndarray, np.ndarray]:
    xs = np.linspace(-size / 2, size / 2, n + 1)
    v = np.array([[x, 0.2 * np.sin(x) * np.cos(z), z] for x in xs for z in xs])
    w = n + 1
    t = []
    for i in range(n):
        for j in range(n):
            a = i * w + j
            t += [[a, a + 1, a + w], [a + 1, a + w + 1, a + w]]
    return v, np.array(t)


def test_mesh_and_heightfield_distance_and_cast_equal_the_minimum_over_triangles() -> None:
    rng = np.random.default_rng(27)
    v, t = _grid()
    mesh = carom.TriMesh(v, t)
    hf = carom.HeightField(rng.uniform(-0.2, 0.2, size=(6, 6)), (0.8, 0.8))
    shapes = [carom.Sphere(0.3), carom.Box([0.3, 0.1, 0.2]), carom.Capsule(0.1, 0.3)]
    for target in (mesh, hf):
        if target is mesh:
            tris = [carom.Triangle(*v[i]) for i in t]
        else:
            # The heightfield's triangles, read through the mesh it is equivalent to.
            tris = None
        for s in shapes:
            for _ in range(15):
                q = rng.normal(size=4)
                pose = carom.Pose(rng.uniform([-1.5, 0.4, -1.5], [1.5, 1.5, 1.5]), q / np.linalg.norm(q))
                d = carom.distance(target, None, s, pose).distance
                d_swapped = carom.distance(s, pose, target, None).distance
                assert abs(d - d_swapped) < 1e-5
                hit = carom.shape_cast(s, pose, [0.2, -3.0, 0.1], target, None, [0, 0, 0])
                assert hit is not None and 0.0 <= hit.toi <= 1.0
                if tris is not None:
                    want = min(carom.distance(tr, None, s, pose).distance for tr in tris)
                    assert abs(d - want) < 1e-5
                    casts = [carom.shape_cast(s, pose, [0.2, -3.0, 0.1], tr, None, [0, 0, 0]) for tr in tris]
                    assert abs(hit.toi - min(c.toi for c in casts if c is not None)) < 1e-5
                assert carom.intersects(target, None, s, pose) == (d <= 0.0)


def test_heightfield_shape_cast_and_world_cast_hit() -> None:
    hf = carom.HeightField(np.zeros((3, 3)))
    s = carom.Sphere(0.5)
    hit = carom.shape_cast(s, carom.Pose([0.0, 2.0, 0.0]), [0.0, -5.0, 0.0], hf, None, [0.0, 0.0, 0.0])
    assert hit is not None and abs(hit.toi - 0.3) < 1e-5
    w = carom.World()
    w.add_body(hf, is_static=True)
    h = w.shape_cast(s, carom.Pose([0.0, 3.0, 0.0]), [0.0, -5.0, 0.0])
    assert h is not None and abs(h.toi - 0.5) < 1e-5


def test_time_of_impact_on_a_compound_stops_at_the_far_wall() -> None:
    floor, wall = carom.Box([5.0, 0.5, 5.0]), carom.Box([0.5, 5.0, 5.0])
    comp = carom.Compound([(floor, carom.Pose([0.0, -0.5, 0.0])), (wall, carom.Pose([3.5, 0.0, 0.0]))])
    ball = carom.Sphere(0.5)
    start = carom.Pose([0.0, 1.0, 0.0])
    for v in ([10.0, 0.0, 0.0], [10.0, -1.0, 0.0]):
        h = carom.time_of_impact(ball, start, v, [0, 0, 0], comp, None, [0, 0, 0], [0, 0, 0])
        assert h is not None and 0.249 < h.toi <= 0.25


def test_cone_rays_normals_far_away_and_plane_casts() -> None:
    cone = carom.Cone(1.0, 1.0)
    o = np.array([-4.50638378, 11.42157718, 2.8402253])
    d = np.array([0.37875963, -0.89446247, -0.23765109])
    hit = carom.raycast(cone, None, o, d)
    assert abs(hit.distance - 11.783131) < 1e-3
    assert abs(carom.project_point(cone, None, hit.point).distance) < 1e-4
    # A triangle and a cylinder near 1e5: the normal stays unit.
    tri = carom.Triangle(
        [27899.10742188, 97985.765625, 57897.1171875],
        [27898.63476562, 97986.859375, 57896.203125],
        [27898.55273438, 97987.046875, 57896.40625],
    )
    pose = carom.Pose.from_array([2.78990767e04, 9.79861206e04, 5.78969609e04, -0.399846357, 0.37530596, -0.281321977, 0.787480966])
    c = carom.distance(tri, None, carom.Cylinder(0.1, 0.07), pose)
    assert abs(np.linalg.norm(c.normal) - 1.0) < 1e-3
    # A box cast onto a plane: its lowest corner reaches the plane first.
    plane = carom.Plane([0.0, 1.0, 0.0], 0.0)
    h = carom.shape_cast(carom.Box([0.5, 0.5, 0.5]), carom.Pose([0.0, 2.0, 0.0]), [0.0, -3.0, 0.0], plane, None, [0, 0, 0])
    assert h is not None and abs(h.toi - 0.5) < 1e-6


def test_sphere_cast_onto_a_cylinder_ends_with_the_contact_normal() -> None:
    # The cast stopped within the GJK ray cast's tolerance with its normal 0.24 degrees off
    # the sphere's radius through the contact point; it now ends with conservative-advancement
    # steps and the contact query's normal there.
    a = carom.Sphere(0.8381035327911377)
    b = carom.Cylinder(1.8616008758544922, 0.9953323602676392)
    qa = [0.4042821456849178, 0.559846240523436, -0.6263805189340501, -0.3616290629250972]
    qb = [0.38650358231761744, -0.5191342776828705, 0.24299999485311033, -0.7225410611804157]
    pa = np.array([-0.7299577838888034, -1.1644746476129855, 0.10823257324411059])
    pb = np.array([-2.1952375766710857, -5.712924755905853, -1.934490715571448])
    vb = np.array([3.9690888386835796, 10.125144088187437, 4.806942716191389])
    h = carom.shape_cast(a, carom.Pose(pa, qa), [0, 0, 0], b, carom.Pose(pb, qb), vb, 0.5)
    assert h is not None
    radial = (h.point_a - pa) / np.linalg.norm(h.point_a - pa)
    assert np.degrees(np.arccos(min(1.0, float(radial @ h.normal)))) < 0.02
    c = carom.distance(a, carom.Pose(pa, qa), b, carom.Pose(pb + vb * h.toi, qb))
    assert abs(c.distance) < 1e-5
