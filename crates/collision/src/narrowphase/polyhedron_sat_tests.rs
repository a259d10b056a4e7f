//! The edge query's pruning against the unpruned loop over every edge pair (the oracle),
//! and [`crossing_edges`] against the per-edge test of both faces' signs.

use super::*;
use crate::math::{Quat, Vec3};
use crate::shape::ConvexHull;
use proptest::prelude::*;

/// The edge query as it was before any pruning: every edge of A against every edge of B,
/// Gregorius' test on each pair, in index order.
fn edge_query_unpruned(
    a: &Polyhedron,
    b: &Polyhedron,
    posed: &PosedPolyhedron,
) -> (Real, usize, usize, Vec3) {
    let mut best = (Real::NEG_INFINITY, 0, 0, Vec3::ZERO);
    let va = a.vertices();
    let a_centre = va.iter().fold(Vec3::ZERO, |s, v| s + *v) / va.len().max(1) as Real;
    for (i, (ea, fa)) in a.edges().iter().zip(a.edge_faces()).enumerate() {
        let (pa, qa) = (va[ea[0] as usize], va[ea[1] as usize]);
        let edge_a = EdgeOf {
            index: i,
            p: pa,
            d: qa - pa,
            n0: a.faces()[fa[0] as usize].normal,
            n1: a.faces()[fa[1] as usize].normal,
        };
        for j in 0..b.edges().len() {
            edge_pair(&edge_a, j, b, posed, va, a_centre, &mut best);
        }
    }
    best
}

/// A hull of `n` points drawn from `seed`: on a sphere of radius `r` (many faces) or in a
/// box (few).
fn hull(seed: u64, n: usize, round: bool) -> ConvexHull {
    let mut s = seed | 1;
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as Real / (1u64 << 53) as Real - 0.5
    };
    let points: Vec<Vec3> = (0..n)
        .map(|_| {
            let p = Vec3::new(next(), next(), next() * 0.6);
            if round {
                p.normalize_or_zero() * 1.5
            } else {
                p
            }
        })
        .collect();
    ConvexHull::new(&points).expect("random points span a volume")
}

fn pose(t: [Real; 3], axis: [Real; 3], angle: Real) -> Isometry {
    let axis = Vec3::from(axis).normalize_or(Vec3::X);
    Isometry::new(Vec3::from(t), Quat::from_axis_angle(axis, angle))
}

/// The case proptest found (session 26): 27 points whose hull has more than 64 edges, which
/// the test above took for a small hull. Such hulls get no masks.
#[test]
fn a_hull_of_more_than_64_edges_has_no_masks() {
    let h = hull(8233957354457101378, 27, false);
    let p = Polyhedron::from_hull(&h);
    assert!(p.edge_faces().len() > 64, "{} edges", p.edge_faces().len());
    assert!(face_edge_masks(&p).is_none());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// The pruned query finds exactly what the unpruned loop finds, bit for bit, for hulls
    /// with up to 64 faces and edges (the masks) and beyond (the per-edge sign test).
    #[test]
    fn edge_query_equals_the_unpruned_loop(
        seed_a in any::<u64>(),
        seed_b in any::<u64>(),
        n_a in 4usize..40,
        n_b in 4usize..120,
        round in any::<bool>(),
        t in prop::array::uniform3(-2.0 as Real..2.0),
        axis in prop::array::uniform3(-1.0 as Real..1.0),
        angle in -3.2 as Real..3.2,
    ) {
        let (ha, hb) = (hull(seed_a, n_a, false), hull(seed_b, n_b, round));
        let (a, b) = (Polyhedron::from_hull(&ha), Polyhedron::from_hull(&hb));
        let posed = PosedPolyhedron::new(&b, &pose(t, axis, angle), false);
        let (s, i, j, ax) = edge_query(&a, &b, &posed);
        let (s0, i0, j0, ax0) = edge_query_unpruned(&a, &b, &posed);
        prop_assert_eq!((s.to_bits(), i, j), (s0.to_bits(), i0, j0));
        prop_assert_eq!(ax.to_array().map(Real::to_bits), ax0.to_array().map(Real::to_bits));
    }

    /// `crossing_edges` marks exactly the edges whose faces' normals lie strictly on
    /// opposite sides of `d`, including directions in a face's plane (a zero dot product
    /// is on neither side).
    #[test]
    fn crossing_edges_are_the_edges_whose_faces_straddle(
        seed in any::<u64>(),
        n in 4usize..30,
        d in prop::array::uniform3(-1.0 as Real..1.0),
        along_face in any::<Option<prop::sample::Index>>(),
    ) {
        let h = hull(seed, n, false);
        let p = Polyhedron::from_hull(&h);
        let normals: Vec<Vec3> = p.faces().iter().map(|f| f.normal).collect();
        // A direction perpendicular to a face normal puts that face on neither side.
        let d = match along_face {
            Some(k) => normals[k.index(normals.len())].cross(Vec3::from(d)),
            None => Vec3::from(d),
        };
        // Up to 29 points can make a hull of more than 64 edges (24 vertices or more on
        // the hull): no masks then, and the edge query takes its scalar pass.
        let Some(masks) = face_edge_masks(&p) else {
            prop_assert!(p.faces().len() > 64 || p.edge_faces().len() > 64);
            return Ok(());
        };
        let bits = crossing_edges(&normals, &masks, d);
        for (e, f) in p.edge_faces().iter().enumerate() {
            let (x0, x1) = (normals[f[0] as usize].dot(d), normals[f[1] as usize].dot(d));
            let straddle = (x0 > 0.0 && x1 < 0.0) || (x0 < 0.0 && x1 > 0.0);
            prop_assert_eq!(bits >> e & 1 == 1, straddle, "edge {}", e);
        }
        prop_assert_eq!(bits >> p.edge_faces().len(), 0);
    }
}

/// A hull with more than 64 faces takes the per-edge path, and still agrees.
#[test]
fn a_hull_of_many_faces_takes_the_per_edge_path() {
    let big = hull(7, 400, true);
    let small = hull(11, 20, false);
    let (a, b) = (Polyhedron::from_hull(&small), Polyhedron::from_hull(&big));
    assert!(face_edge_masks(&b).is_none());
    for k in 0..20 {
        let angle = k as Real * 0.3;
        let posed =
            PosedPolyhedron::new(&b, &pose([0.4, -0.2, 0.1], [1.0, 2.0, 0.5], angle), false);
        let (s, i, j, _) = edge_query(&a, &b, &posed);
        let (s0, i0, j0, _) = edge_query_unpruned(&a, &b, &posed);
        assert_eq!((s.to_bits(), i, j), (s0.to_bits(), i0, j0));
    }
}
