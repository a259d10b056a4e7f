//! Quickhull and `ConvexHull` against oracles on random clouds: the brute-force hull (volume,
//! vertex set, planes), invariants (containment, planar convex faces, closed manifold with
//! Euler's formula, merged coplanar faces) on random and degenerate clouds, hill-climbing
//! support against a scan, and errors for flat inputs.

mod support;

use carom_collision::math::{real, Real, Vec3, EPSILON};
use carom_collision::shape::{ConvexHull, SupportMap};
use proptest::prelude::*;
use support::brute_force_hull::brute_force_hull;
use support::hull_checks::{check_hull, extent, polygon_plane, polygons_volume};

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
