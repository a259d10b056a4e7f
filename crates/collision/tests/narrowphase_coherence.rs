//! The GJK-guided polyhedral manifold (large hulls) against the full SAT manifold, and the
//! spatial-coherence shortcut of `Dispatcher::update_manifold` against fresh generation.

mod common;

use carom_collision::math::{Isometry, Quat, Real, Vec3};
use carom_collision::narrowphase::polyhedron::{
    polyhedron_manifold, polyhedron_manifold_guided, Polyhedron,
};
use carom_collision::narrowphase::{ContactManifold, Dispatcher, COHERENCE_DISTANCE};
use carom_collision::query::{self, Contact};
use carom_collision::shape::{ConvexHull, ConvexRef, Cuboid, Shape};
use common::Rng;

fn random_hull(rng: &mut Rng, n: usize) -> ConvexHull {
    let pts: Vec<Vec3> = (0..n).map(|_| rng.unit() * rng.range(0.5, 1.0)).collect();
    ConvexHull::new(&pts).unwrap()
}

fn inside(h: &ConvexHull, p: Vec3, pose: &Isometry, tol: Real) -> bool {
    let q = pose.inverse_transform_point(p);
    h.faces().iter().all(|f| f.normal.dot(q) - f.offset <= tol)
}

#[test]
fn guided_manifold_agrees_with_the_full_sat() {
    let mut rng = Rng::new(21);
    let mut checked = 0;
    let mut multi = 0;
    for k in 0..80 {
        let (ha, hb) = (random_hull(&mut rng, 32), random_hull(&mut rng, 32));
        let (sa, sb) = (Shape::ConvexHull(ha.clone()), Shape::ConvexHull(hb.clone()));
        let mut pose = Isometry::new(
            rng.unit() * 1.5,
            Quat::from_axis_angle(rng.unit(), rng.range(0.0, 3.0)),
        );
        let c0 = query::contact(&sa, &Isometry::IDENTITY, &sb, &pose, 10.0)
            .unwrap()
            .unwrap();
        pose.translation -= c0.normal * (c0.distance + rng.range(0.001, 0.03));
        if k % 4 == 0 {
            // Face-on: B's face against A's face, the resting case with several points.
            let fa = &ha.faces()[0];
            let fb = &hb.faces()[0];
            let rot = Quat::from_rotation_arc(fb.normal, -fa.normal);
            pose = Isometry::new(Vec3::ZERO, rot);
            let lowest = hb
                .vertices()
                .iter()
                .map(|v| fa.normal.dot(pose.transform_point(*v)))
                .fold(Real::INFINITY, Real::min);
            pose.translation = fa.normal * (fa.offset - lowest - 0.01);
        }
        let (sat, guided) = full_sat_and_guided(&ha, &hb, &pose, 0.0);
        assert_eq!(sat.is_empty(), guided.is_empty(), "case {k}");
        if sat.is_empty() {
            continue;
        }
        checked += 1;
        let tol = 2e-3 + 0.02 * min_distance(&sat).abs();
        assert!(
            (min_distance(&sat) - min_distance(&guided)).abs() < tol,
            "case {k}"
        );
        for (c, _) in &guided {
            assert!(c.distance.is_finite() && c.normal.is_finite());
            let slack = 1e-3 + c.distance.abs();
            assert!(inside(&ha, c.point_b, &Isometry::IDENTITY, slack));
            assert!(inside(&hb, c.point_a, &pose, slack));
        }
        if k % 4 == 0 {
            assert!(
                guided.len() >= 3,
                "face-on case {k}: {} points",
                guided.len()
            );
            multi += 1;
        }
    }
    assert!(checked > 40 && multi >= 15, "{checked} {multi}");
}

#[test]
fn coherent_poses_reuse_points_and_moves_regenerate() {
    let d = Dispatcher::default();
    let ground = Shape::Cuboid(Cuboid::new(Vec3::new(3.0, 0.5, 3.0)).unwrap());
    let b = Shape::Cuboid(Cuboid::new(Vec3::splat(0.5)).unwrap());
    let pose = |x: Real, tilt: Real| {
        Isometry::new(
            Vec3::new(x, 0.99, 0.0),
            Quat::from_rotation_z(tilt) * Quat::from_rotation_y(0.3),
        )
    };
    let fresh = |p: &Isometry| {
        let mut m = ContactManifold::new();
        d.update_manifold(&ground, &Isometry::IDENTITY, &b, p, &mut m)
            .unwrap();
        m
    };
    let mut m = fresh(&pose(0.0, 0.0));
    assert_eq!(m.len(), 4);
    assert!(m.generated_at.is_some());
    // A tiny move: the points are kept (same local points), refreshed distances.
    let small = pose(0.2 * COHERENCE_DISTANCE, 0.0);
    let old: Vec<Vec3> = m.points.iter().map(|p| p.local_b).collect();
    d.update_manifold(&ground, &Isometry::IDENTITY, &b, &small, &mut m)
        .unwrap();
    assert_eq!(old, m.points.iter().map(|p| p.local_b).collect::<Vec<_>>());
    let again = fresh(&small);
    for (p, q) in m.points.iter().zip(&again.points) {
        assert!((p.distance - q.distance).abs() < 1e-5);
        assert!((p.point_b - q.point_b).length() < 2.0 * COHERENCE_DISTANCE);
    }
    // A real move or a tilt: generated again, identical to a fresh manifold.
    for p in [pose(0.01, 0.0), pose(0.0, 0.05)] {
        d.update_manifold(&ground, &Isometry::IDENTITY, &b, &p, &mut m)
            .unwrap();
        let f = fresh(&p);
        assert_eq!(m.len(), f.len());
        for (x, y) in m.points.iter().zip(&f.points) {
            assert_eq!(x.feature, y.feature);
            assert!((x.point_b - y.point_b).length() < 1e-5);
            assert!((x.distance - y.distance).abs() < 1e-5);
        }
    }
    // Clearing forgets the generation pose.
    m.clear();
    assert!(m.generated_at.is_none());
}

/// Hulls touching within round-off (face-on, tilted and far from the origin), where EPA's
/// polytope is degenerate and the guided path re-measures EPA's contact along its normal
/// instead of running the full SAT: the manifold must still match the full SAT's.
#[test]
fn guided_manifold_on_touching_hulls_matches_the_full_sat() {
    let mut rng = Rng::new(77);
    let mut checked = 0;
    for k in 0..120 {
        let (ha, hb) = (random_hull(&mut rng, 24), random_hull(&mut rng, 24));
        let fa = &ha.faces()[k % ha.faces().len()];
        let fb = &hb.faces()[0];
        // B's face against A's face, turned about the normal, tilted a little in one case
        // out of three (edge or vertex touching), gap in [-1e-5, 1e-5].
        let spin = Quat::from_axis_angle(fa.normal, rng.range(0.0, std::f32::consts::TAU as Real));
        let tilt = if k % 3 == 0 {
            Quat::from_axis_angle(rng.unit(), rng.range(0.0, 0.2))
        } else {
            Quat::IDENTITY
        };
        let rot = tilt * spin * Quat::from_rotation_arc(fb.normal, -fa.normal);
        let lateral = rng.unit() * 0.3;
        let lateral = lateral - fa.normal * fa.normal.dot(lateral);
        let mut pose = Isometry::new(lateral, rot);
        let lowest = hb
            .vertices()
            .iter()
            .map(|v| fa.normal.dot(pose.transform_point(*v)))
            .fold(Real::INFINITY, Real::min);
        pose.translation += fa.normal * (fa.offset - lowest + rng.range(-1.0e-5, 1.0e-5));
        if k % 4 == 1 {
            // The same relative pose, built from world poses far from the origin.
            let wa = Isometry::new(Vec3::new(1.0e3, -2.0e3, 5.0e2), Quat::IDENTITY);
            let wb = wa * pose;
            pose = wa.inverse() * wb;
        }
        let (sat, guided) = full_sat_and_guided(&ha, &hb, &pose, 0.01);
        assert_eq!(sat.is_empty(), guided.is_empty(), "case {k}");
        if sat.is_empty() {
            continue;
        }
        checked += 1;
        assert!(
            (min_distance(&sat) - min_distance(&guided)).abs() < 2.0e-4,
            "case {k}"
        );
        let n_sat = sat[0].0.normal;
        for (c, _) in &guided {
            assert!(c.distance.is_finite() && c.normal.is_finite());
            assert!(c.normal.dot(n_sat) > 0.99, "case {k}: normal");
            let slack = 1e-3 + c.distance.abs();
            assert!(
                inside(&ha, c.point_b, &Isometry::IDENTITY, slack),
                "case {k}"
            );
            assert!(inside(&hb, c.point_a, &pose, slack), "case {k}");
        }
    }
    assert!(checked > 100, "{checked}");
}

/// A manifold's points with their feature ids.
type Points = Vec<(Contact, u32)>;

/// The full-SAT manifold and the guided one (one GJK/EPA, then clipping) of two hulls at
/// `pose` (B in A's frame), as (contact, feature id) lists.
fn full_sat_and_guided(
    ha: &ConvexHull,
    hb: &ConvexHull,
    pose: &Isometry,
    prediction: Real,
) -> (Points, Points) {
    let (pa, pb) = (Polyhedron::from_hull(ha), Polyhedron::from_hull(hb));
    let sat = polyhedron_manifold(&pa, &pb, pose, prediction);
    let mut guided: Points = Vec::new();
    polyhedron_manifold_guided(
        &pa,
        &pb,
        ConvexRef::ConvexHull(ha),
        ConvexRef::ConvexHull(hb),
        pose,
        prediction,
        &mut guided,
    );
    (sat.into_iter().collect(), guided)
}

/// The smallest signed distance of a manifold's points (infinity when empty).
fn min_distance(v: &[(Contact, u32)]) -> Real {
    v.iter()
        .map(|c| c.0.distance)
        .fold(Real::INFINITY, Real::min)
}
