//! Shape-level queries on meshes, heightfields and compounds against brute-force oracles
//! over their convex pieces: `contact`/`distance`/`intersects` and `shape_cast` must give
//! the answer of the minimum over every triangle or child, and `time_of_impact` must never
//! pass through any piece (the first contact found by sampling the motion).
//!
//! Session 27's adversarial sweep found `shape_cast` recursing forever on heightfields,
//! heightfields refused by `contact`, and conservative advancement on compounds and meshes
//! stepping through a wall while the floor was the closest piece.

mod midphase_common;

use carom_collision::math::{Isometry, Quat, Real, Vec3};
use carom_collision::query::{self, Motion};
use carom_collision::shape::{
    Capsule, Compound, ConvexHull, Cuboid, HeightField, Shape, Sphere, TriMesh, Triangle,
};
use midphase_common::{grid_mesh, soup_mesh, Rng};
use std::sync::Arc;

fn convex_shapes() -> Vec<Shape> {
    let pts = [
        Vec3::new(0.3, 0.0, 0.1),
        Vec3::new(-0.2, 0.25, 0.0),
        Vec3::new(0.0, -0.3, 0.2),
        Vec3::new(0.1, 0.1, -0.35),
        Vec3::new(-0.15, -0.1, -0.1),
    ];
    vec![
        Shape::Sphere(Sphere::new(0.3).unwrap()),
        Shape::Cuboid(Cuboid::new(Vec3::new(0.4, 0.1, 0.25)).unwrap()),
        Shape::Capsule(Capsule::new(0.15, 0.3).unwrap()),
        Shape::ConvexHull(ConvexHull::new(&pts).unwrap()),
    ]
}

fn pose(rng: &mut Rng, lo: Real, hi: Real) -> Isometry {
    let axis = rng.unit();
    Isometry::new(
        rng.vec(lo, hi),
        Quat::from_axis_angle(axis, rng.range(0.0, 6.0)),
    )
}

/// The triangles of a mesh or heightfield as shapes.
fn triangles(shape: &Shape) -> Vec<Shape> {
    let corners: Vec<[Vec3; 3]> = match shape {
        Shape::TriMesh(m) => (0..m.num_triangles()).map(|i| m.triangle(i)).collect(),
        Shape::HeightField(h) => (0..h.num_triangles()).map(|i| h.triangle(i)).collect(),
        _ => unreachable!(),
    };
    corners
        .into_iter()
        .map(|[a, b, c]| Shape::Triangle(Triangle { a, b, c }))
        .collect()
}

fn targets(rng: &mut Rng) -> Vec<Shape> {
    let (v, t) = grid_mesh(6, 4.0, Vec3::new(-2.0, -0.2, -2.0));
    let (sv, st) = soup_mesh(rng, 40, -1.5, 1.5);
    let heights: Vec<Real> = (0..36)
        .map(|k| 0.3 * ((k % 6) as Real * 0.9).sin() * ((k / 6) as Real * 0.7).cos())
        .collect();
    vec![
        Shape::TriMesh(TriMesh::new(v, t).unwrap()),
        Shape::TriMesh(TriMesh::new(sv, st).unwrap()),
        Shape::HeightField(HeightField::new(6, 6, heights, 0.8, 0.7).unwrap()),
    ]
}

fn scale_of(a: Real) -> Real {
    1e-4 * (1.0 + a.abs())
}

#[test]
fn contact_and_cast_on_meshes_and_heightfields_match_the_brute_force() {
    let mut rng = Rng(27);
    let (mut contacts, mut casts) = (0, 0);
    for target in targets(&mut rng) {
        let tris = triangles(&target);
        for shape in convex_shapes() {
            for _ in 0..40 {
                let pa = pose(&mut rng, -0.5, 0.5);
                let pb = pose(&mut rng, -2.5, 2.5);
                // Contact at several predictions, in both argument orders.
                for prediction in [0.0, 0.05, 0.5, Real::INFINITY] {
                    let got = query::contact(&target, &pa, &shape, &pb, prediction).unwrap();
                    let want = tris
                        .iter()
                        .filter_map(|t| query::contact(t, &pa, &shape, &pb, prediction).unwrap())
                        .map(|c| c.distance)
                        .min_by(Real::total_cmp);
                    match (got, want) {
                        (None, None) => {}
                        (Some(c), Some(w)) => assert!(
                            (c.distance - w).abs() <= scale_of(w),
                            "{} vs {}: {} != {w}",
                            target.kind_name(),
                            shape.kind_name(),
                            c.distance
                        ),
                        (g, w) => panic!("contact {:?} vs oracle {w:?}", g.map(|c| c.distance)),
                    }
                    let swapped = query::contact(&shape, &pb, &target, &pa, prediction).unwrap();
                    assert_eq!(swapped.is_some(), want.is_some());
                    contacts += 1;
                }
                let hit = query::intersects(&target, &pa, &shape, &pb).unwrap();
                let want = tris
                    .iter()
                    .any(|t| query::intersects(t, &pa, &shape, &pb).unwrap());
                let d = query::distance(&target, &pa, &shape, &pb).unwrap().distance;
                assert_eq!(
                    hit,
                    want,
                    "{} vs {}: distance {d}",
                    target.kind_name(),
                    shape.kind_name()
                );
                // A cast towards the target's frame origin.
                let vel = (pa.translation - pb.translation) * rng.range(0.5, 2.0);
                let got = query::shape_cast(&shape, &pb, vel, &target, &pa, Vec3::ZERO, 1.0)
                    .unwrap()
                    .map(|h| h.toi);
                let want = tris
                    .iter()
                    .filter_map(|t| {
                        query::shape_cast(&shape, &pb, vel, t, &pa, Vec3::ZERO, 1.0).unwrap()
                    })
                    .map(|h| h.toi)
                    .min_by(Real::total_cmp);
                match (got, want) {
                    (None, None) => {}
                    (Some(g), Some(w)) => assert!((g - w).abs() <= 1e-4, "cast {g} vs {w}"),
                    (g, w) => panic!("cast {g:?} vs oracle {w:?}"),
                }
                casts += 1;
            }
        }
    }
    assert!(contacts > 1000 && casts > 400);
}

#[test]
fn heightfield_shape_cast_hits_instead_of_recursing() {
    let hf = Shape::HeightField(HeightField::new(3, 3, vec![0.0; 9], 1.0, 1.0).unwrap());
    let ball = Shape::Sphere(Sphere::new(0.5).unwrap());
    let at = Isometry::from_translation(Vec3::new(1.0, 2.0, 1.0));
    for (a, pa, va, b, pb) in [
        (
            &ball,
            at,
            Vec3::new(0.0, -5.0, 0.0),
            &hf,
            Isometry::IDENTITY,
        ),
        (&hf, Isometry::IDENTITY, Vec3::new(0.0, 5.0, 0.0), &ball, at),
    ] {
        let h = query::shape_cast(a, &pa, va, b, &pb, Vec3::ZERO, 1.0)
            .unwrap()
            .expect("a hit");
        assert!((h.toi - 0.3).abs() < 1e-4, "toi {}", h.toi);
    }
    // Distance and TOI too.
    let d = query::distance(&ball, &at, &hf, &Isometry::IDENTITY).unwrap();
    assert!((d.distance - 1.5).abs() < 1e-5);
    let m = Motion::new(at, Vec3::new(0.0, -5.0, 0.0), Vec3::ZERO).unwrap();
    let still = Motion::new(Isometry::IDENTITY, Vec3::ZERO, Vec3::ZERO).unwrap();
    let h = query::time_of_impact(&ball, &m, &hf, &still, 1.0, 1e-4)
        .unwrap()
        .expect("a hit");
    assert!((h.toi - 0.3).abs() < 1e-3 && h.toi <= 0.3, "toi {}", h.toi);
}

/// A floor and a wall as a compound and as a mesh: a sphere sliding along the floor must stop
/// at the wall, whatever the closest piece says.
#[test]
fn time_of_impact_on_composites_does_not_pass_through_a_far_piece() {
    let floor = Arc::new(Shape::Cuboid(
        Cuboid::new(Vec3::new(5.0, 0.5, 5.0)).unwrap(),
    ));
    let wall = Arc::new(Shape::Cuboid(
        Cuboid::new(Vec3::new(0.5, 5.0, 5.0)).unwrap(),
    ));
    let compound = Shape::Compound(
        Compound::new(vec![
            (Isometry::from_translation(Vec3::new(0.0, -0.5, 0.0)), floor),
            (Isometry::from_translation(Vec3::new(3.5, 0.0, 0.0)), wall),
        ])
        .unwrap(),
    );
    let v = [
        [-5.0, 0.0, -5.0],
        [5.0, 0.0, -5.0],
        [5.0, 0.0, 5.0],
        [-5.0, 0.0, 5.0],
        [3.0, -5.0, -5.0],
        [3.0, 5.0, -5.0],
        [3.0, 5.0, 5.0],
        [3.0, -5.0, 5.0],
    ]
    .map(|p| Vec3::new(p[0], p[1], p[2]))
    .to_vec();
    let mesh =
        Shape::TriMesh(TriMesh::new(v, vec![[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7]]).unwrap());
    let ball = Shape::Sphere(Sphere::new(0.5).unwrap());
    let start = Isometry::from_translation(Vec3::new(0.0, 1.0, 0.0));
    let still = Motion::new(Isometry::IDENTITY, Vec3::ZERO, Vec3::ZERO).unwrap();
    for target in [&compound, &mesh] {
        for (vel, spin) in [
            (Vec3::new(10.0, 0.0, 0.0), Vec3::ZERO),
            (Vec3::new(10.0, -1.0, 0.0), Vec3::ZERO),
            (Vec3::new(10.0, 0.0, 0.0), Vec3::new(0.0, 3.0, 0.0)),
        ] {
            let m = Motion::new(start, vel, spin).unwrap();
            let h = query::time_of_impact(&ball, &m, target, &still, 1.0, 1e-4)
                .unwrap()
                .expect("the wall is hit");
            assert!(
                h.toi <= 0.25 && h.toi > 0.249,
                "{}: toi {}",
                target.kind_name(),
                h.toi
            );
            // Swapped: the target moves the other way.
            let mt = Motion::new(Isometry::IDENTITY, -vel, Vec3::ZERO).unwrap();
            let sm = Motion::new(start, Vec3::ZERO, Vec3::ZERO).unwrap();
            if spin == Vec3::ZERO {
                let h = query::time_of_impact(target, &mt, &ball, &sm, 1.0, 1e-4)
                    .unwrap()
                    .expect("the wall is hit");
                assert!(h.toi <= 0.25 && h.toi > 0.249, "swapped: toi {}", h.toi);
                assert!(
                    h.normal.x < -0.99,
                    "normal from the wall to the ball: {}",
                    h.normal
                );
            }
        }
    }
}

/// Random motions of convex shapes against the targets: the reported time of impact is never
/// later than the first contact found by sampling the motion (distance <= 0 at a sample),
/// and at the reported time the shapes are within the tolerance.
#[test]
fn time_of_impact_on_meshes_never_passes_a_sampled_contact() {
    let mut rng = Rng(2711);
    let still = Motion::new(Isometry::IDENTITY, Vec3::ZERO, Vec3::ZERO).unwrap();
    let tol = 1e-3;
    let mut hits = 0;
    for target in targets(&mut rng) {
        for shape in convex_shapes() {
            for _ in 0..25 {
                let p0 = pose(&mut rng, -2.0, 2.0) * Isometry::from_translation(Vec3::Y * 1.5);
                let vel = rng.vec(-4.0, 4.0) - p0.translation;
                let spin = rng.vec(-6.0, 6.0);
                let m = Motion::new(p0, vel, spin).unwrap();
                let dist = |t: Real| {
                    query::distance(&shape, &m.pose_at(t), &target, &Isometry::IDENTITY)
                        .unwrap()
                        .distance
                };
                let first = (0..=400)
                    .map(|k| k as Real / 400.0)
                    .find(|&t| dist(t) <= 0.0);
                let h = query::time_of_impact(&shape, &m, &target, &still, 1.0, tol).unwrap();
                if let Some(t) = first {
                    let h = h.expect("a sampled contact must be reported");
                    assert!(
                        h.toi <= t,
                        "{} vs {}: toi {} after the sampled contact {t}: d(toi) {} d(t) {} d(t - 1/400) {}",
                        shape.kind_name(),
                        target.kind_name(),
                        h.toi,
                        dist(h.toi),
                        dist(t),
                        dist(t - 1.0 / 400.0)
                    );
                    hits += 1;
                }
                if let Some(h) = h {
                    assert!(dist(h.toi) <= tol * 1.01, "apart at the reported time");
                }
            }
        }
    }
    assert!(hits > 20, "only {hits} hits");
}

/// Triangles without area, as meshes hold them: a repeated corner (a segment) against a
/// sphere, and collinear corners against a box, in both argument orders. Session 27: the
/// first gave no closest points at all (0/0 in the closest point on the triangle), the
/// second a distance of 0 with a zero normal when the triangle was A (the separating-axis
/// fallback took the triangle's zero face normal).
#[test]
fn triangles_without_area_have_distances_in_both_orders() {
    let seg = Shape::Triangle(Triangle {
        a: Vec3::new(0.0, 0.0, 0.0),
        b: Vec3::new(0.0, 0.0, 0.0),
        c: Vec3::new(2.0, 0.0, 0.0),
    });
    let ball = Shape::Sphere(Sphere::new(0.5).unwrap());
    let at = Isometry::from_translation(Vec3::new(1.0, 0.8, 0.0));
    let d = query::distance(&seg, &Isometry::IDENTITY, &ball, &at).unwrap();
    assert!((d.distance - 0.3).abs() < 1e-5, "{d:?}");
    let d = query::distance(&ball, &at, &seg, &Isometry::IDENTITY).unwrap();
    assert!((d.distance - 0.3).abs() < 1e-5, "{d:?}");
    assert!(query::intersects(&seg, &Isometry::IDENTITY, &ball, &Isometry::IDENTITY).unwrap());

    let line = Shape::Triangle(Triangle {
        a: Vec3::new(1.418_885_8, -0.733_221_05, -0.688_995_24),
        b: Vec3::new(1.288_662_3, -0.818_077_5, -0.717_622_6),
        c: Vec3::new(1.158_438_8, -0.902_933_96, -0.746_249_9),
    });
    let cube = convex_shapes().swap_remove(1);
    let pose = Isometry::new(
        Vec3::new(1.372_013_1, -0.576_235_9, -0.376_516_76),
        Quat::from_xyzw(0.233_834_46, 0.624_453_7, 0.322_669_6, -0.671_761_4).normalize(),
    );
    let ab = query::distance(&cube, &pose, &line, &Isometry::IDENTITY).unwrap();
    let ba = query::distance(&line, &Isometry::IDENTITY, &cube, &pose).unwrap();
    assert!(ab.distance > 5e-4, "{ab:?}");
    assert!((ab.distance - ba.distance).abs() < 1e-5, "{ab:?} vs {ba:?}");
    assert!((ba.normal.length() - 1.0).abs() < 1e-4, "{ba:?}");
}
