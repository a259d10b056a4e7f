//! The box–box manifold settled by the boxes' own separating-axis test (no GJK for apart
//! pairs), against analytic configurations, the exact box–box query (GJK on apart pairs)
//! and the guided polyhedron path it replaced (which clips with the general polyhedron clipper).

mod common;

use carom_collision::math::{consts::PI, Isometry, Quat, Real, Vec3, EPSILON};
use carom_collision::narrowphase::contact_cuboid_cuboid::cuboid_cuboid_manifold_into;
use carom_collision::narrowphase::polyhedron::{polyhedron_manifold_guided, Polyhedron};
use carom_collision::narrowphase::{ContactManifold, Dispatcher, ManifoldConfig};
use carom_collision::query::contact_cuboid_cuboid::{
    contact_cuboid_cuboid, cuboid_cuboid_axis, cuboid_cuboid_sat, CuboidSat,
};
use carom_collision::query::Contact;
use carom_collision::shape::{ConvexRef, Cuboid, Shape};
use common::Rng;

/// Length tolerance for boxes of size ~1 at `far` from the origin.
fn tolerance(far: Real) -> Real {
    2.0e-4_f32.max(2.0e3 * f32::EPSILON) as Real + 16.0 * EPSILON * far
}

fn manifold(a: &Cuboid, b: &Cuboid, pose_ab: &Isometry, prediction: Real) -> Vec<Contact> {
    let mut out = Vec::new();
    cuboid_cuboid_manifold_into(a, b, pose_ab, prediction, &mut out);
    out.into_iter().map(|(c, _)| c).collect()
}

/// How far `p` (in the box's frame) is from the box's surface (0 on it).
fn off_surface(h: Vec3, p: Vec3) -> Real {
    let q = p.abs() - h;
    let outside = q.max(Vec3::ZERO).length();
    if outside > 0.0 {
        outside
    } else {
        -q.max_element()
    }
}

fn random_box(rng: &mut Rng) -> Cuboid {
    Cuboid::new(Vec3::new(
        rng.range(0.1, 2.0),
        rng.range(0.1, 2.0),
        rng.range(0.1, 2.0),
    ))
    .unwrap()
}

fn random_pose(rng: &mut Rng, reach: Real) -> Isometry {
    let rotation = match rng.range(0.0, 3.0) as u32 {
        // Aligned and nearly aligned boxes: parallel faces and edges.
        0 => Quat::IDENTITY,
        1 => Quat::from_axis_angle(rng.unit(), rng.range(-1e-3, 1e-3)),
        _ => Quat::from_axis_angle(rng.unit(), rng.range(0.0, PI)),
    };
    Isometry::new(rng.unit() * rng.range(0.0, reach), rotation)
}

#[test]
fn the_axis_is_the_sat_overlap_and_a_lower_bound_of_the_distance() {
    let mut rng = Rng::new(7);
    let (mut overlapping, mut within, mut beyond) = (0, 0, 0);
    for _ in 0..4000 {
        let (a, b) = (random_box(&mut rng), random_box(&mut rng));
        let pose = random_pose(&mut rng, 5.0);
        let prediction = rng.range(0.0, 0.5);
        let axis = cuboid_cuboid_axis(&a, &b, &pose, prediction);
        match cuboid_cuboid_sat(&a, &b, &pose, prediction) {
            CuboidSat::Overlap {
                depth,
                normal,
                axis: kind,
            } => {
                // Bit for bit the SAT's overlap branch.
                assert_eq!(axis, Some((depth, normal, kind)));
                overlapping += 1;
            }
            CuboidSat::Final(_) => {
                // The exact distance (GJK) of the query, with no prediction cut-off.
                let exact = contact_cuboid_cuboid(&a, &b, &pose, 100.0)
                    .unwrap()
                    .distance;
                let tol = tolerance(0.0);
                match axis {
                    None => {
                        assert!(exact > prediction - tol, "{exact} vs {prediction}");
                        beyond += 1;
                    }
                    Some((overlap, normal, _)) => {
                        assert!(-overlap <= exact + tol, "{} vs {exact}", -overlap);
                        assert!(-overlap <= prediction);
                        assert!((normal.length() - 1.0).abs() < 1e-5);
                        within += 1;
                    }
                }
            }
        }
    }
    eprintln!("overlapping {overlapping}, apart within {within}, beyond {beyond}");
    assert!(overlapping > 200 && within > 200 && beyond > 200);
}

/// Every point on both boxes, `point_b = point_a + n d`, the distance at least the exact
/// one, and a contact whenever the boxes are within the prediction.
#[test]
fn apart_and_overlapping_manifolds_lie_on_the_boxes() {
    let mut rng = Rng::new(11);
    let mut apart_points = 0;
    for k in 0..4000 {
        let (a, b) = (random_box(&mut rng), random_box(&mut rng));
        let pose = random_pose(&mut rng, 4.0);
        let prediction = rng.range(0.0, 0.5);
        let exact = contact_cuboid_cuboid(&a, &b, &pose, 100.0)
            .unwrap()
            .distance;
        let contacts = manifold(&a, &b, &pose, prediction);
        let tol = tolerance(0.0);
        if exact <= prediction - tol {
            assert!(!contacts.is_empty(), "case {k}: no contact at {exact}");
        }
        if exact > prediction + tol {
            // Apart beyond the prediction: at most lower-bound points within it.
            assert!(contacts.iter().all(|c| c.distance <= prediction));
        }
        for c in &contacts {
            assert!(c.distance <= prediction + tol, "case {k}: {c:?}");
            assert!((c.point_b - c.point_a - c.normal * c.distance).length() < tol);
            assert!(
                off_surface(a.half_extents(), c.point_a) < tol,
                "case {k}: {c:?}"
            );
            let pb = pose.inverse_transform_point(c.point_b);
            assert!(off_surface(b.half_extents(), pb) < tol, "case {k}: {c:?}");
            if exact > 0.0 {
                // Two points on the boxes are at least the boxes' distance apart.
                assert!(
                    c.distance >= exact - tol,
                    "case {k}: {} < {exact}",
                    c.distance
                );
                apart_points += 1;
            }
        }
    }
    assert!(apart_points > 500, "{apart_points}");
}

/// Overlapping pairs give the points of the guided polyhedron path it replaced (its general
/// clipper against the boxes' axis-aligned one): the same points up to round-off, in any
/// order, with the same normals and distances.
#[test]
fn overlapping_pairs_match_the_guided_path() {
    let mut rng = Rng::new(5);
    let mut checked = 0;
    for k in 0..3000 {
        let (a, b) = (random_box(&mut rng), random_box(&mut rng));
        let pose = random_pose(&mut rng, 2.0);
        if !matches!(
            cuboid_cuboid_sat(&a, &b, &pose, 0.02),
            CuboidSat::Overlap { .. }
        ) {
            continue;
        }
        let mut guided = Vec::new();
        let (pa, pb) = (Polyhedron::from_cuboid(&a), Polyhedron::from_cuboid(&b));
        let (ca, cb) = (ConvexRef::Cuboid(&a), ConvexRef::Cuboid(&b));
        polyhedron_manifold_guided(&pa, &pb, ca, cb, &pose, 0.02, &mut guided);
        let ours = manifold(&a, &b, &pose, 0.02);
        let tol = 1e-4 * (1.0 + pose.translation.length());
        let same = |x: &Contact, y: &Contact| {
            (x.point_a - y.point_a).length() < tol
                && (x.point_b - y.point_b).length() < tol
                && (x.normal - y.normal).length() < 1e-4
                && (x.distance - y.distance).abs() < tol
        };
        assert_eq!(ours.len(), guided.len(), "case {k}: {ours:?} vs {guided:?}");
        for c in &ours {
            assert!(
                guided.iter().any(|(g, _)| same(c, g)),
                "case {k}: {c:?} not in {guided:?}"
            );
        }
        for (g, _) in &guided {
            assert!(
                ours.iter().any(|c| same(c, g)),
                "case {k}: {g:?} not in {ours:?}"
            );
        }
        checked += 1;
    }
    assert!(checked > 500, "{checked}");
}

/// A box face-on above another at gap `g`, near the origin and 1 km from it, through the
/// dispatcher's persistent manifold: four points at distance `g` while `g` is within the
/// prediction, none beyond.
#[test]
fn a_box_above_a_box_gets_four_points_at_the_gap() {
    let ground = Shape::from(Cuboid::new(Vec3::new(5.0, 0.5, 5.0)).unwrap());
    let cube = Shape::from(Cuboid::new(Vec3::splat(0.5)).unwrap());
    let d = Dispatcher::new(ManifoldConfig::default());
    for far in [0.0, 1000.0] {
        let tol = tolerance(far);
        let origin = Vec3::new(far, 0.3 * far, -far);
        let pose_a = Isometry::new(origin, Quat::IDENTITY);
        for g in [0.0, 0.001, 0.015, 0.019, 0.03, 0.5] {
            let pose_b = Isometry::new(origin + Vec3::new(0.3, 1.0 + g, -0.2), Quat::IDENTITY);
            let mut m = ContactManifold::new();
            d.update_manifold(&ground, &pose_a, &cube, &pose_b, &mut m)
                .unwrap();
            if g > 0.02 + tol {
                assert!(m.is_empty(), "gap {g}: {:?}", m.points);
                continue;
            }
            assert_eq!(m.len(), 4, "gap {g} at {far}");
            for p in &m.points {
                assert!((p.distance - g).abs() < tol, "{} vs {g}", p.distance);
                assert!((p.normal - Vec3::NEG_Y).length() < 1e-5, "{:?}", p.normal);
            }
        }
    }
}

/// A box tilted about two axes above the ground: the deepest point is the lowest corner,
/// at its analytic height; the reference face is the ground's.
#[test]
fn a_tilted_box_above_the_ground_touches_at_its_lowest_corner() {
    let ground = Cuboid::new(Vec3::new(50.0, 0.5, 50.0)).unwrap();
    let cube = Cuboid::new(Vec3::new(0.5, 0.3, 0.4)).unwrap();
    let mut rng = Rng::new(3);
    for _ in 0..200 {
        let rotation = Quat::from_axis_angle(rng.unit(), rng.range(0.0, PI));
        let lowest = (0..8)
            .map(|i| {
                let s = |bit: usize| if i & bit != 0 { 1.0 } else { -1.0 };
                let h = cube.half_extents();
                (rotation * Vec3::new(s(1) * h.x, s(2) * h.y, s(4) * h.z)).y
            })
            .fold(Real::INFINITY, Real::min);
        let g = rng.range(-0.01, 0.1);
        let pose = Isometry::new(Vec3::new(1.0, 0.5 + g - lowest, -2.0), rotation);
        let contacts = manifold(&ground, &cube, &pose, 0.1);
        let min = contacts
            .iter()
            .map(|c| c.distance)
            .fold(Real::INFINITY, Real::min);
        assert!((min - g).abs() < 1e-4, "{min} vs {g}");
        for c in &contacts {
            assert!((c.normal - Vec3::Y).length() < 1e-5);
            assert!((c.point_a.y - 0.5).abs() < 1e-5);
        }
    }
}

/// Two edges crossing at right angles above each other, apart by `g`: one point, at the
/// gap, between the two edges' midpoints.
#[test]
fn crossing_edges_apart_give_one_point_at_the_gap() {
    let h = 0.5;
    let cube = Cuboid::new(Vec3::splat(h)).unwrap();
    let top = h * (2.0 as Real).sqrt();
    let rot_a = Quat::from_rotation_x(PI / 4.0); // top edge along x
    for g in [0.0, 0.004, 0.015] {
        // B's bottom edge along z, `g` above A's top edge, B in A's frame.
        let world_b = Isometry::new(
            Vec3::new(0.0, 2.0 * top + g, 0.0),
            Quat::from_rotation_z(PI / 4.0),
        );
        let pose_ab = Isometry::new(Vec3::ZERO, rot_a).inv_mul(&world_b);
        let contacts = manifold(&cube, &cube, &pose_ab, 0.02);
        assert_eq!(contacts.len(), 1, "gap {g}: {contacts:?}");
        let c = contacts[0];
        assert!((c.distance - g).abs() < 1e-5, "{} vs {g}", c.distance);
        let world_a = rot_a * c.point_a;
        assert!(
            (world_a - Vec3::new(0.0, top, 0.0)).length() < 1e-4,
            "{world_a}"
        );
    }
}
