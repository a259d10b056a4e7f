//! Capsule–box contacts and manifolds against independent oracles computed in f64:
//! the segment–box distance by ternary search on the (convex) point–box distance along the
//! segment, the penetration depth as the least support value of the Minkowski difference
//! (brute force over the supporting planes of box ⊕ segment), and analytic manifolds for a capsule lying flat, tilted,
//! hanging over a face's edge, standing, and across an edge; near and far from the origin,
//! touching and parallel, with the shapes in both orders.

mod common;

use carom_collision::math::{Isometry, Quat, Real, Vec3};
use carom_collision::narrowphase::{ContactManifold, Dispatcher};
use carom_collision::query;
use carom_collision::shape::{Capsule, Cuboid, Shape};
use common::Rng;

type V = [f64; 3];

fn v(x: Vec3) -> V {
    [x.x as f64, x.y as f64, x.z as f64]
}
fn sub(a: V, b: V) -> V {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: V, b: V) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn lerp(a: V, b: V, t: f64) -> V {
    [
        a[0] + (b[0] - a[0]) * t,
        a[1] + (b[1] - a[1]) * t,
        a[2] + (b[2] - a[2]) * t,
    ]
}

/// Distance from a point to the box of half extents `h` (0 inside).
fn point_box(x: V, h: V) -> f64 {
    (0..3)
        .map(|i| (x[i].abs() - h[i]).max(0.0).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// Signed distance from a point to the box's surface (negative inside).
fn point_box_signed(x: V, h: V) -> f64 {
    let out = point_box(x, h);
    if out > 0.0 {
        out
    } else {
        -(0..3)
            .map(|i| h[i] - x[i].abs())
            .fold(f64::INFINITY, f64::min)
    }
}

/// Distance from a point to the segment `p q`.
fn point_segment(x: V, p: V, q: V) -> f64 {
    let d = sub(q, p);
    let t = (dot(sub(x, p), d) / dot(d, d)).clamp(0.0, 1.0);
    let y = lerp(p, q, t);
    dot(sub(x, y), sub(x, y)).sqrt()
}

/// Segment–box distance by ternary search (the distance is convex along the segment).
fn segment_box(p: V, q: V, h: V) -> f64 {
    let f = |t: f64| point_box(lerp(p, q, t), h);
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    for _ in 0..200 {
        let (m1, m2) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
        if f(m1) <= f(m2) {
            hi = m2;
        } else {
            lo = m1;
        }
    }
    f(0.5 * (lo + hi)).min(f(0.0)).min(f(1.0))
}

/// The translation along `−u` of the capsule (segment `p q`, radius `r`) that separates it
/// from the box: the support of box ⊕ segment along `u`, plus `r`.
fn support_gap(u: V, p: V, q: V, r: f64, h: V) -> f64 {
    (0..3).map(|i| h[i] * u[i].abs()).sum::<f64>() + dot(u, p).max(dot(u, q)) + r
}

/// The signed distance of the capsule (segment `p q`, radius `r`) and the box.
fn oracle(p: V, q: V, r: f64, h: V) -> f64 {
    let dcore = segment_box(p, q, h);
    if dcore > 1e-9 {
        return dcore - r;
    }
    // The cores overlap: the depth is the distance from the origin to the boundary of the
    // polytope box ⊕ segment (whose support is `support_gap − r`), found by brute force over
    // the supporting planes through every triple of its 16 candidate vertices.
    let mut pts = Vec::with_capacity(16);
    for s in [p, q] {
        for k in 0..8 {
            let c = |i: usize| if k >> i & 1 == 1 { h[i] } else { -h[i] };
            pts.push([s[0] + c(0), s[1] + c(1), s[2] + c(2)]);
        }
    }
    let mut best = f64::INFINITY;
    for i in 0..16 {
        for j in i + 1..16 {
            for k in j + 1..16 {
                let n = cross(sub(pts[j], pts[i]), sub(pts[k], pts[i]));
                let l = dot(n, n).sqrt();
                if l < 1e-9 {
                    continue;
                }
                let n = [n[0] / l, n[1] / l, n[2] / l];
                let off = dot(n, pts[i]);
                let (lo, hi) = pts
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                        (lo.min(dot(n, *x) - off), hi.max(dot(n, *x) - off))
                    });
                if hi <= 1e-9 {
                    best = best.min(off);
                } else if lo >= -1e-9 {
                    best = best.min(-off);
                }
            }
        }
    }
    -best - r
}

fn cross(a: V, b: V) -> V {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn tol() -> f64 {
    if std::mem::size_of::<Real>() == 4 {
        2e-4
    } else {
        1e-7
    }
}

/// Checks one contact (box B's frame: `p q` the capsule's segment) against the oracle.
fn check_contact(c: &query::Contact, p: V, q: V, r: f64, h: V, truth: f64, ctx: &str) {
    let (n, pa, pb) = (v(c.normal), v(c.point_a), v(c.point_b));
    let dist = c.distance as f64;
    assert!((dot(n, n).sqrt() - 1.0).abs() < 1e-5, "{ctx}: normal {n:?}");
    if truth < -r {
        // Overlapping cores: the depth along n is the support gap along n, and the least.
        let gap = support_gap(n, p, q, r, h);
        assert!(
            (gap + dist).abs() < 10.0 * tol(),
            "{ctx}: gap {gap} vs {dist}"
        );
        assert!(
            -dist <= -truth + 10.0 * tol(),
            "{ctx}: {dist} deeper than {truth}"
        );
        assert!(
            -dist >= -truth - 10.0 * tol(),
            "{ctx}: {dist} shallower than {truth}"
        );
    } else {
        assert!(
            (dist - truth).abs() < 10.0 * tol(),
            "{ctx}: {dist} vs {truth}"
        );
    }
    // Witnesses: B's on the box surface, A's on (or in) the capsule, joined along n.
    assert!(
        point_box_signed(pb, h).abs() < 10.0 * tol(),
        "{ctx}: point_b {pb:?}"
    );
    assert!(
        point_segment(pa, p, q) < r + 10.0 * tol(),
        "{ctx}: point_a {pa:?}"
    );
    let w = sub(pb, pa);
    for i in 0..3 {
        assert!(
            (w[i] - n[i] * dist).abs() < 10.0 * tol(),
            "{ctx}: witness {w:?}"
        );
    }
}

fn random_case(rng: &mut Rng) -> (Capsule, Cuboid, Isometry) {
    let h = Vec3::new(
        rng.range(0.1, 1.5),
        rng.range(0.1, 1.5),
        rng.range(0.1, 1.5),
    );
    let cap = Capsule::new(rng.range(0.05, 0.5), rng.range(0.05, 1.5)).unwrap();
    let reach = h + Vec3::splat(cap.radius() + cap.half_height() + 0.1);
    let t = Vec3::new(
        rng.range(-reach.x, reach.x),
        rng.range(-reach.y, reach.y),
        rng.range(-reach.z, reach.z),
    );
    let rot = Quat::from_axis_angle(rng.unit(), rng.range(0.0, 3.1));
    (cap, Cuboid::new(h).unwrap(), Isometry::new(t, rot))
}

#[test]
fn random_capsule_box_contacts_match_the_oracle() {
    let mut rng = Rng::new(61);
    let (mut deep, mut shallow, mut apart) = (0, 0, 0);
    for i in 0..600 {
        let (cap, bx, pose_cap) = random_case(&mut rng);
        let (s0, s1) = cap.segment();
        let (p, q) = (
            v(pose_cap.transform_point(s0)),
            v(pose_cap.transform_point(s1)),
        );
        let (r, h) = (cap.radius() as f64, v(bx.half_extents()));
        let truth = oracle(p, q, r, h);
        let (sa, sb) = (Shape::Capsule(cap), Shape::Cuboid(bx));
        let c = query::contact(&sa, &pose_cap, &sb, &Isometry::IDENTITY, Real::INFINITY)
            .unwrap()
            .unwrap();
        // The box sits at the origin: world frame = the box's frame.
        check_contact(&c, p, q, r, h, truth, &format!("case {i} capsule-box"));
        let c = query::contact(&sb, &Isometry::IDENTITY, &sa, &pose_cap, Real::INFINITY)
            .unwrap()
            .unwrap();
        check_contact(
            &c.swapped(),
            p,
            q,
            r,
            h,
            truth,
            &format!("case {i} box-capsule"),
        );
        match truth {
            t if t < -r => deep += 1,
            t if t < 0.0 => shallow += 1,
            _ => apart += 1,
        }
    }
    assert!(
        deep > 50 && shallow > 50 && apart > 50,
        "{deep} {shallow} {apart}"
    );
}

fn manifold(a: &Shape, pa: &Isometry, b: &Shape, pb: &Isometry) -> ContactManifold {
    let mut m = ContactManifold::new();
    Dispatcher::default()
        .update_manifold(a, pa, b, pb, &mut m)
        .unwrap();
    m
}

#[test]
fn random_capsule_box_manifolds_hold_the_deepest_point_and_no_deeper() {
    let mut rng = Rng::new(62);
    let pred = Dispatcher::default().config.prediction as f64;
    let mut two = 0;
    for i in 0..400 {
        let (cap, bx, pose_cap) = random_case(&mut rng);
        let (s0, s1) = cap.segment();
        let (p, q) = (
            v(pose_cap.transform_point(s0)),
            v(pose_cap.transform_point(s1)),
        );
        let (r, h) = (cap.radius() as f64, v(bx.half_extents()));
        let truth = oracle(p, q, r, h);
        let (sa, sb) = (Shape::Capsule(cap), Shape::Cuboid(bx));
        for swap in [false, true] {
            let m = if swap {
                manifold(&sb, &Isometry::IDENTITY, &sa, &pose_cap)
            } else {
                manifold(&sa, &pose_cap, &sb, &Isometry::IDENTITY)
            };
            if truth > pred + 10.0 * tol() {
                assert!(m.points.is_empty(), "case {i}: {truth}");
                continue;
            }
            if truth < pred - 10.0 * tol() {
                assert!(!m.points.is_empty(), "case {i}: lost contact at {truth}");
            }
            if m.points.is_empty() {
                continue;
            }
            two += usize::from(m.len() == 2);
            let min = m
                .points
                .iter()
                .map(|c| c.distance as f64)
                .fold(f64::INFINITY, f64::min);
            // A normal within 0.8° of a face normal is snapped to it (`FACE_COS`): the
            // clipped points' gap is then measured along the face normal, longer than the
            // cores' distance by at most 1 − cos 0.8° = 1e-4 of it.
            let slack = 10.0 * tol() + 1.5e-4 * (truth + r).abs();
            assert!(
                min >= truth - 10.0 * tol(),
                "case {i}: point at {min} deeper than {truth}"
            );
            assert!(
                min <= truth + slack,
                "case {i} swap {swap}: deepest point {min} vs {truth}: {:?} {p:?} {q:?} {r} {h:?}",
                m.points
            );
            for c in &m.points {
                assert!(c.is_finite() && c.distance as f64 <= pred + 1e-6);
                let (pa, pb) = (v(c.point_a()), v(c.point_b));
                // The box is B in the unswapped order, A when swapped.
                let (on_box, on_cap) = if swap { (pa, pb) } else { (pb, pa) };
                assert!(
                    point_box_signed(on_box, h).abs() < 10.0 * tol(),
                    "case {i} box pt"
                );
                assert!(
                    point_segment(on_cap, p, q) < r + 10.0 * tol(),
                    "case {i} cap pt"
                );
            }
        }
    }
    assert!(two > 20, "{two} two-point manifolds");
}

/// The contact points on the box (world frame), sorted by x, with their distances.
fn box_points(m: &ContactManifold, swap: bool) -> Vec<(Vec3, Real)> {
    let mut pts: Vec<(Vec3, Real)> = m
        .points
        .iter()
        .map(|c| (if swap { c.point_a() } else { c.point_b }, c.distance))
        .collect();
    pts.sort_by(|a, b| a.0.x.total_cmp(&b.0.x));
    pts
}

#[test]
fn capsule_lying_flat_or_tilted_on_a_face_gives_two_analytic_points() {
    for far in [Vec3::ZERO, Vec3::new(1000.0, -500.0, 800.0)] {
        let tol: Real = if far == Vec3::ZERO { 1e-4 } else { 2e-3 };
        for swap in [false, true] {
            // Flat along x, 1 cm into the top face (y = 0.5): the segment's ends.
            let lift = Vec3::new(0.1, 0.5 + 0.25 - 0.01, 0.2);
            let rot = Quat::from_rotation_z(std::f64::consts::FRAC_PI_2 as Real);
            let bx = Shape::Cuboid(Cuboid::new(Vec3::new(1.0, 0.5, 1.0)).unwrap());
            let cap = Shape::Capsule(Capsule::new(0.25, 0.6).unwrap());
            let pc = Isometry::new(far + lift, rot);
            let pb = Isometry::from_translation(far);
            let m = if swap {
                manifold(&bx, &pb, &cap, &pc)
            } else {
                manifold(&cap, &pc, &bx, &pb)
            };
            let pts = box_points(&m, swap);
            assert_eq!(pts.len(), 2, "{pts:?}");
            for (x, (pt, d)) in [-0.5, 0.7].iter().zip(&pts) {
                let local = *pt - far;
                assert!((local.x - x).abs() < tol, "{pts:?}");
                assert!((local.y - 0.5).abs() < tol && (local.z - 0.2).abs() < tol);
                assert!((d + 0.01).abs() < tol, "{pts:?}");
            }
            // Tilted by asin(0.01 / 1.2): one end 1 cm in, the other touching.
            let tilt = (0.01 as Real / 1.2).asin();
            let rot = Quat::from_rotation_z(std::f64::consts::FRAC_PI_2 as Real - tilt);
            let centre = Vec3::new(0.0, 0.5 + 0.25 - 0.005, 0.0);
            let pc = Isometry::new(far + centre, rot);
            let m = if swap {
                manifold(&bx, &pb, &cap, &pc)
            } else {
                manifold(&cap, &pc, &bx, &pb)
            };
            let pts = box_points(&m, swap);
            assert_eq!(pts.len(), 2, "{pts:?}");
            let ds: Vec<Real> = pts.iter().map(|p| p.1).collect();
            let (lo, hi) = (ds[0].min(ds[1]), ds[0].max(ds[1]));
            assert!((lo + 0.01).abs() < tol && hi.abs() < tol, "{ds:?}");
        }
    }
}

#[test]
fn capsule_hanging_over_an_edge_is_clipped_at_the_side_plane() {
    let bx = Shape::Cuboid(Cuboid::new(Vec3::new(1.0, 0.5, 1.0)).unwrap());
    let cap = Shape::Capsule(Capsule::new(0.25, 0.6).unwrap());
    let rot = Quat::from_rotation_z(std::f64::consts::FRAC_PI_2 as Real);
    // Segment x ∈ [0.7, 1.9]: only [0.7, 1.0] lies over the top face.
    let pc = Isometry::new(Vec3::new(1.3, 0.5 + 0.25 - 0.02, 0.0), rot);
    for swap in [false, true] {
        let m = if swap {
            manifold(&bx, &Isometry::IDENTITY, &cap, &pc)
        } else {
            manifold(&cap, &pc, &bx, &Isometry::IDENTITY)
        };
        let pts = box_points(&m, swap);
        assert_eq!(pts.len(), 2, "{pts:?}");
        assert!((pts[0].0.x - 0.7).abs() < 1e-4 && (pts[1].0.x - 1.0).abs() < 1e-4);
        assert!(pts.iter().all(|p| (p.1 + 0.02).abs() < 1e-4), "{pts:?}");
    }
}

#[test]
fn capsule_standing_or_across_an_edge_gives_one_point() {
    let bx = Shape::Cuboid(Cuboid::new(Vec3::new(1.0, 0.5, 1.0)).unwrap());
    let cap = Shape::Capsule(Capsule::new(0.25, 0.6).unwrap());
    // Standing on the top face, touching exactly.
    let pc = Isometry::from_translation(Vec3::new(0.3, 0.5 + 0.6 + 0.25, -0.4));
    let m = manifold(&cap, &pc, &bx, &Isometry::IDENTITY);
    assert_eq!(m.len(), 1);
    assert!(m.points[0].distance.abs() < 1e-5);
    assert!((m.points[0].point_b - Vec3::new(0.3, 0.5, -0.4)).length() < 1e-4);
    // Lying along z across the box's top edge at x = 1, y = 0.5, 1 cm deep along the
    // diagonal: one point on the edge, normal along (1, 1, 0)/√2 (from the box's side).
    let rot = Quat::from_rotation_x(std::f64::consts::FRAC_PI_2 as Real);
    let s = (0.5 as Real).sqrt() * (0.25 - 0.01);
    let pc = Isometry::new(Vec3::new(1.0 + s, 0.5 + s, 0.0), rot);
    let m = manifold(&bx, &Isometry::IDENTITY, &cap, &pc);
    assert_eq!(m.len(), 1, "{:?}", m.points);
    let c = &m.points[0];
    assert!((c.distance + 0.01).abs() < 1e-4, "{c:?}");
    let n = Vec3::new(1.0, 1.0, 0.0).normalize();
    assert!((c.normal - n).length() < 1e-4 || (c.normal + n).length() < 1e-4);
    let on_box = c.point_a();
    assert!((on_box.x - 1.0).abs() < 1e-4 && (on_box.y - 0.5).abs() < 1e-4);
}

#[test]
fn capsule_inside_and_parallel_to_a_box_face_pushes_out_through_the_nearest_face() {
    let bx = Cuboid::new(Vec3::new(1.0, 0.5, 1.0)).unwrap();
    let cap = Capsule::new(0.1, 0.3).unwrap();
    let rot = Quat::from_rotation_z(std::f64::consts::FRAC_PI_2 as Real);
    // Core inside the box, 0.1 below the top face: depth 0.1 + r along −y from the capsule.
    let pc = Isometry::new(Vec3::new(0.2, 0.4, 0.0), rot);
    let c = query::contact(
        &Shape::Capsule(cap),
        &pc,
        &Shape::Cuboid(bx),
        &Isometry::IDENTITY,
        0.0,
    )
    .unwrap()
    .unwrap();
    assert!((c.distance + 0.2).abs() < 1e-5, "{c:?}");
    assert!(
        (c.normal - Vec3::new(0.0, -1.0, 0.0)).length() < 1e-5,
        "{c:?}"
    );
    assert!((c.point_b.y - 0.5).abs() < 1e-5, "{c:?}");
}
