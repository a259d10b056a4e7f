//! Quickhull and `ConvexHull` on named clouds: a box given as a surface grid (also far from
//! the origin, tiny and huge) against analytic mass properties, points on a sphere, nearly
//! coplanar points, the Taru cloud against its reference values and the brute-force oracle,
//! degenerate inputs, 10k points, and regressions.

mod support;

use carom_collision::math::{real, Real, Vec3, EPSILON};
use carom_collision::shape::{polyhedron_mass_properties, quickhull, ConvexHull, SupportMap};
use carom_collision::CaromError;
use support::brute_force_hull::brute_force_hull;
use support::hull_checks::{assert_box, check_hull, cube_surface_grid, Lcg};

#[test]
fn cube_given_as_surface_grid() {
    let (half, centre) = (Vec3::new(1.0, 2.0, 0.5), Vec3::new(0.25, -1.0, 3.0));
    let mut pts = cube_surface_grid(10, half, centre);
    assert_eq!(pts.len(), 1000 - 512);
    // Interior points and duplicates change nothing.
    let mut rng = Lcg(7);
    for k in 0..200 {
        pts.push(centre + rng.point() * half * 0.99);
        pts.push(pts[k * 2]);
    }
    let hull = ConvexHull::new(&pts).unwrap();
    check_hull(&pts, &hull);
    assert_box(&hull, half, centre, 1e-4);
}

#[test]
fn box_far_from_origin() {
    let far: Real = if cfg!(feature = "f64") { 1e8 } else { 1e4 };
    let centre = Vec3::new(far, -far, 0.5 * far);
    let half = Vec3::new(0.5, 1.0, 2.0);
    let pts = cube_surface_grid(4, half, centre);
    let hull = ConvexHull::new(&pts).unwrap();
    check_hull(&pts, &hull);
    // f32 at 1e4 resolves ~1e-3: compare loosely.
    let rel = if cfg!(feature = "f64") { 1e-6 } else { 1e-2 };
    assert_box(&hull, half, centre, rel);
}

#[test]
fn tiny_and_huge_boxes() {
    for scale in [1e-6 as Real, 1e-3, 1e3, 1e6] {
        let half = Vec3::new(1.0, 0.5, 0.25) * scale;
        let pts = cube_surface_grid(5, half, Vec3::ZERO);
        let hull = ConvexHull::new(&pts).unwrap();
        check_hull(&pts, &hull);
        assert_box(&hull, half, Vec3::ZERO, 1e-4);
    }
}

#[test]
fn points_on_a_sphere_are_all_vertices() {
    // Fibonacci sphere: every point is extreme.
    let n = 500;
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let pts: Vec<Vec3> = (0..n)
        .map(|i| {
            let y = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - y * y).sqrt();
            let a = golden * i as f64;
            Vec3::new(real(r * a.cos()), real(y), real(r * a.sin()))
        })
        .collect();
    let hull = ConvexHull::new(&pts).unwrap();
    assert_eq!(check_hull(&pts, &hull), n);
    let ball = real(4.0 / 3.0 * std::f64::consts::PI);
    assert!(hull.volume() < ball && hull.volume() > 0.98 * ball);
    assert!(hull.faces().len() == 2 * n - 4, "a triangulated sphere");
}

#[test]
fn nearly_coplanar_points() {
    let mut rng = Lcg(11);
    // A thin slab (1e-3 thick) is a valid hull.
    let slab: Vec<Vec3> = (0..300)
        .map(|_| {
            let p = rng.point();
            Vec3::new(p.x, p.y, p.z * 5e-4)
        })
        .collect();
    let hull = ConvexHull::new(&slab).unwrap();
    check_hull(&slab, &hull);
    // Noise far below the tolerance: coplanar.
    let flat: Vec<Vec3> = (0..300)
        .map(|_| {
            let p = rng.point();
            Vec3::new(p.x, p.y, p.z * 0.1 * EPSILON)
        })
        .collect();
    let err = ConvexHull::new(&flat).unwrap_err();
    assert!(err.to_string().contains("coplanar"), "{err}");
    // Points of a plane plus one point above: a pyramid-like hull with a flat base.
    let mut cone = flat.clone();
    cone.push(Vec3::new(0.0, 0.0, 1.0));
    let hull = ConvexHull::new(&cone).unwrap();
    check_hull(&cone, &hull);
}

#[test]
fn degenerate_inputs_name_the_problem() {
    let p = Vec3::new(1.0, 2.0, 3.0);
    let cases: Vec<(Vec<Vec3>, &str)> = vec![
        (vec![], "at least 4"),
        (vec![p, p * 2.0, p * 3.0], "at least 4"),
        (vec![p; 10], "coincide"),
        ((0..10).map(|i| p * i as Real).collect(), "collinear"),
        (
            (0..10)
                .map(|i| Vec3::new(i as Real, (i * i) as Real, 1.0))
                .collect(),
            "coplanar",
        ),
        (
            vec![p, Vec3::X, Vec3::Y, Vec3::new(Real::NAN, 0.0, 0.0)],
            "points[3]",
        ),
        (
            vec![p, Vec3::X, Vec3::Y, Vec3::splat(Real::INFINITY)],
            "points[3]",
        ),
    ];
    for (points, needle) in cases {
        let err = ConvexHull::new(&points).unwrap_err();
        assert!(err.to_string().contains(needle), "{err} lacks {needle}");
        let err = quickhull(&points).unwrap_err();
        assert!(matches!(
            err,
            CaromError::InvalidValue { .. } | CaromError::Degenerate { .. }
        ));
    }
}

#[test]
fn taru_point_cloud() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/data/taru.obj");
    let text = std::fs::read_to_string(path).unwrap();
    let pts: Vec<Vec3> = text
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let c: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            Vec3::new(real(c[0]), real(c[1]), real(c[2]))
        })
        .collect();
    assert_eq!(pts.len(), 43);
    let hull = ConvexHull::new(&pts).unwrap();
    assert_eq!(check_hull(&pts, &hull), 24);
    assert!(
        (hull.volume() - 24.3499).abs() < 1e-3,
        "volume {}",
        hull.volume()
    );
    // Mass properties equal those of the oracle hull's own triangulation.
    let oracle = brute_force_hull(&pts).unwrap();
    assert_eq!(oracle.vertices.len(), 24);
    let mut tris = Vec::new();
    for f in &oracle.faces {
        for k in 1..f.len() - 1 {
            tris.push([f[0], f[k], f[k + 1]]);
        }
    }
    let (_, expected) = polyhedron_mass_properties(&oracle.vertices, &tris);
    let got = hull.mass_properties(1.0);
    assert!((got.center_of_mass - expected.center_of_mass).length() < 1e-4);
    for i in 0..3 {
        assert!((got.inertia.col(i) - expected.inertia.col(i)).length() < 1e-3);
    }
}

#[test]
fn ten_thousand_random_points() {
    let mut rng = Lcg(3);
    let pts: Vec<Vec3> = (0..10_000).map(|_| rng.point()).collect();
    let start = std::time::Instant::now();
    let hull = ConvexHull::new(&pts).unwrap();
    let elapsed = start.elapsed();
    println!(
        "10k random points: {} vertices, {} faces, {:?}",
        hull.vertices().len(),
        hull.faces().len(),
        elapsed
    );
    check_hull(&pts, &hull);
    assert!(hull.vertices().len() > 32);
    // The worst case for size: every point on the hull.
    let sphere: Vec<Vec3> = pts.iter().map(|p| p.normalize()).collect();
    let start = std::time::Instant::now();
    let ball = ConvexHull::new(&sphere).unwrap();
    println!(
        "10k points on a sphere: {} vertices, {} faces, {:?}",
        ball.vertices().len(),
        ball.faces().len(),
        start.elapsed()
    );
    assert!(ball.vertices().len() > 9_900);
    for k in 0..200 {
        let d = rng.point();
        let best = hull
            .vertices()
            .iter()
            .map(|v| v.dot(d))
            .fold(Real::MIN, Real::max);
        assert!(
            hull.support(d).dot(d) >= best - 8.0 * EPSILON,
            "direction {k}"
        );
    }
}

/// Points on the two circles of a cylinder (`(circle, angle / π)`), rotated by
/// `(angle, axis)`.
fn cylinder_points(raw: &[(u32, f64)], rotation: Option<(f64, [f64; 3])>) -> Vec<Vec3> {
    raw.iter()
        .map(|&(i, s)| {
            let a = real(s * std::f64::consts::PI);
            let p = Vec3::new(a.cos(), if i % 2 == 0 { -1.0 } else { 1.0 }, a.sin());
            match rotation {
                Some((angle, [x, y, z])) => {
                    let axis = Vec3::new(real(x), real(y), real(z)).normalize();
                    carom_collision::math::Quat::from_axis_angle(axis, real(angle)) * p
                }
                None => p,
            }
        })
        .collect()
}

/// Clouds that broke earlier versions (found by `hull_invariants_on_degenerate_clouds`):
/// nearly coincident points on a circle (a vertex quickhull keeps that later points make
/// redundant; two near-duplicates both looking collinear), sliver faces whose normals lose
/// digits, coplanar fans around an interior vertex.
#[test]
fn regression_near_duplicates_and_slivers() {
    let clouds = [
        cylinder_points(
            &[
                (2, -0.9533156901099955),
                (2, -0.7990901875768033),
                (1, 0.0),
                (0, -0.8916445252524606),
                (1, -0.9494873517734953),
                (0, -0.8916402627870644),
                (1, 0.6363669192793322),
                (1, 0.0),
            ],
            None,
        ),
        cylinder_points(
            &[
                (0, -0.13061944615697382),
                (1, -0.10498496163332137),
                (1, -0.17815076044074063),
                (0, -0.1306297013520921),
                (2, 0.9755408906424616),
                (2, -0.17961263885779372),
                (2, -0.09180548223104494),
                (0, 0.4031326397438356),
                (1, -0.8040364151548044),
            ],
            Some((
                1.1612281221036302,
                [0.0, 0.7864254169610085, 0.3668571449301411],
            )),
        ),
        // An eye coplanar with a face but beyond another of its edges (needs a retry).
        cylinder_points(
            &[
                (1, 0.33376653113254195),
                (1, 0.0026785223408817764),
                (0, -0.44725859138720814),
                (0, 0.0),
                (1, 0.3018784658382496),
                (1, 0.30186384395642035),
                (1, 0.3923580088831654),
                (1, 0.2686332488073096),
                (1, 0.29938378901435636),
                (0, 0.029268971555233458),
                (0, 0.29490153154939763),
                (1, 0.5775387841426505),
                (2, 0.2967911078083758),
                (0, -0.9044483537344139),
                (1, -0.17768524293308754),
            ],
            Some((
                -1.7169843234758841,
                [-0.6010230664921061, 0.7928076412308663, 0.0],
            )),
        ),
        cylinder_points(
            &[
                (2, -0.42598738307568),
                (2, -0.42601113734424595),
                (1, -0.42727153757506176),
                (0, 0.0),
                (0, 0.0),
            ],
            Some((
                2.7526012909624504,
                [
                    -0.17871737423632933,
                    0.4756567543712015,
                    -0.11237123300111243,
                ],
            )),
        ),
        cylinder_points(
            &[
                (0, 0.2080720927180703),
                (1, 0.0),
                (0, 0.0),
                (2, 0.20802879315376016),
                (0, -0.46638159293283776),
                (1, 0.36201579048726973),
            ],
            Some((
                1.4595187755554113,
                [0.6787096209978919, 0.6841921302476727, -0.6077581994236956],
            )),
        ),
        cylinder_points(
            &[
                (0, 0.6068985165605779),
                (0, 0.0),
                (0, 0.6086708370304109),
                (1, 0.6030356672656332),
                (2, 0.6079621091622575),
            ],
            Some((
                -2.371847584492004,
                [0.17055589283953593, 0.0, 0.3377871981388674],
            )),
        ),
        // Points on the faces of a box: a coplanar fan around an interior vertex, and a
        // vertex within the tolerance of an edge.
        vec![
            Vec3::new(0.8437221, -0.27092493, -1.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, -0.90012956, 0.88029194),
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(1.0, 0.74391276, 0.56479424),
            Vec3::new(1.0, 0.34484863, -0.641543),
        ],
        vec![
            Vec3::new(0.0490213, -0.5262723, -1.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(-0.7277036, 1.0, 0.84221506),
            Vec3::new(0.0, -1.0, 0.0),
            Vec3::new(0.80617654, -0.53981286, -1.0),
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::new(-1.0, -0.974057, -0.9974077),
            Vec3::new(-0.74138206, -0.51229805, -1.0),
            Vec3::new(-1.0, 0.0, 0.0),
        ],
    ];
    for (k, pts) in clouds.iter().enumerate() {
        let hull = ConvexHull::new(pts).unwrap_or_else(|e| panic!("cloud {k}: {e}"));
        check_hull(pts, &hull);
    }
}
