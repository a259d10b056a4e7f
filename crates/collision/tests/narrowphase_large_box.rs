//! Hulls against boxes much larger than themselves (a ground box): the guided path cuts the
//! box down to the hull's neighbourhood (`large_box_hull` in `narrowphase/polyhedron_guided.rs`)
//! before GJK/EPA. Every manifold is checked against the brute-force polytope oracle
//! (`polytope_common`, f64, unpruned SAT), in both orders, on faces, edges and corners of the
//! box, apart within the prediction, touching, coplanar (a hull face flat on the box), deep,
//! and 1 km from the origin; and against the full separating-axis manifold of the uncut box.

mod polytope_common;

use carom_collision::math::{Isometry, Quat, Real, Vec3};
use carom_collision::narrowphase::polyhedron::{polyhedron_manifold, Polyhedron};
use carom_collision::narrowphase::{ContactManifold, Dispatcher, ManifoldConfig};
use carom_collision::query::Contact;
use carom_collision::shape::{Cuboid, Shape, SupportMap};
use polytope_common::*;
use proptest::prelude::*;

/// How the hull meets the box.
#[derive(Debug, Clone, Copy)]
enum Place {
    /// Random orientation over a point of a face (clamped to an edge or a corner at times).
    Random,
    /// One of the hull's faces flat on the box's face.
    Flat,
}

#[derive(Debug, Clone)]
struct Case {
    half: Vec3,
    place: Place,
    /// Face of the box: axis and side.
    face: (usize, bool),
    /// Position on the face, in [-1.2, 1.2]² of its half extents (clamped to [-1, 1]).
    at: (Real, Real),
    rot: Quat,
    /// Depth along the face normal (negative: apart).
    depth: Real,
    far: Vec3,
    /// Hull first.
    swap: bool,
}

fn case() -> impl Strategy<Value = Case> {
    (
        (6.0..300.0 as Real, 2.0..60.0 as Real, 6.0..300.0 as Real),
        prop_oneof![Just(Place::Random), Just(Place::Flat)],
        (0usize..3, any::<bool>()),
        (-1.2..1.2 as Real, -1.2..1.2 as Real),
        rotation(),
        prop_oneof![
            Just(0.0 as Real),
            -0.015..0.0 as Real,
            0.0..0.05 as Real,
            0.05..0.4 as Real
        ],
        prop_oneof![Just(0.0 as Real), Just(1.0e3 as Real)],
        unit(),
        any::<bool>(),
    )
        .prop_map(
            |((x, y, z), place, face, at, rot, depth, far, far_dir, swap)| Case {
                half: Vec3::new(x, y, z),
                place,
                face,
                at,
                rot,
                depth,
                far: far_dir * far,
                swap,
            },
        )
}

/// The hull's pose in the box's frame for `c`.
fn place(hull: &Shape, c: &Case) -> Isometry {
    let (axis, positive) = c.face;
    let mut n = Vec3::ZERO;
    n[axis] = if positive { 1.0 } else { -1.0 };
    let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
    let mut p = n * c.half[axis];
    p[u] = c.at.0.clamp(-1.0, 1.0) * c.half[u];
    p[v] = c.at.1.clamp(-1.0, 1.0) * c.half[v];
    let rot = match c.place {
        Place::Random => c.rot,
        Place::Flat => {
            let faces = local_faces(hull);
            let (m, _, _) = pick(&faces, 0.5 * (c.rot.x + 1.0));
            Quat::from_rotation_arc(m, -n)
        }
    };
    // The hull's lowest point along -n sits `depth` below the face.
    let low = hull
        .as_convex()
        .unwrap()
        .support_world(&Isometry::from_rotation(rot), -n)
        .dot(n);
    Isometry::new(p + n * (-low - c.depth), rot)
}

/// Contacts of the manifold in the world frame, query convention (normal from A to B).
fn world_contacts(m: &ContactManifold) -> Vec<Contact> {
    m.points
        .iter()
        .map(|p| Contact {
            distance: p.distance,
            point_a: p.point_a(),
            point_b: p.point_b,
            normal: -p.normal,
        })
        .collect()
}

fn check(hull: &Shape, c: &Case) -> Result<(), TestCaseError> {
    let bx = Shape::Cuboid(Cuboid::new(c.half).unwrap());
    let pose_box = Isometry::new(c.far, Quat::from_rotation_y(0.3));
    let pose_hull = pose_box.mul(&place(hull, c));
    let (a, pa, b, pb) = if c.swap {
        (hull, pose_hull, &bx, pose_box)
    } else {
        (&bx, pose_box, hull, pose_hull)
    };
    // Coordinates reach the box's size: the f32 tolerance grows with them.
    let tol = tolerance(c.far + c.half);
    let prediction = 0.02;
    let d = Dispatcher::new(ManifoldConfig {
        prediction,
        ..Default::default()
    });
    let mut m = ContactManifold::new();
    d.update_manifold(a, &pa, b, &pb, &mut m).unwrap();
    let got = world_contacts(&m);
    // Points within the prediction count as contacts; the oracle wants them at the
    // tolerance, so apart configurations are checked for distance only.
    let kind = Kind::Random;
    if c.depth >= 0.0 {
        check_against_polytope(a, &pa, b, &pb, &got, kind, tol + r(prediction))
            .map_err(|e| TestCaseError::fail(format!("{c:?}: {e}\n{got:?}")))?;
    } else {
        // Apart by -depth along the face normal (less near an edge or a corner): a point at
        // no less than the distance, and only within the prediction.
        for k in &got {
            prop_assert!(k.distance <= prediction + 1.0e-4, "{c:?}: {k:?}");
        }
    }
    // The full separating-axis manifold of the uncut box: the same deepest distance.
    fn view(s: &Shape) -> Polyhedron<'_> {
        match s {
            Shape::Cuboid(x) => Polyhedron::from_cuboid(x),
            Shape::ConvexHull(h) => Polyhedron::from_hull(h),
            _ => unreachable!(),
        }
    }
    let sat = polyhedron_manifold(&view(a), &view(b), &pa.inv_mul(&pb), prediction);
    let deepest = |ks: &mut dyn Iterator<Item = Real>| ks.fold(Real::INFINITY, Real::min);
    let want = deepest(&mut sat.iter().map(|(k, _)| k.distance));
    let have = deepest(&mut got.iter().map(|k| k.distance));
    if want <= 0.0 || have <= 0.0 {
        prop_assert!(
            (want - have).abs() <= 2.0e-3 * (1.0 + want.abs()) + 4.0 * tol as Real,
            "{c:?}: deepest {have} vs full SAT {want}"
        );
    }
    Ok(())
}

proptest! {
    #![proptest_config(fixed_seed(400, 0x6361_726f_6d08))]

    #[test]
    fn hull_against_large_box_matches_oracle(h in hull(6..24), c in case()) {
        check(&h, &c)?;
    }
}

/// A fixed hull resting flat at the centre of the ground box of scenes 1–4 (250 × 50 × 250
/// half extents): four points or more at the exact gap, both orders, near the origin and
/// 1 km out, touching, within the prediction and overlapping.
#[test]
fn flat_hull_on_ground_box() {
    let h = hull_of(&[
        Vec3::new(-0.5, -0.3, -0.5),
        Vec3::new(0.5, -0.3, -0.5),
        Vec3::new(0.5, -0.3, 0.5),
        Vec3::new(-0.5, -0.3, 0.5),
        Vec3::new(0.0, 0.6, 0.0),
        Vec3::new(0.3, 0.2, 0.1),
    ]);
    for far in [0.0 as Real, 1.0e3] {
        for gap in [0.0 as Real, 0.01, -0.004, -0.1] {
            for swap in [false, true] {
                let c = Case {
                    half: Vec3::new(250.0, 50.0, 250.0),
                    place: Place::Random,
                    face: (1, true),
                    at: (0.0, 0.0),
                    rot: Quat::IDENTITY,
                    depth: -gap,
                    far: Vec3::new(far, 0.0, far),
                    swap,
                };
                check(&h, &c).unwrap();
                let bx = Shape::Cuboid(Cuboid::new(c.half).unwrap());
                let pose_box = Isometry::new(c.far, Quat::IDENTITY);
                let pose_hull =
                    Isometry::new(c.far + Vec3::new(3.0, 50.3 + gap, -7.0), Quat::IDENTITY);
                let (a, pa, b, pb) = if swap {
                    (&h, pose_hull, &bx, pose_box)
                } else {
                    (&bx, pose_box, &h, pose_hull)
                };
                let d = Dispatcher::new(ManifoldConfig::default());
                let mut m = ContactManifold::new();
                d.update_manifold(a, &pa, b, &pb, &mut m).unwrap();
                assert!(m.len() >= 4, "far {far} gap {gap} swap {swap}: {m:?}");
                let tol = 2.0e-4 + 16.0 * Real::EPSILON * (far + 300.0);
                for p in &m.points {
                    assert!(
                        (p.distance - gap).abs() <= tol,
                        "far {far} gap {gap}: {p:?}"
                    );
                    assert!((p.normal.y.abs() - 1.0).abs() < 1.0e-5, "{p:?}");
                }
            }
        }
    }
}
