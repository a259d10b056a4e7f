//! Support maps, bounding boxes and mass properties of every convex shape, checked against
//! independent oracles: dense surface samples, implicit inside tests and Monte Carlo
//! integration.
#![allow(clippy::needless_range_loop)]

mod common;

use carom_collision::math::{Isometry, Quat, Real, Vec3};
use carom_collision::shape::*;
use common::{inside, sample_surface, Rng};
use proptest::prelude::*;
use std::sync::Arc;

/// Tolerance for "on the shape" checks, relative to the shape size.
const TOL: Real = if cfg!(feature = "f64") { 1e-9 } else { 2e-4 };

fn test_shapes() -> Vec<Shape> {
    let taru = common::taru_points();
    vec![
        Sphere::new(0.7).unwrap().into(),
        Cuboid::new(Vec3::new(0.5, 1.0, 2.0)).unwrap().into(),
        Capsule::new(0.3, 0.8).unwrap().into(),
        Cylinder::new(0.6, 0.4).unwrap().into(),
        Cone::new(0.5, 1.2).unwrap().into(),
        ConvexHull::new(&taru).unwrap().into(),
        Triangle::new(
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.2, 0.0),
            Vec3::new(0.3, 1.0, 0.5),
        )
        .unwrap()
        .into(),
        Scaled::new(
            Arc::new(Capsule::new(0.5, 1.0).unwrap().into()),
            Vec3::new(2.0, 0.5, -1.0),
        )
        .unwrap()
        .into(),
        Scaled::new(
            Arc::new(Cone::new(0.5, 1.0).unwrap().into()),
            Vec3::new(1.0, 3.0, 0.25),
        )
        .unwrap()
        .into(),
    ]
}

fn unit_dir() -> impl Strategy<Value = Vec3> {
    (-1.0..1.0 as Real, -1.0..1.0 as Real, -1.0..1.0 as Real)
        .prop_filter("non-zero", |(x, y, z)| x * x + y * y + z * z > 1e-4)
        .prop_map(|(x, y, z)| Vec3::new(x, y, z).normalize())
}

fn pose() -> impl Strategy<Value = Isometry> {
    (
        -10.0..10.0 as Real,
        -10.0..10.0 as Real,
        -10.0..10.0 as Real,
        unit_dir(),
        -3.2..3.2 as Real,
    )
        .prop_map(|(x, y, z, axis, angle)| {
            Isometry::new(Vec3::new(x, y, z), Quat::from_axis_angle(axis, angle))
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    /// The support point maximises `p · d` over a dense sampling of the surface and lies on
    /// the shape; the core support with the margin added stays inside the shape.
    #[test]
    fn support_maximises_over_surface_samples(dir in unit_dir(), seed in 0u64..1000) {
        let mut rng = Rng::new(seed);
        for shape in test_shapes() {
            let convex = shape.as_convex().unwrap();
            let size = shape.local_aabb().extents().max_element();
            // Hull faces merge points coplanar within the builder's tolerance (the Taru data
            // is single precision), so vertices may sit that far off a face plane.
            let tol = if matches!(shape, Shape::ConvexHull(_)) { TOL.max(2e-5) } else { TOL };
            let samples = sample_surface(&shape, 3000, &mut rng);
            let best = samples.iter().map(|p| p.dot(dir)).fold(Real::MIN, Real::max);
            let s = convex.support(dir);
            prop_assert!(s.dot(dir) >= best - tol * size, "{}: support {s} below sample max", shape.kind_name());
            prop_assert!(inside(&shape, s, tol * size), "{}: support {s} is not on the shape", shape.kind_name());
            // No sample may beat the support point by more than the sampling resolution.
            let with_margin = convex.support_with_margin(dir);
            prop_assert!(inside(&shape, with_margin, tol * size), "{}: core + margin outside", shape.kind_name());
            prop_assert!(with_margin.dot(dir) <= s.dot(dir) + tol * size);
            let core = convex.support_core(dir);
            prop_assert!(core.dot(dir) <= s.dot(dir) - convex.margin() + tol * size);
        }
    }

    /// World AABBs contain the posed surface samples and are tight (each face is touched).
    #[test]
    fn world_aabb_contains_and_touches(pose in pose(), seed in 0u64..1000) {
        let mut rng = Rng::new(seed);
        for shape in test_shapes() {
            let aabb = shape.aabb(&pose);
            let size = shape.local_aabb().extents().max_element();
            let tol = TOL * (size + 10.0);
            let samples = sample_surface(&shape, 2000, &mut rng);
            let mut touched_min = Vec3::splat(Real::MAX);
            let mut touched_max = Vec3::splat(Real::MIN);
            for p in samples {
                let w = pose.transform_point(p);
                prop_assert!(aabb.expanded(tol).contains_point(w), "{}: {w} outside {aabb:?}", shape.kind_name());
                touched_min = touched_min.min(w);
                touched_max = touched_max.max(w);
            }
            // Sampling is dense: the box is at most a few percent larger than the samples.
            let slack = 0.1 * size;
            prop_assert!((touched_min - aabb.min).max_element() <= slack, "{}: loose AABB", shape.kind_name());
            prop_assert!((aabb.max - touched_max).max_element() <= slack, "{}: loose AABB", shape.kind_name());
        }
    }
}

/// Monte Carlo estimate of volume, centre of mass and inertia from the inside test.
fn monte_carlo(shape: &Shape, n: usize, rng: &mut Rng) -> (f64, [f64; 3], [[f64; 3]; 3]) {
    let b = shape.local_aabb();
    let (lo, ext) = (b.min, b.extents());
    let box_volume = (ext.x * ext.y * ext.z) as f64;
    let mut pts = Vec::new();
    for _ in 0..n {
        let p = lo + Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * ext;
        if inside(shape, p, 0.0) {
            pts.push([p.x as f64, p.y as f64, p.z as f64]);
        }
    }
    let volume = box_volume * pts.len() as f64 / n as f64;
    let m = pts.len() as f64;
    let mut com = [0.0; 3];
    for p in &pts {
        for i in 0..3 {
            com[i] += p[i] / m;
        }
    }
    // Inertia per unit density about the centre of mass: ∫ (|r|² δij − ri rj) dV.
    let mut inertia = [[0.0; 3]; 3];
    for p in &pts {
        let r = [p[0] - com[0], p[1] - com[1], p[2] - com[2]];
        let r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
        for i in 0..3 {
            for j in 0..3 {
                let d = if i == j { r2 } else { 0.0 };
                inertia[i][j] += (d - r[i] * r[j]) * volume / m;
            }
        }
    }
    (volume, com, inertia)
}

#[test]
fn mass_properties_match_monte_carlo_integration() {
    let mut rng = Rng::new(7);
    let n = if cfg!(debug_assertions) {
        200_000
    } else {
        1_000_000
    };
    for shape in test_shapes() {
        if matches!(shape, Shape::Triangle(_)) {
            continue;
        }
        let density: f64 = 2.5;
        let mp = shape.mass_properties(density as Real);
        let (vol, com, inertia) = monte_carlo(&shape, n, &mut rng);
        let size = shape.local_aabb().extents().max_element() as f64;
        let name = shape.kind_name();
        assert!(
            ((shape.volume() as f64) - vol).abs() < 0.02 * vol,
            "{name}: volume {} vs {vol}",
            shape.volume()
        );
        assert!(
            ((mp.mass as f64) - density * vol).abs() < 0.02 * density * vol,
            "{name}: mass"
        );
        for i in 0..3 {
            assert!(
                ((mp.center_of_mass[i] as f64) - com[i]).abs() < 0.01 * size,
                "{name}: com {:?} vs {com:?}",
                mp.center_of_mass
            );
        }
        let scale = (0..3).map(|i| inertia[i][i]).fold(0.0, f64::max) * density;
        for i in 0..3 {
            for j in 0..3 {
                let got = mp.inertia.col(j)[i] as f64;
                let want = inertia[i][j] * density;
                assert!(
                    (got - want).abs() < 0.04 * scale,
                    "{name}: inertia[{i}][{j}] {got} vs {want}"
                );
            }
        }
    }
}

#[test]
fn analytic_mass_properties() {
    use std::f64::consts::PI;
    let close = |a: Real, b: f64| ((a as f64) - b).abs() <= 1e-4 * b.abs().max(1.0);
    let s = Sphere::new(2.0).unwrap().mass_properties(3.0);
    let m = 3.0 * 4.0 / 3.0 * PI * 8.0;
    assert!(close(s.mass, m) && close(s.inertia.x_axis.x, 0.4 * m * 4.0));
    let b = Cuboid::new(Vec3::new(1.0, 2.0, 3.0))
        .unwrap()
        .mass_properties(1.0);
    assert!(close(b.mass, 48.0) && close(b.inertia.x_axis.x, 48.0 * (16.0 + 36.0) / 12.0));
    let c = Cylinder::new(1.0, 2.0).unwrap().mass_properties(1.0);
    let m = PI * 4.0;
    assert!(
        close(c.mass, m)
            && close(c.inertia.y_axis.y, 0.5 * m)
            && close(c.inertia.x_axis.x, m * (3.0 + 16.0) / 12.0)
    );
    let k = Cone::new(1.0, 1.5).unwrap().mass_properties(1.0);
    let m = PI * 3.0 / 3.0;
    assert!(
        close(k.mass, m) && close(k.center_of_mass.y, -0.75) && close(k.inertia.y_axis.y, 0.3 * m)
    );
    assert!(close(
        k.inertia.x_axis.x,
        m * (3.0 / 20.0 + 3.0 / 80.0 * 9.0)
    ));
    // A capsule of zero height tends to a sphere; a long one to a cylinder plus a sphere.
    let cap = Capsule::new(1.0, 1e-3).unwrap().mass_properties(1.0);
    let sphere = Sphere::new(1.0).unwrap().mass_properties(1.0);
    assert!((cap.inertia.x_axis.x - sphere.inertia.x_axis.x).abs() < 1e-2);
    // Compound of two unit boxes side by side equals one 2x1x1 box.
    let unit = Arc::new(Shape::from(Cuboid::new(Vec3::splat(0.5)).unwrap()));
    let comp = Compound::new(vec![
        (
            Isometry::from_translation(Vec3::new(-0.5, 0.0, 0.0)),
            unit.clone(),
        ),
        (Isometry::from_translation(Vec3::new(0.5, 0.0, 0.0)), unit),
    ])
    .unwrap()
    .mass_properties(1.0);
    let whole = Cuboid::new(Vec3::new(1.0, 0.5, 0.5))
        .unwrap()
        .mass_properties(1.0);
    assert!(close(comp.mass, whole.mass as f64));
    for i in 0..3 {
        assert!((comp.inertia.col(i) - whole.inertia.col(i)).length() < 1e-4);
    }
    // A uniformly scaled sphere is a sphere.
    let sc = Scaled::new(Arc::new(Sphere::new(1.0).unwrap().into()), Vec3::splat(2.0)).unwrap();
    let direct = Sphere::new(2.0).unwrap().mass_properties(1.0);
    let via = sc.mass_properties(1.0);
    assert!(
        (via.mass - direct.mass).abs() < 1e-3
            && (via.inertia.x_axis.x - direct.inertia.x_axis.x).abs() < 1e-2
    );
}

#[test]
fn taru_hull_matches_reference() {
    let hull = ConvexHull::new(&common::taru_points()).unwrap();
    // shared/data/README.md: 24 hull vertices, 44 triangles, volume 24.3499 (qhull).
    assert_eq!(hull.vertices().len(), 24);
    assert!(
        (hull.volume() - 24.3499).abs() < 1e-3,
        "volume {}",
        hull.volume()
    );
}

/// A closed surface of revolution about Y from a profile `(radius, y)` running from the
/// bottom pole to the top pole, with `segments` around. Counter-clockwise from outside.
fn revolve(profile: &[(Real, Real)], segments: usize) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut v = Vec::new();
    for &(r, y) in profile {
        for k in 0..segments {
            let a = 2.0 * carom_collision::math::consts::PI * k as Real / segments as Real;
            v.push(Vec3::new(r * a.cos(), y, -r * a.sin()));
        }
    }
    let mut t = Vec::new();
    for i in 0..profile.len() - 1 {
        for k in 0..segments {
            let a = (i * segments + k) as u32;
            let b = (i * segments + (k + 1) % segments) as u32;
            let c = a + segments as u32;
            let d = b + segments as u32;
            t.push([a, b, d]);
            t.push([a, d, c]);
        }
    }
    (v, t)
}

/// Mass properties against fine tessellations (exact polyhedron integrals converging
/// quadratically), an oracle independent of the closed-form formulas.
#[test]
fn mass_properties_match_tessellations() {
    use carom_collision::math::consts::PI;
    let n = 96;
    let check = |name: &str, mp: MassProperties, profile: Vec<(Real, Real)>| {
        let (v, t) = revolve(&profile, 256);
        let (_, poly) = polyhedron_mass_properties(&v, &t);
        assert!(
            (mp.mass - poly.mass).abs() < 2e-3 * mp.mass,
            "{name}: mass {} vs {}",
            mp.mass,
            poly.mass
        );
        assert!(
            (mp.center_of_mass - poly.center_of_mass).length() < 2e-3,
            "{name}: com"
        );
        for i in 0..3 {
            let (a, b) = (mp.inertia.col(i)[i], poly.inertia.col(i)[i]);
            assert!((a - b).abs() < 3e-3 * a, "{name}: inertia[{i}] {a} vs {b}");
        }
    };
    let (r, h) = (0.3 as Real, 0.8 as Real);
    let mut profile = vec![(0.0, -h - r)];
    for i in 1..n {
        let a = -PI / 2.0 + PI / 2.0 * i as Real / n as Real;
        profile.push((r * a.cos(), -h + r * a.sin()));
    }
    for i in 0..n {
        let a = PI / 2.0 * i as Real / n as Real;
        profile.push((r * a.cos(), h + r * a.sin()));
    }
    profile.push((0.0, h + r));
    check(
        "capsule",
        Capsule::new(r, h).unwrap().mass_properties(1.0),
        profile,
    );
    check(
        "cylinder",
        Cylinder::new(0.6, 0.4).unwrap().mass_properties(1.0),
        vec![(0.0, -0.4), (0.6, -0.4), (0.6, 0.4), (0.0, 0.4)],
    );
    check(
        "cone",
        Cone::new(0.5, 1.2).unwrap().mass_properties(1.0),
        vec![(0.0, -1.2), (0.5, -1.2), (0.0, 1.2)],
    );
    let mut sphere = vec![];
    for i in 0..=2 * n {
        let a = -PI / 2.0 + PI * i as Real / (2 * n) as Real;
        sphere.push((0.7 * a.cos(), 0.7 * a.sin()));
    }
    check(
        "sphere",
        Sphere::new(0.7).unwrap().mass_properties(1.0),
        sphere,
    );
}

#[test]
fn hull_world_aabb_is_the_box_of_the_posed_vertices() {
    // Small hulls get their world box from one pass over rotated vertices, large ones from six
    // support queries; both must equal the box of the vertices posed one by one (quaternion
    // transform, an independent formula) to round-off, near and far from the origin.
    let mut rng = Rng::new(42);
    let taru = ConvexHull::new(&common::taru_points()).unwrap();
    let sphere_points: Vec<Vec3> = (0..400)
        .map(|_| {
            let d = Vec3::new(
                rng.uniform() - 0.5,
                rng.uniform() - 0.5,
                rng.uniform() - 0.5,
            );
            d.normalize_or_zero() * 2.0
        })
        .collect();
    let big = ConvexHull::new(&sphere_points).unwrap();
    assert!(taru.vertices().len() <= ConvexHull::AABB_SCAN_MAX_VERTICES);
    assert!(big.vertices().len() > ConvexHull::AABB_SCAN_MAX_VERTICES);
    for hull in [taru, big] {
        let shape = Shape::from(hull.clone());
        for k in 0..200 {
            let far = if k % 2 == 0 { 1.0 } else { 1000.0 };
            let axis = Vec3::new(
                rng.uniform() - 0.4,
                rng.uniform() - 0.5,
                rng.uniform() - 0.6,
            );
            let t = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * far;
            let pose = Isometry::new(
                t,
                Quat::from_axis_angle(axis.normalize(), 6.0 * rng.uniform()),
            );
            let got = shape.aabb(&pose);
            let (mut lo, mut hi) = (Vec3::splat(Real::MAX), Vec3::splat(Real::MIN));
            for v in hull.vertices() {
                let w = pose.transform_point(*v);
                lo = lo.min(w);
                hi = hi.max(w);
            }
            let tol = 8.0 * Real::EPSILON * (far + 4.0);
            assert!(
                (got.min - lo).abs().max_element() <= tol
                    && (got.max - hi).abs().max_element() <= tol,
                "{} vertices: {got:?} vs [{lo}, {hi}]",
                hull.vertices().len()
            );
        }
    }
}

#[test]
fn capsule_world_aabb_equals_the_six_support_box() {
    // The capsule's closed-form box (end spheres) against the box from the exact support
    // function along the six world axes, near and 1 km from the origin.
    let mut rng = Rng::new(7);
    for (radius, half_height) in [(0.3, 0.5), (0.05, 2.0), (1.0, 0.0001)] {
        let shape = Shape::from(Capsule::new(radius, half_height).unwrap());
        let convex = shape.as_convex().unwrap();
        for k in 0..200 {
            let far = if k % 2 == 0 { 1.0 } else { 1000.0 };
            let axis = Vec3::new(
                rng.uniform() - 0.4,
                rng.uniform() - 0.5,
                rng.uniform() - 0.6,
            );
            let t = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * far;
            let pose = Isometry::new(
                t,
                Quat::from_axis_angle(axis.normalize(), 6.0 * rng.uniform()),
            );
            let got = shape.aabb(&pose);
            let mut lo = Vec3::ZERO;
            let mut hi = Vec3::ZERO;
            for i in 0..3 {
                let mut e = Vec3::ZERO;
                e[i] = 1.0;
                hi[i] = pose.transform_point(convex.support(pose.rotation.inverse() * e))[i];
                lo[i] = pose.transform_point(convex.support(pose.rotation.inverse() * -e))[i];
            }
            let tol = 16.0 * Real::EPSILON * (far + 3.0);
            assert!(
                (got.min - lo).abs().max_element() <= tol
                    && (got.max - hi).abs().max_element() <= tol,
                "{got:?} vs [{lo}, {hi}]"
            );
        }
    }
}
