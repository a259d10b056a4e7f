//! Quickhull and `ConvexHull` against oracles: the brute-force hull, invariants (containment,
//! planar convex faces, closed manifold with Euler's formula, merged coplanar faces), analytic
//! mass properties, the Taru point cloud's reference values, and errors for degenerate inputs.

mod support;

use carom_collision::math::{real, Mat3, Real, Vec3, EPSILON};
use carom_collision::shape::{polyhedron_mass_properties, quickhull, ConvexHull, SupportMap};
use carom_collision::CaromError;
use proptest::prelude::*;
use support::brute_force_hull::brute_force_hull;

/// Largest coordinate magnitude of `points` about their bounding-box centre.
fn extent(points: &[Vec3]) -> Real {
    let (lo, hi) = points.iter().fold(
        (Vec3::splat(Real::MAX), Vec3::splat(Real::MIN)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    ((hi - lo) * 0.5).max_element()
}

/// Length tolerance for checks on a hull of `points`: relative to its size, plus the rounding
/// of plane offsets far from the origin.
fn tolerance(points: &[Vec3]) -> Real {
    let far = points
        .iter()
        .fold(0.0 as Real, |m, p| m.max(p.abs().max_element()));
    1000.0 * EPSILON * extent(points) + 16.0 * EPSILON * far
}

/// A small deterministic generator (64-bit LCG) for fixed test clouds.
struct Lcg(u64);

impl Lcg {
    fn unit(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn symmetric(&mut self) -> f64 {
        2.0 * self.unit() - 1.0
    }
    fn point(&mut self) -> Vec3 {
        Vec3::new(
            real(self.symmetric()),
            real(self.symmetric()),
            real(self.symmetric()),
        )
    }
}

/// Checks every invariant of a hull built from `points`; returns the number of hull vertices.
fn check_hull(points: &[Vec3], hull: &ConvexHull) -> usize {
    let tol = tolerance(points);
    let verts = hull.vertices();
    // Hull vertices are distinct input points.
    for (i, v) in verts.iter().enumerate() {
        assert!(points.contains(v), "vertex {i} {v:?} is not an input point");
        assert!(!verts[..i].contains(v), "vertex {i} {v:?} repeated");
    }
    // Every input point is inside or on the hull.
    for face in hull.faces() {
        assert!(
            (face.normal.length() - 1.0).abs() < 1e-3,
            "normal {:?}",
            face.normal
        );
        for p in points {
            let d = face.normal.dot(*p) - face.offset;
            assert!(d <= tol, "point {p:?} is {d} outside face {face:?}");
        }
    }
    // Faces are planar, convex and without collinear vertices.
    for (f, face) in hull.faces().iter().enumerate() {
        let loop_ = hull.face_vertices(f);
        let n = loop_.len();
        assert!(n >= 3, "face {f} has {n} vertices");
        for k in 0..n {
            let u = verts[loop_[(k + n - 1) % n] as usize];
            let v = verts[loop_[k] as usize];
            let w = verts[loop_[(k + 1) % n] as usize];
            let d = face.normal.dot(v) - face.offset;
            assert!(d.abs() <= tol, "face {f} not planar: vertex off by {d}");
            let turn = (v - u).cross(w - v).dot(face.normal) / (w - u).length();
            assert!(
                turn > EPSILON * extent(points),
                "face {f} vertex {k}: reflex or collinear (turn {turn})"
            );
        }
    }
    // Closed and oriented: every directed edge once, its reverse once; V - E + F = 2.
    let mut directed: Vec<(u32, u32, usize)> = Vec::new();
    for f in 0..hull.faces().len() {
        let l = hull.face_vertices(f);
        for k in 0..l.len() {
            directed.push((l[k], l[(k + 1) % l.len()], f));
        }
    }
    directed.sort_unstable();
    for w in directed.windows(2) {
        assert!((w[0].0, w[0].1) != (w[1].0, w[1].1), "edge {w:?} twice");
    }
    for &(a, b, f) in &directed {
        let twin = directed
            .binary_search_by(|e| (e.0, e.1).cmp(&(b, a)))
            .unwrap_or_else(|_| panic!("edge ({a}, {b}) of face {f} has no twin"));
        let g = directed[twin].2;
        // Adjacent faces were merged if coplanar: some vertex of g lies clearly below f.
        // Measured from a vertex of f: differences of nearby floats are exact.
        let nf = hull.faces()[f].normal;
        let origin = verts[hull.face_vertices(f)[0] as usize];
        let deepest = hull
            .face_vertices(g)
            .iter()
            .map(|&i| nf.dot(verts[i as usize] - origin))
            .fold(0.0 as Real, Real::min);
        let coplanar_tol = 2.0 * EPSILON * extent(points);
        assert!(
            deepest < -coplanar_tol,
            "faces {f} and {g} are coplanar ({deepest})"
        );
    }
    let (v, e, f) = (verts.len(), directed.len() / 2, hull.faces().len());
    assert_eq!(
        v as i64 - e as i64 + f as i64,
        2,
        "Euler: V={v} E={e} F={f}"
    );
    assert_eq!(hull.edges().len(), e);
    // Adjacency is the edge list, both ways.
    for (i, _) in verts.iter().enumerate() {
        for &j in hull.vertex_neighbors(i) {
            let (a, b) = (i.min(j as usize) as u32, i.max(j as usize) as u32);
            assert!(
                hull.edges().contains(&[a, b]),
                "neighbour {i}-{j} is no edge"
            );
            assert!(hull.vertex_neighbors(j as usize).contains(&(i as u32)));
        }
    }
    let degree: usize = (0..v).map(|i| hull.vertex_neighbors(i).len()).sum();
    assert_eq!(degree, 2 * e);
    v
}

/// Volume of a polygon hull (fan triangulation).
fn polygons_volume(vertices: &[Vec3], faces: &[Vec<u32>]) -> Real {
    let mut tris = Vec::new();
    for f in faces {
        for k in 1..f.len() - 1 {
            tris.push([f[0], f[k], f[k + 1]]);
        }
    }
    polyhedron_mass_properties(vertices, &tris).0
}

/// Newell plane of a polygon.
fn polygon_plane(vertices: &[Vec3], face: &[u32]) -> (Vec3, Real) {
    let mut n = Vec3::ZERO;
    let mut c = Vec3::ZERO;
    for k in 0..face.len() {
        let p = vertices[face[k] as usize];
        let q = vertices[face[(k + 1) % face.len()] as usize];
        n += p.cross(q);
        c += p;
    }
    let n = n.normalize();
    (n, n.dot(c / face.len() as Real))
}

/// Whether some point lies within the brute-force oracle's tolerance (`1e-5 ×` the scale)
/// of a nearly supporting plane through three other points without being on it: there the
/// oracle's answer is ambiguous (it is approximate by design), so such clouds are skipped.
fn ambiguous_for_oracle(points: &[Vec3]) -> bool {
    let scale = points
        .iter()
        .fold(0.0 as Real, |m, p| m.max(p.abs().max_element()));
    let gap = 2e-5 * scale;
    let n = points.len();
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                let (a, b, c) = (points[i], points[j], points[k]);
                let Some(normal) = (b - a).cross(c - a).try_normalize() else {
                    continue;
                };
                let d: Vec<Real> = points.iter().map(|p| normal.dot(*p - a)).collect();
                let max = d.iter().copied().fold(Real::MIN, Real::max);
                let min = d.iter().copied().fold(Real::MAX, Real::min);
                if max > gap && min < -gap {
                    continue;
                }
                if points
                    .iter()
                    .zip(&d)
                    .any(|(p, d)| ![a, b, c].contains(p) && d.abs() < gap)
                {
                    return true;
                }
            }
        }
    }
    false
}

fn cloud(max: usize) -> impl Strategy<Value = Vec<Vec3>> {
    prop::collection::vec(
        (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0)
            .prop_map(|(x, y, z)| Vec3::new(real(x), real(y), real(z))),
        5..max,
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Quickhull equals the brute-force hull: volume, vertex set (up to points within the
    /// oracle's tolerance of the other hull's surface) and face planes.
    #[test]
    fn quickhull_matches_brute_force(mut points in cloud(28), dups in 0usize..4) {
        for k in 0..dups {
            let p = points[(k * 7) % points.len()];
            points.push(p);
        }
        prop_assume!(!ambiguous_for_oracle(&points));
        let oracle = brute_force_hull(&points).expect("random cloud has a hull");
        let hull = ConvexHull::new(&points).expect("random cloud has a hull");
        check_hull(&points, &hull);
        let scale = extent(&points);
        let cmp_tol = 1e-4 * scale;
        let v_oracle = polygons_volume(&oracle.vertices, &oracle.faces);
        prop_assert!((hull.volume() - v_oracle).abs() <= 1e-3 * v_oracle,
            "volume {} vs oracle {}", hull.volume(), v_oracle);
        let oracle_planes: Vec<(Vec3, Real)> =
            oracle.faces.iter().map(|f| polygon_plane(&oracle.vertices, f)).collect();
        let outside = |planes: &[(Vec3, Real)], p: Vec3| {
            planes.iter().map(|(n, d)| n.dot(p) - d).fold(Real::MIN, Real::max)
        };
        let hull_planes: Vec<(Vec3, Real)> =
            hull.faces().iter().map(|f| (f.normal, f.offset)).collect();
        for v in hull.vertices() {
            if !oracle.vertices.contains(v) {
                prop_assert!(outside(&oracle_planes, *v) > -cmp_tol, "extra vertex {v:?}");
            }
        }
        for v in &oracle.vertices {
            if !hull.vertices().contains(v) {
                prop_assert!(outside(&hull_planes, *v) > -cmp_tol, "missing vertex {v:?}");
            }
        }
        let same = |a: &(Vec3, Real), b: &(Vec3, Real)| {
            (a.0 - b.0).length() < 1e-2 && (a.1 - b.1).abs() < 1e-2 * scale
        };
        for p in &hull_planes {
            prop_assert!(oracle_planes.iter().any(|q| same(p, q)), "plane {p:?} not in oracle");
        }
        for q in &oracle_planes {
            prop_assert!(hull_planes.iter().any(|p| same(p, q)), "oracle plane {q:?} missing");
        }
    }

    /// Invariants on bigger clouds, shifted far from the origin and scaled.
    #[test]
    fn hull_invariants_on_random_clouds(
        points in cloud(200),
        offset in (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0),
        log_scale in -3i32..4,
    ) {
        let s = real(10f64.powi(log_scale));
        let o = Vec3::new(real(offset.0), real(offset.1), real(offset.2)) * (10.0 * s);
        let points: Vec<Vec3> = points.iter().map(|p| *p * s + o).collect();
        let hull = ConvexHull::new(&points).expect("random cloud has a hull");
        check_hull(&points, &hull);
    }

    /// Invariants on clouds full of coplanar and collinear subsets: integer lattices, points on
    /// the faces of a box, on a sphere, on two circles (a cylinder), each optionally rotated
    /// (which makes exactly coplanar points nearly coplanar).
    #[test]
    fn hull_invariants_on_degenerate_clouds(
        raw in prop::collection::vec((0u32..4, 0u32..4, 0u32..4, -1.0f64..1.0, -1.0f64..1.0), 8..150),
        kind in 0usize..4,
        angle in prop::option::of((-3.0f64..3.0, -1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0)),
    ) {
        let points: Vec<Vec3> = raw
            .iter()
            .map(|&(i, j, k, s, t)| {
                let p = match kind {
                    0 => Vec3::new(i as Real, j as Real, k as Real),
                    1 => {
                        let (a, b) = (real(s), real(t));
                        let side = if i % 2 == 0 { -1.0 } else { 1.0 };
                        match j % 3 {
                            0 => Vec3::new(side, a, b),
                            1 => Vec3::new(a, side, b),
                            _ => Vec3::new(a, b, side),
                        }
                    }
                    2 => Vec3::new(real(s), real(t), real(s * t - 0.3))
                        .try_normalize()
                        .unwrap_or(Vec3::X),
                    _ => {
                        let a = real(s * std::f64::consts::PI);
                        Vec3::new(a.cos(), if i % 2 == 0 { -1.0 } else { 1.0 }, a.sin())
                    }
                };
                match angle {
                    Some((w, x, y, z)) => {
                        let axis = Vec3::new(real(x), real(y), real(z));
                        let axis = axis.try_normalize().unwrap_or(Vec3::Z);
                        carom_collision::math::Quat::from_axis_angle(axis, real(w)) * p
                    }
                    None => p,
                }
            })
            .collect();
        match ConvexHull::new(&points) {
            Ok(hull) => {
                check_hull(&points, &hull);
            }
            Err(e) => {
                // Only flat inputs may fail.
                let msg = e.to_string();
                prop_assert!(msg.contains("coplanar") || msg.contains("collinear")
                    || msg.contains("coincide"), "{msg}");
            }
        }
    }

    /// Hill-climbing support equals the brute-force support on random directions.
    #[test]
    fn hill_climbing_support_matches_scan(
        points in cloud(400),
        dirs in prop::collection::vec((-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0), 16),
    ) {
        // Push the points onto a sphere so that most of them are hull vertices.
        let points: Vec<Vec3> = points
            .iter()
            .filter_map(|p| p.try_normalize())
            .collect();
        prop_assume!(points.len() >= 8);
        let hull = ConvexHull::new(&points).expect("sphere cloud has a hull");
        for d in dirs {
            let d = Vec3::new(real(d.0), real(d.1), real(d.2));
            let best = hull.vertices().iter().map(|v| v.dot(d)).fold(Real::MIN, Real::max);
            let got = hull.support(d).dot(d);
            prop_assert!(got >= best - 8.0 * EPSILON, "support {got} < max {best}");
            prop_assert!(hull.vertices().contains(&hull.support(d)));
        }
    }

    /// Flat and degenerate random inputs give errors, never panics.
    #[test]
    fn degenerate_random_inputs_are_rejected(
        points in cloud(40),
        kind in 0usize..4,
        normal in (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0),
    ) {
        let n = Vec3::new(real(normal.0), real(normal.1), real(normal.2));
        prop_assume!(n.length() > 0.1);
        let n = n.normalize();
        let origin = points[0];
        let flat: Vec<Vec3> = match kind {
            // On a plane through `origin` with normal `n`.
            0 => points.iter().map(|p| *p - n * n.dot(*p - origin)).collect(),
            // On a line.
            1 => points.iter().map(|p| origin + n * p.x).collect(),
            // One point repeated.
            2 => vec![origin; points.len()],
            // Too few points.
            _ => points[..3].to_vec(),
        };
        prop_assert!(ConvexHull::new(&flat).is_err());
    }
}

fn cube_surface_grid(k: usize, half: Vec3, centre: Vec3) -> Vec<Vec3> {
    let mut pts = Vec::new();
    for i in 0..k {
        for j in 0..k {
            for l in 0..k {
                if [i, j, l].iter().any(|&c| c == 0 || c == k - 1) {
                    let t = |c: usize| real(2.0 * c as f64 / (k - 1) as f64 - 1.0);
                    pts.push(centre + Vec3::new(t(i), t(j), t(l)) * half);
                }
            }
        }
    }
    pts
}

fn assert_box(hull: &ConvexHull, half: Vec3, centre: Vec3, rel: Real) {
    assert_eq!(hull.vertices().len(), 8);
    assert_eq!(hull.faces().len(), 6);
    assert!((0..6).all(|f| hull.face_vertices(f).len() == 4));
    let size = half * 2.0;
    let volume = size.x * size.y * size.z;
    assert!(
        (hull.volume() - volume).abs() <= rel * volume,
        "volume {}",
        hull.volume()
    );
    let mp = hull.mass_properties(2.0);
    let m = 2.0 * volume;
    assert!((mp.mass - m).abs() <= rel * m);
    assert!((mp.center_of_mass - centre).length() <= rel * size.length() + rel * centre.length());
    let expected = Mat3::from_diagonal(Vec3::new(
        m / 12.0 * (size.y * size.y + size.z * size.z),
        m / 12.0 * (size.x * size.x + size.z * size.z),
        m / 12.0 * (size.x * size.x + size.y * size.y),
    ));
    let scale = expected
        .x_axis
        .x
        .max(expected.y_axis.y)
        .max(expected.z_axis.z);
    for i in 0..3 {
        let diff = (mp.inertia.col(i) - expected.col(i)).abs().max_element();
        assert!(
            diff <= 10.0 * rel * scale,
            "inertia {:?} vs {expected:?}",
            mp.inertia
        );
    }
}

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
