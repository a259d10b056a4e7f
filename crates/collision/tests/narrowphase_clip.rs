//! Narrowphase manifolds against analytic oracles: box on box, box on edge, capsule on box,
//! cylinder on plane, random hull–hull against EPA and containment, persistence.

mod common;

use carom_collision::math::{Isometry, Quat, Real, Vec3};
use carom_collision::narrowphase::{ContactManifold, Dispatcher, ManifoldConfig};
use carom_collision::query;
use carom_collision::shape::{Capsule, ConvexHull, Cuboid, Cylinder, Plane, Shape};
use common::Rng;

fn cuboid(x: Real, y: Real, z: Real) -> Shape {
    Shape::Cuboid(Cuboid::new(Vec3::new(x, y, z)).unwrap())
}

fn step(d: &Dispatcher, a: &Shape, pa: &Isometry, b: &Shape, pb: &Isometry) -> ContactManifold {
    let mut m = ContactManifold::new();
    d.update_manifold(a, pa, b, pb, &mut m).unwrap();
    m
}

#[test]
fn box_resting_flat_on_box_gives_four_corner_points() {
    let d = Dispatcher::default();
    let ground = cuboid(2.0, 0.5, 2.0);
    let b = cuboid(0.5, 0.5, 0.5);
    let depth: Real = 0.01;
    let rot = Quat::from_rotation_y(0.3);
    let pb = Isometry::new(Vec3::new(0.3, 1.0 - depth, -0.2), rot);
    let m = step(&d, &ground, &Isometry::IDENTITY, &b, &pb);
    assert_eq!(m.len(), 4);
    // Oracle: the box's bottom corners, computed directly.
    let corners: Vec<Vec3> = [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)]
        .iter()
        .map(|&(x, z)| pb.transform_point(Vec3::new(0.5 * x, -0.5, 0.5 * z)))
        .collect();
    for p in &m.points {
        assert!((p.distance + depth).abs() < 1e-4, "depth {}", p.distance);
        assert!((p.normal - Vec3::new(0.0, -1.0, 0.0)).length() < 1e-4);
        assert!((p.point_a().y - 0.5).abs() < 1e-4);
        let near = corners.iter().any(|c| (*c - p.point_b).length() < 1e-3);
        assert!(near, "point {:?} is not a corner", p.point_b);
    }
}

#[test]
fn box_on_its_edge_gives_two_points() {
    let d = Dispatcher::default();
    let ground = cuboid(2.0, 0.5, 2.0);
    let b = cuboid(0.5, 0.5, 0.5);
    let h = 0.5 * (2.0 as Real).sqrt();
    let pb = Isometry::new(
        Vec3::new(0.0, 0.5 + h - 0.005, 0.0),
        Quat::from_rotation_z(std::f64::consts::FRAC_PI_4 as Real),
    );
    let m = step(&d, &ground, &Isometry::IDENTITY, &b, &pb);
    assert_eq!(m.len(), 2, "{:?}", m.points);
    let mut zs: Vec<Real> = m.points.iter().map(|p| p.point_b.z).collect();
    zs.sort_by(|a, b| a.partial_cmp(b).unwrap());
    assert!(
        (zs[0] + 0.5).abs() < 1e-3 && (zs[1] - 0.5).abs() < 1e-3,
        "{zs:?}"
    );
    for p in &m.points {
        assert!((p.distance + 0.005).abs() < 1e-3);
        assert!(p.point_b.x.abs() < 1e-3);
    }
}

#[test]
fn capsule_lying_on_box_gives_two_points() {
    let d = Dispatcher::default();
    let ground = cuboid(2.0, 0.5, 2.0);
    let cap = Shape::Capsule(Capsule::new(0.25, 0.6).unwrap());
    let pb = Isometry::new(
        Vec3::new(0.1, 0.5 + 0.25 - 0.01, 0.2),
        Quat::from_rotation_z(std::f64::consts::FRAC_PI_2 as Real),
    );
    for (a, pa, b, pbb) in [
        (&ground, Isometry::IDENTITY, &cap, pb),
        (&cap, pb, &ground, Isometry::IDENTITY),
    ] {
        let m = step(&d, a, &pa, b, &pbb);
        assert_eq!(m.len(), 2);
        let mut xs: Vec<Real> = m
            .points
            .iter()
            .map(|p| p.point_b.x.min(p.point_a().x))
            .collect();
        xs.sort_by(|a, b| a.partial_cmp(b).unwrap());
        assert!(
            (xs[0] - (0.1 - 0.6)).abs() < 1e-3 && (xs[1] - 0.7).abs() < 1e-3,
            "{xs:?}"
        );
        for p in &m.points {
            assert!((p.distance + 0.01).abs() < 1e-3);
        }
    }
}

#[test]
fn cylinder_standing_on_plane_gets_three_points_by_caching() {
    let d = Dispatcher::default();
    let plane = Shape::Plane(Plane::new(Vec3::Y, 0.0).unwrap());
    let cyl = Shape::Cylinder(Cylinder::new(0.5, 0.5).unwrap());
    let mut m = ContactManifold::new();
    let pb = Isometry::from_translation(Vec3::new(0.0, 0.5 - 0.002, 0.0));
    for _ in 0..3 {
        d.update_manifold(&plane, &Isometry::IDENTITY, &cyl, &pb, &mut m)
            .unwrap();
    }
    assert!(m.len() >= 3, "{} points", m.len());
    for p in &m.points {
        // Oracle: the rim of the bottom disc, 0.002 below the plane.
        let r = Vec3::new(p.point_b.x, 0.0, p.point_b.z).length();
        assert!((r - 0.5).abs() < 2e-3, "radius {r}");
        assert!((p.distance + 0.002).abs() < 2e-3, "distance {}", p.distance);
    }
}

fn random_hull(rng: &mut Rng, n: usize) -> ConvexHull {
    let pts: Vec<Vec3> = (0..n).map(|_| rng.unit() * rng.range(0.5, 1.0)).collect();
    ConvexHull::new(&pts).unwrap()
}

fn inside_hull(h: &ConvexHull, pose: &Isometry, p: Vec3, tol: Real) -> bool {
    let q = pose.inverse_transform_point(p);
    h.faces().iter().all(|f| f.normal.dot(q) - f.offset <= tol)
}

#[test]
fn hull_hull_manifolds_agree_with_epa_and_lie_in_both_shapes() {
    let mut rng = Rng::new(7);
    let d = Dispatcher::new(ManifoldConfig {
        prediction: 0.0,
        ..Default::default()
    });
    let mut checked = 0;
    for _ in 0..60 {
        let (ha, hb) = (random_hull(&mut rng, 8), random_hull(&mut rng, 32));
        let pa = Isometry::new(
            rng.unit() * 0.2,
            Quat::from_axis_angle(rng.unit(), rng.range(0.0, 3.0)),
        );
        let pb = Isometry::new(
            pa.translation + rng.unit() * rng.range(0.8, 1.4),
            Quat::from_axis_angle(rng.unit(), rng.range(0.0, 3.0)),
        );
        let (sa, sb) = (Shape::ConvexHull(ha.clone()), Shape::ConvexHull(hb.clone()));
        let Some(c) = query::contact(&sa, &pa, &sb, &pb, 0.0).unwrap() else {
            continue;
        };
        let m = step(&d, &sa, &pa, &sb, &pb);
        if c.distance > -1e-3 {
            continue;
        }
        checked += 1;
        assert!(!m.is_empty() && m.len() <= 4);
        let deepest = m.min_distance().unwrap();
        assert!(
            (deepest - c.distance).abs() < 2e-3 + 0.02 * c.distance.abs(),
            "{deepest} vs {}",
            c.distance
        );
        for p in &m.points {
            assert!(p.distance <= 1e-4);
            let tol = 1e-3 + p.distance.abs();
            assert!(inside_hull(&ha, &pa, p.point_a(), 1e-3));
            assert!(inside_hull(&hb, &pb, p.point_b, 1e-3));
            assert!(inside_hull(&hb, &pb, p.point_a(), tol));
            assert!(inside_hull(&ha, &pa, p.point_b, tol));
        }
    }
    assert!(checked > 10, "only {checked} overlapping cases");
}

#[test]
fn sliding_box_keeps_features_and_impulses_then_lifts_off() {
    let d = Dispatcher::default();
    let ground = cuboid(5.0, 0.5, 5.0);
    let b = cuboid(0.5, 0.5, 0.5);
    let mut m = ContactManifold::new();
    let pose =
        |x: Real, y: Real| Isometry::new(Vec3::new(x, 1.0 + y, 0.0), Quat::from_rotation_y(0.2));
    d.update_manifold(&ground, &Isometry::IDENTITY, &b, &pose(0.0, -0.01), &mut m)
        .unwrap();
    assert_eq!(m.len(), 4);
    for (i, p) in m.points.iter_mut().enumerate() {
        p.normal_impulse = 1.0 + i as Real;
        p.tangent_impulse = [0.5, -0.5];
    }
    let ids: Vec<u32> = m.points.iter().map(|p| p.feature).collect();
    for k in 1..10 {
        d.update_manifold(
            &ground,
            &Isometry::IDENTITY,
            &b,
            &pose(0.005 * k as Real, -0.01),
            &mut m,
        )
        .unwrap();
        assert_eq!(m.len(), 4);
        for p in &m.points {
            let i = ids
                .iter()
                .position(|&f| f == p.feature)
                .expect("feature id kept");
            assert_eq!(p.normal_impulse, 1.0 + i as Real);
            assert_eq!(p.tangent_impulse, [0.5, -0.5]);
            assert_eq!(p.lifetime, k);
        }
    }
    d.update_manifold(&ground, &Isometry::IDENTITY, &b, &pose(0.05, 0.2), &mut m)
        .unwrap();
    assert!(m.is_empty());
}

#[test]
fn box_overhanging_an_edge_gives_the_corners_of_the_overlap() {
    // Oracle: the overlap of the top face [-2, 2]² of the ground with the bottom face
    // [1.3, 2.3] × [-0.5, 0.5] (+0.2 in z) of the box is [1.3, 2.0] × [-0.3, 0.7], 1 cm deep.
    let d = Dispatcher::default();
    let ground = cuboid(2.0, 0.5, 2.0);
    let b = cuboid(0.5, 0.5, 0.5);
    let pb = Isometry::from_translation(Vec3::new(1.8, 1.0 - 0.01, 0.2));
    for swap in [false, true] {
        let m = if swap {
            step(&d, &b, &pb, &ground, &Isometry::IDENTITY)
        } else {
            step(&d, &ground, &Isometry::IDENTITY, &b, &pb)
        };
        assert_eq!(m.len(), 4, "{:?}", m.points);
        let mut hit = [false; 4];
        let corners = [(1.3, -0.3), (1.3, 0.7), (2.0, -0.3), (2.0, 0.7)];
        for p in &m.points {
            assert!((p.distance + 0.01).abs() < 1e-4, "depth {}", p.distance);
            let (lo, hi) = (
                p.point_a().y.min(p.point_b.y),
                p.point_a().y.max(p.point_b.y),
            );
            assert!(
                (lo - 0.49).abs() < 1e-4 && (hi - 0.5).abs() < 1e-4,
                "{lo} {hi}"
            );
            let k = corners
                .iter()
                .position(|&(x, z)| {
                    (p.point_b.x - x).abs() < 1e-4 && (p.point_b.z - z).abs() < 1e-4
                })
                .unwrap_or_else(|| panic!("{:?} is not a corner of the overlap", p.point_b));
            hit[k] = true;
        }
        assert!(hit.iter().all(|&h| h), "{hit:?}");
    }
}
