//! Manifold reduction against brute force, Gauss-map pruning against the unpruned edge
//! search, random box–box against EPA, and parallel capsules.

mod common;

use carom_collision::math::{Isometry, Quat, Real, Vec3};
use carom_collision::narrowphase::polyhedron::{polyhedron_manifold, Polyhedron};
use carom_collision::narrowphase::{ContactManifold, ContactPoint, Dispatcher, NO_FEATURE};
use carom_collision::query;
use carom_collision::shape::{Capsule, ConvexHull, Cuboid, Shape};
use common::Rng;

fn point(p: Vec3, d: Real) -> ContactPoint {
    ContactPoint {
        distance: d,
        normal: Vec3::Y,
        point_b: p,
        local_a: p,
        local_b: p,
        local_normal_b: Vec3::Y,
        feature: NO_FEATURE,
        normal_impulse: 0.0,
        tangent_impulse: [0.0; 2],
        lifetime: 0,
    }
}

/// Area of the convex hull of up to 4 points in the XZ plane (shoelace on the sorted hull).
fn area(pts: &[Vec3]) -> Real {
    let c = pts.iter().fold(Vec3::ZERO, |a, p| a + *p) / pts.len() as Real;
    let mut v: Vec<Vec3> = pts.to_vec();
    v.sort_by(|a, b| {
        let (ta, tb) = ((a.z - c.z).atan2(a.x - c.x), (b.z - c.z).atan2(b.x - c.x));
        ta.partial_cmp(&tb).unwrap()
    });
    let mut s = 0.0;
    for i in 0..v.len() {
        let (p, q) = (v[i], v[(i + 1) % v.len()]);
        s += p.x * q.z - q.x * p.z;
    }
    0.5 * s.abs()
}

#[test]
fn reduction_keeps_deepest_and_a_large_area() {
    let mut rng = Rng::new(3);
    for _ in 0..100 {
        let n = 5 + (rng.uniform() * 8.0) as usize;
        let pts: Vec<ContactPoint> = (0..n)
            .map(|_| {
                point(
                    Vec3::new(rng.range(-1.0, 1.0), 0.0, rng.range(-1.0, 1.0)),
                    rng.range(-0.1, 0.0),
                )
            })
            .collect();
        let deepest = pts
            .iter()
            .map(|p| p.distance)
            .fold(Real::INFINITY, Real::min);
        let mut m = ContactManifold::new();
        m.replace_all(pts.clone(), 0.0);
        assert_eq!(m.len(), 4);
        assert_eq!(m.min_distance().unwrap(), deepest);
        let got = area(&m.points.iter().map(|p| p.point_b).collect::<Vec<_>>());
        // Brute force: the best 4-subset containing the deepest point.
        let di = pts.iter().position(|p| p.distance == deepest).unwrap();
        let mut best: Real = 0.0;
        for i in 0..n {
            for j in i + 1..n {
                for k in j + 1..n {
                    if [i, j, k].contains(&di) {
                        continue;
                    }
                    let s = [
                        pts[di].point_b,
                        pts[i].point_b,
                        pts[j].point_b,
                        pts[k].point_b,
                    ];
                    best = best.max(area(&s));
                }
            }
        }
        assert!(got >= 0.6 * best, "area {got} vs best {best}");
    }
}

/// The largest separation `min_B(u) - max_A(u)` over every face normal of A and B and every
/// edge pair's cross product (both orientations, no Gauss-map pruning): minus the minimum
/// penetration depth.
fn unpruned_separation(a: &Polyhedron, b: &Polyhedron, pose_ab: &Isometry) -> Real {
    let vb: Vec<Vec3> = b
        .vertices()
        .iter()
        .map(|v| pose_ab.transform_point(*v))
        .collect();
    let va = a.vertices();
    let sep = |u: Vec3| {
        let max_a = va
            .iter()
            .map(|v| v.dot(u))
            .fold(Real::NEG_INFINITY, Real::max);
        let min_b = vb.iter().map(|v| v.dot(u)).fold(Real::INFINITY, Real::min);
        min_b - max_a
    };
    let mut axes: Vec<Vec3> = a.faces().iter().map(|f| f.normal).collect();
    axes.extend(b.faces().iter().map(|f| pose_ab.transform_vector(f.normal)));
    for ea in a.edges() {
        for eb in b.edges() {
            let da = va[ea[1] as usize] - va[ea[0] as usize];
            let db = vb[eb[1] as usize] - vb[eb[0] as usize];
            if let Some(u) = da.cross(db).try_normalize() {
                axes.push(u);
            }
        }
    }
    axes.iter()
        .flat_map(|&u| [sep(u), sep(-u)])
        .fold(Real::NEG_INFINITY, Real::max)
}

fn random_hull(rng: &mut Rng, n: usize) -> ConvexHull {
    let pts: Vec<Vec3> = (0..n).map(|_| rng.unit() * rng.range(0.5, 1.0)).collect();
    ConvexHull::new(&pts).unwrap()
}

#[test]
fn gauss_map_pruning_finds_the_unpruned_answer() {
    let mut rng = Rng::new(5);
    let mut checked = 0;
    for _ in 0..60 {
        let (ha, hb) = (random_hull(&mut rng, 16), random_hull(&mut rng, 16));
        let (sa, sb) = (Shape::ConvexHull(ha.clone()), Shape::ConvexHull(hb.clone()));
        let mut pose = Isometry::new(
            rng.unit() * rng.range(0.3, 1.6),
            Quat::from_axis_angle(rng.unit(), rng.range(0.0, 3.0)),
        );
        // Shallow penetration: move B along the contact normal to a random small depth
        // (clipping reports the contact region, which matches the MTD for shallow contacts).
        let c0 = query::contact(&sa, &Isometry::IDENTITY, &sb, &pose, 10.0)
            .unwrap()
            .unwrap();
        pose.translation -= c0.normal * (c0.distance + rng.range(0.002, 0.05));
        let c = query::contact(&sa, &Isometry::IDENTITY, &sb, &pose, 10.0)
            .unwrap()
            .unwrap();
        let (pa, pb) = (Polyhedron::from_hull(&ha), Polyhedron::from_hull(&hb));
        let pruned = polyhedron_manifold(&pa, &pb, &pose, 0.0);
        let min = |v: &[(query::Contact, u32)]| {
            v.iter()
                .map(|c| c.0.distance)
                .fold(Real::INFINITY, Real::min)
        };
        if c.distance < -1e-3 {
            let tol = 2e-3 + 0.02 * c.distance.abs();
            assert!(
                (min(&pruned) - c.distance).abs() < tol,
                "{} vs {}",
                min(&pruned),
                c.distance
            );
            // The unpruned separating-axis answer: every face normal and every edge pair.
            let brute = unpruned_separation(&pa, &pb, &pose);
            assert!(
                (brute - c.distance).abs() < tol,
                "{} vs {}",
                brute,
                c.distance
            );
            checked += 1;
        }
    }
    assert!(checked > 10, "{checked}");
}

#[test]
fn random_box_box_agrees_with_epa() {
    let mut rng = Rng::new(9);
    let d = Dispatcher::default();
    let mut checked = 0;
    for _ in 0..80 {
        let ha = Vec3::new(
            rng.range(0.2, 1.0),
            rng.range(0.2, 1.0),
            rng.range(0.2, 1.0),
        );
        let hb = Vec3::new(
            rng.range(0.2, 1.0),
            rng.range(0.2, 1.0),
            rng.range(0.2, 1.0),
        );
        let (a, b) = (
            Shape::Cuboid(Cuboid::new(ha).unwrap()),
            Shape::Cuboid(Cuboid::new(hb).unwrap()),
        );
        let pa = Isometry::new(
            Vec3::new(100.0, -50.0, 3.0),
            Quat::from_axis_angle(rng.unit(), rng.range(0.0, 3.0)),
        );
        let pb = Isometry::new(
            pa.translation + rng.unit() * rng.range(0.3, 1.5),
            Quat::from_axis_angle(rng.unit(), rng.range(0.0, 3.0)),
        );
        let Some(c) = query::contact(&a, &pa, &b, &pb, 0.0).unwrap() else {
            continue;
        };
        if c.distance > -1e-3 {
            continue;
        }
        checked += 1;
        let mut m = ContactManifold::new();
        d.update_manifold(&a, &pa, &b, &pb, &mut m).unwrap();
        let deepest = m.min_distance().unwrap();
        assert!(
            (deepest - c.distance).abs() < 2e-3 + 0.02 * c.distance.abs(),
            "{deepest} vs {}",
            c.distance
        );
        for p in &m.points {
            let qa = pa.inverse_transform_point(p.point_a());
            let qb = pb.inverse_transform_point(p.point_b);
            assert!((qa.abs() - ha).max_element() < 1e-3);
            assert!(
                (qb.abs() - hb).max_element() < 1e-3,
                "{qa:?} {qb:?} {p:?} {ha:?} {hb:?}"
            );
        }
    }
    assert!(checked > 10);
}

#[test]
fn parallel_capsules_give_two_points() {
    let d = Dispatcher::default();
    let a = Shape::Capsule(Capsule::new(0.3, 1.0).unwrap());
    let b = Shape::Capsule(Capsule::new(0.2, 0.5).unwrap());
    let pb = Isometry::from_translation(Vec3::new(0.49, 0.8, 0.0));
    let mut m = ContactManifold::new();
    d.update_manifold(&a, &Isometry::IDENTITY, &b, &pb, &mut m)
        .unwrap();
    assert_eq!(m.len(), 2);
    let mut ys: Vec<Real> = m.points.iter().map(|p| p.point_b.y).collect();
    ys.sort_by(|a, b| a.partial_cmp(b).unwrap());
    // Oracle: overlap of the segments [-1, 1] and [0.3, 1.3] along Y.
    assert!(
        (ys[0] - 0.3).abs() < 1e-3 && (ys[1] - 1.0).abs() < 1e-3,
        "{ys:?}"
    );
    for p in &m.points {
        assert!((p.distance + 0.01).abs() < 1e-4);
    }
}
