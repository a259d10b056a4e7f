//! The plane cull of `mesh_convex_contacts` against GJK/EPA distances: a culled triangle is
//! always farther than the prediction from the shape; the mesh query cache against the BVH
//! and brute force; the round shapes' closed form against the general path.

use super::*;
use crate::math::{consts::PI, Quat};
use crate::query::closest_points::closest_point_triangle;
use crate::query::distance_convex;
use crate::shape::{Capsule, Cuboid, Sphere};

/// xorshift64*: deterministic, dependency-free.
struct Rng(u64);

impl Rng {
    fn uniform(&mut self) -> Real {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let x = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D);
        ((x >> 11) as f64 / (1u64 << 53) as f64) as Real
    }
    fn range(&mut self, lo: Real, hi: Real) -> Real {
        lo + (hi - lo) * self.uniform()
    }
    fn unit(&mut self) -> Vec3 {
        let z = self.range(-1.0, 1.0);
        let a = self.range(0.0, 2.0 * PI);
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * a.cos(), r * a.sin(), z)
    }
}

#[test]
fn plane_cull_only_skips_triangles_beyond_the_prediction() {
    let mut rng = Rng(0x51_7CC1_B727_220A);
    let sphere = Sphere::new(0.7).unwrap();
    let capsule = Capsule::new(0.4, 0.9).unwrap();
    let cuboid = Cuboid::new(Vec3::new(0.3, 1.1, 0.6)).unwrap();
    let shapes = [
        ConvexRef::Sphere(&sphere),
        ConvexRef::Capsule(&capsule),
        ConvexRef::Cuboid(&cuboid),
    ];
    let (mut culled, mut kept) = (0, 0);
    for k in 0..6000 {
        let b = shapes[k % 3];
        let far = if k % 7 == 0 { 1.0e3 } else { 1.0 };
        let pose = Isometry::new(
            rng.unit() * rng.range(0.0, 3.0) * far,
            Quat::from_axis_angle(rng.unit(), rng.range(0.0, 3.0)),
        );
        // A triangle whose plane passes near the shape (grazing, touching, or just clear),
        // sometimes large (coplanar with a box face when the normal is one of its axes).
        let n = if k % 5 == 0 {
            pose.rotation * [Vec3::X, Vec3::Y, Vec3::Z][k % 3]
        } else {
            rng.unit()
        };
        let reach = match b {
            ConvexRef::Sphere(s) => s.radius(),
            _ => {
                let p = b.support_world(&pose, n);
                n.dot(p - pose.translation)
            }
        };
        let prediction = [0.0, 0.02, 0.1][k % 3];
        let gap = reach + prediction + rng.range(-0.05, 0.05) * [1.0, 1.0e-3][k % 2];
        let centre = pose.translation + n * gap + rng.unit().cross(n) * rng.range(0.0, 2.0);
        let (t1, t2) = (
            n.any_orthonormal_vector(),
            n.cross(n.any_orthonormal_vector()),
        );
        let size = rng.range(0.1, 5.0);
        let corner = |a: Real| centre + (t1 * a.cos() + t2 * a.sin()) * size;
        let tri = Triangle {
            a: corner(0.0),
            b: corner(2.1),
            c: corner(4.2),
        };
        let Some(tn) = tri.normal() else { continue };
        let slab = PlaneSlab::new(b, &pose).unwrap();
        let tri_ref = ConvexRef::Triangle(&tri);
        if slab.clear_of_plane(tn, tn.dot(tri.a), prediction) {
            culled += 1;
            let d = distance_convex(tri_ref, b, &pose).distance;
            assert!(d > prediction, "culled at distance {d} (case {k})");
        } else {
            kept += 1;
        }
    }
    assert!(culled > 1000 && kept > 1000, "culled {culled}, kept {kept}");
}

#[test]
fn hull_box_cull_only_skips_triangles_beyond_the_prediction() {
    let mut rng = Rng(0x2545_F491_4F6C_DD1D);
    let pts: Vec<Vec3> = (0..30)
        .map(|_| rng.unit() * Vec3::new(1.8, 2.0, 1.2) * rng.range(0.5, 1.0))
        .collect();
    let hull = ConvexHull::new(&pts).unwrap();
    let b = ConvexRef::ConvexHull(&hull);
    let (mut culled, mut kept) = (0, 0);
    for k in 0..6000 {
        let far = if k % 7 == 0 { 1.0e3 } else { 1.0 };
        let pose = Isometry::new(
            rng.unit() * rng.range(0.0, 3.0) * far,
            Quat::from_axis_angle(rng.unit(), rng.range(0.0, 3.0)),
        );
        let (lo, hi) = hull.rotated_bounds(pose.rotation);
        let slab = PlaneSlab::from_box(lo + pose.translation, hi + pose.translation);
        // A triangle whose plane passes near the hull's box (grazing, touching, or clear),
        // sometimes along a box axis (coplanar with a box face).
        let n = if k % 5 == 0 {
            [Vec3::X, Vec3::Y, Vec3::Z][k % 3]
        } else {
            rng.unit()
        };
        let half = (hi - lo) * 0.5;
        let reach = half.x * n.x.abs() + half.y * n.y.abs() + half.z * n.z.abs();
        let centre_box = (lo + hi) * 0.5 + pose.translation;
        let prediction = [0.0, 0.02, 0.1][k % 3];
        let gap = reach + prediction + rng.range(-0.05, 0.05) * [1.0, 1.0e-3][k % 2];
        let centre = centre_box + n * gap + rng.unit().cross(n) * rng.range(0.0, 2.0);
        let (t1, t2) = (
            n.any_orthonormal_vector(),
            n.cross(n.any_orthonormal_vector()),
        );
        let size = rng.range(0.1, 5.0);
        let corner = |a: Real| centre + (t1 * a.cos() + t2 * a.sin()) * size;
        let tri = Triangle {
            a: corner(0.0),
            b: corner(2.1),
            c: corner(4.2),
        };
        let Some(tn) = tri.normal() else { continue };
        if slab.clear_of_plane(tn, tn.dot(tri.a), prediction) {
            culled += 1;
            let d = distance_convex(ConvexRef::Triangle(&tri), b, &pose).distance;
            assert!(d > prediction, "culled at distance {d} (case {k})");
            // The hull's own face test rejects it too: no contact is lost.
            let pb = Polyhedron::from_hull(&hull);
            let posed = super::posed_hull(&pb, &pose);
            let mut out = ContactList::new();
            let mut scratch = super::EdgeScratch::new(&pb, &posed);
            let pa = Polyhedron::from_triangle(&tri);
            super::triangle_hull_manifold(
                &pa,
                &pb,
                &posed,
                &pose,
                prediction,
                &mut scratch,
                &mut out,
            );
            assert!(out.is_empty(), "case {k}");
        } else {
            kept += 1;
        }
    }
    assert!(culled > 1000 && kept > 1000, "culled {culled}, kept {kept}");
}

/// A bumpy `n × n` grid of cells (two triangles each) of side `h`, shifted by `offset`,
/// with some collapsed triangles (a repeated corner: zero area) and random heights.
fn bumpy_grid(rng: &mut Rng, n: usize, h: Real, offset: Vec3) -> TriMesh {
    let mut vertices = Vec::new();
    for i in 0..=n {
        for j in 0..=n {
            let y = if (i + j).is_multiple_of(5) {
                0.0
            } else {
                rng.range(-0.5, 0.5)
            };
            vertices.push(offset + Vec3::new(i as Real * h, y, j as Real * h));
        }
    }
    let at = |i: usize, j: usize| (i * (n + 1) + j) as u32;
    let mut indices = Vec::new();
    for i in 0..n {
        for j in 0..n {
            indices.push([at(i, j), at(i, j + 1), at(i + 1, j)]);
            if (i * n + j).is_multiple_of(11) {
                indices.push([at(i + 1, j), at(i, j + 1), at(i, j + 1)]);
            } else {
                indices.push([at(i + 1, j), at(i, j + 1), at(i + 1, j + 1)]);
            }
        }
    }
    TriMesh::new(vertices, indices).unwrap()
}

/// Brute force: every triangle whose box (`Aabb::from_points`, the midphase's leaf test)
/// intersects `aabb`, ascending.
fn brute_candidates(mesh: &TriMesh, aabb: &Aabb) -> Vec<u32> {
    (0..mesh.num_triangles() as u32)
        .filter(|&t| Aabb::from_points(mesh.triangle(t as usize)).intersects(aabb))
        .collect()
}

fn cached(mesh: &TriMesh, aabb: &Aabb) -> Vec<u32> {
    let mut out = SmallVec::new();
    mesh.candidates_sorted(aabb, &mut out);
    out.to_vec()
}

#[test]
fn cached_mesh_queries_equal_the_bvh_and_brute_force() {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    for (offset, h) in [
        (Vec3::ZERO, 1.0),
        (Vec3::new(1.0e3, -20.0, -1.0e3), 2.0),
        (Vec3::new(-3.0, 0.0, -3.0), 0.25),
    ] {
        let mesh = bumpy_grid(&mut rng, 24, h, offset);
        let span = 24.0 * h;
        let (mut found, mut total) = (0usize, 0usize);
        // Bodies walking over the mesh: small steps (cache hits), jumps (misses), sizes from
        // zero to larger than the cache keeps.
        for _ in 0..40 {
            let mut c = offset + Vec3::new(rng.range(0.0, span), 0.0, rng.range(0.0, span));
            let half = match rng.range(0.0, 1.0) {
                x if x < 0.1 => Vec3::ZERO,
                x if x < 0.2 => Vec3::splat(0.3 * span),
                _ => {
                    Vec3::new(
                        rng.range(0.0, 2.0),
                        rng.range(0.0, 1.0),
                        rng.range(0.0, 2.0),
                    ) * h
                }
            };
            for step in 0..30 {
                let jump = if step % 10 == 9 { 3.0 } else { 0.05 };
                c += Vec3::new(
                    rng.range(-1.0, 1.0),
                    rng.range(-0.2, 0.2),
                    rng.range(-1.0, 1.0),
                ) * jump
                    * h;
                let aabb = Aabb::from_center_half_extents(c, half);
                let want = brute_candidates(&mesh, &aabb);
                let mut bvh = Vec::new();
                mesh.view().triangles_in_aabb(&aabb, &mut bvh);
                assert_eq!(bvh, want, "the BVH query is the brute force");
                assert_eq!(cached(&mesh, &aabb), want, "box {aabb:?}");
                total += 1;
                found += usize::from(!want.is_empty());
            }
        }
        assert!(
            found > total / 2,
            "{found} of {total} queries found triangles"
        );
        // A box touching triangles' boxes exactly (a face shared with a vertex's coordinate).
        for t in (0..mesh.num_triangles()).step_by(37) {
            let b = Aabb::from_points(mesh.triangle(t));
            let touch = Aabb::new(b.max, b.max + Vec3::splat(0.1 * h));
            assert_eq!(cached(&mesh, &touch), brute_candidates(&mesh, &touch));
            assert!(cached(&mesh, &touch).contains(&(t as u32)));
            let inner = Aabb::from_center_half_extents(b.center(), Vec3::ZERO);
            assert_eq!(cached(&mesh, &inner), brute_candidates(&mesh, &inner));
        }
        // Non-finite and inverted boxes go to the BVH.
        let nan = Aabb::new(Vec3::splat(Real::NAN), Vec3::splat(Real::NAN));
        let mut bvh = Vec::new();
        mesh.view().triangles_in_aabb(&nan, &mut bvh);
        assert_eq!(cached(&mesh, &nan), bvh);
        let inverted = Aabb::new(offset + Vec3::splat(2.0), offset + Vec3::splat(1.0));
        let mut bvh = Vec::new();
        mesh.view().triangles_in_aabb(&inverted, &mut bvh);
        assert_eq!(cached(&mesh, &inverted), bvh);
    }
}

#[test]
fn cached_mesh_queries_follow_moved_vertices_and_clones() {
    let mut rng = Rng(0x2545_F491_4F6C_DD1D);
    let mut mesh = bumpy_grid(&mut rng, 16, 1.0, Vec3::ZERO);
    let aabb = Aabb::from_center_half_extents(Vec3::new(8.2, 0.0, 8.3), Vec3::splat(0.6));
    let before = cached(&mesh, &aabb);
    assert_eq!(before, brute_candidates(&mesh, &aabb));
    assert!(!before.is_empty());
    // The same box again (now from the cache), then on a clone (same contents, same stamp).
    assert_eq!(cached(&mesh, &aabb), before);
    let copy = mesh.clone();
    assert_eq!(cached(&copy, &aabb), before);
    // Move the vertices away: the cached entry must not answer for the moved mesh.
    let moved: Vec<Vec3> = mesh
        .vertices()
        .iter()
        .map(|v| *v + Vec3::new(5.0, 0.0, 0.0))
        .collect();
    mesh.set_vertices(moved).unwrap();
    let after = cached(&mesh, &aabb);
    assert_eq!(after, brute_candidates(&mesh, &aabb));
    assert_ne!(after, before);
    // The unmoved clone still answers with its own triangles.
    assert_eq!(cached(&copy, &aabb), before);
    // A mesh deserialised from the clone gets a stamp of its own and the same answers.
    let bytes = postcard::to_allocvec(&copy).unwrap();
    let back: TriMesh = postcard::from_bytes(&bytes).unwrap();
    assert_eq!(back, copy);
    assert_eq!(cached(&back, &aabb), before);
}

/// The general path's contacts of triangle `tri` (A) against `b`: what `RoundInMesh`
/// replaces.
fn general_contacts(tri: &Triangle, b: ConvexRef<'_>, pose: &Isometry, pred: Real) -> ContactList {
    let cfg = crate::narrowphase::ManifoldConfig {
        prediction: pred,
        ..Default::default()
    };
    let mut out = ContactList::new();
    crate::narrowphase::dispatcher::convex_convex_into(
        ConvexRef::Triangle(tri),
        b,
        pose,
        &cfg,
        false,
        &mut out,
    );
    out
}

#[test]
fn round_shapes_in_the_mesh_frame_match_the_general_path() {
    let mut rng = Rng(0x2B99_2DDF_A232_49D6);
    let sphere = Sphere::new(0.6).unwrap();
    let capsule = Capsule::new(0.35, 0.8).unwrap();
    let shapes = [ConvexRef::Sphere(&sphere), ConvexRef::Capsule(&capsule)];
    let (mut compared, mut two_point, mut undecided, mut beyond) = (0, 0, 0, 0);
    for k in 0..12000 {
        let b = shapes[k % 2];
        let far = [Vec3::ZERO, Vec3::new(1.0e3, -700.0, 400.0)][(k / 2) % 2];
        let prediction = [0.0, 0.02, 0.1][k % 3];
        // A triangle with a random or axis normal (a capsule lying on it: coplanar segment).
        let n = if k % 4 == 0 { Vec3::Y } else { rng.unit() };
        let (t1, t2) = (
            n.any_orthonormal_vector(),
            n.cross(n.any_orthonormal_vector()),
        );
        let size = rng.range(0.2, 4.0);
        let centre = far + rng.unit() * rng.range(0.0, 1.0);
        let corner = |a: Real| centre + (t1 * a.cos() + t2 * a.sin()) * size;
        let mut tri = Triangle {
            a: corner(rng.range(0.0, 1.0)),
            b: corner(rng.range(2.0, 3.0)),
            c: corner(rng.range(4.0, 5.0)),
        };
        if k % 13 == 0 {
            // A sliver (the capsule's closed form declines it).
            tri.c = tri.a + (tri.b - tri.a) * 0.4 + n.cross(tri.b - tri.a) * 1.0e-5;
        }
        let Some(tn) = tri.normal() else { continue };
        // The shape's axis: random, or parallel to the plane or to an edge.
        let axis = match k % 5 {
            0 => t1,
            1 => (tri.b - tri.a).normalize(),
            _ => rng.unit(),
        };
        let rot = Quat::from_rotation_arc(Vec3::Y, axis);
        // Height of the core above (or below) the plane: touching, at the prediction,
        // overlapping, or clear by a little.
        let r = match b {
            ConvexRef::Sphere(s) => s.radius(),
            ConvexRef::Capsule(c) => c.radius(),
            _ => unreachable!(),
        };
        let h = match k % 6 {
            0 => r,
            1 => r + prediction,
            2 => r - rng.range(0.0, 0.2),
            _ => r + rng.range(-0.1, 0.3),
        } * if k % 7 == 0 { -1.0 } else { 1.0 };
        let inplane = (t1 * rng.range(-1.5, 1.5) + t2 * rng.range(-1.5, 1.5)) * size;
        let pose = Isometry::new(centre + inplane + tn * h, rot);
        let round = RoundInMesh::new(b, &pose).unwrap();
        let mut fast = ContactList::new();
        let done = round.triangle_contacts(tri.vertices(), tn, prediction, &mut fast);
        if !done {
            assert!(fast.is_empty());
            undecided += 1;
            continue;
        }
        let slow = general_contacts(&tri, b, &pose, prediction);
        let scale = 1.0 + far.length();
        let tol = 2.0e-5 * scale;
        // Contacts within round-off of the prediction may be present in one list only.
        let near_edge = |c: &Contact| (c.distance - prediction).abs() <= tol;
        for (list, other) in [(&fast, &slow), (&slow, &fast)] {
            for (c, id) in list.iter() {
                match other.iter().find(|(_, j)| j == id) {
                    Some((o, _)) => {
                        // The normal joins the core to the triangle: its round-off is the
                        // coordinates' (a few ulps of `scale`) over the core's distance.
                        let core = (r + c.distance).abs().max(0.05);
                        let tol_n = 1.0e-3 + 1.0e-5 * scale / core;
                        assert!(
                            (c.distance - o.distance).abs() <= tol
                                && (c.normal - o.normal).length() <= tol_n
                                && (c.point_b - c.point_a - c.normal * c.distance).length() <= tol,
                            "case {k}: {c:?} vs {o:?}"
                        );
                        // Points on the triangle and on the shape (a clipped end, ids 0
                        // and 1, sits below its segment point, so inside a tilted capsule)
                        // and equal; a single closest pair (id 2) is on the surface and may
                        // slide along a segment parallel to an edge or the face.
                        // (On a sliver, the nearest edge: the barycentric closest point
                        // divides by a near-zero area.)
                        let to_tri = [(tri.a, tri.b), (tri.b, tri.c), (tri.c, tri.a)]
                            .map(|(u, v)| {
                                (closest_point_segment(c.point_a, u, v).0 - c.point_a).length()
                            })
                            .into_iter()
                            .fold(
                                (closest_point_triangle(c.point_a, tri.a, tri.b, tri.c)
                                    - c.point_a)
                                    .length(),
                                Real::min,
                            );
                        let (sp, sq) = (round.o + round.p, round.o + round.q);
                        let ds = (closest_point_segment(c.point_b, sp, sq).0 - c.point_b).length();
                        assert!(
                            to_tri <= tol && ds <= r + tol && (*id != 2 || (ds - r).abs() <= tol),
                            "case {k}: {c:?} not on the shapes ({to_tri} {ds} {r})"
                        );
                        if *id != 2 {
                            assert!(
                                (c.point_a - o.point_a).length() <= 1.0e-3 * scale
                                    && (c.point_b - o.point_b).length() <= 1.0e-3 * scale,
                                "case {k}: {c:?} vs {o:?}"
                            );
                        }
                        assert!(c.distance <= prediction, "case {k}: {c:?}");
                    }
                    None => assert!(
                        near_edge(c),
                        "case {k}: only one path gives {c:?} ({fast:?} vs {slow:?})"
                    ),
                }
            }
        }
        // The deepest contact is the true distance (GJK/EPA on the pair).
        let truth = distance_convex(ConvexRef::Triangle(&tri), b, &pose).distance;
        match fast.iter().map(|(c, _)| c.distance).reduce(Real::min) {
            Some(d) => assert!(
                (d - truth).abs() <= 1.0e-4 * scale,
                "case {k}: {d} vs {truth}"
            ),
            None => {
                assert!(truth >= prediction - tol, "case {k}: none at {truth}");
                beyond += 1;
            }
        }
        two_point += usize::from(fast.len() == 2);
        compared += 1;
    }
    assert!(
        compared > 8000 && two_point > 300 && undecided > 100 && beyond > 300,
        "compared {compared}, two-point {two_point}, undecided {undecided}, beyond {beyond}"
    );
}
