//! Capsule against box in closed form: the capsule's core segment against the box, then the
//! radius added back (the talk's "point + radius", here "segment + radius").
//!
//! Separated cores: the exact closest points of the segment and the box. The squared
//! distance from the point `p + t·d` to the box is a convex, piecewise quadratic function of
//! `t`, whose pieces change where a coordinate crosses a face plane (at most six
//! breakpoints); each piece is minimised in closed form and the least value kept.
//! Overlapping (or touching) cores: the separating-axis test of a segment and a box, whose
//! candidate axes are the box's three face normals and the three cross products of the
//! segment with the box's edges (the face normals of their Minkowski difference), so the
//! least overlap is the exact penetration depth. Faces are preferred over edges within a
//! small tolerance. This is the analytic counterpart of parry's
//! `contact_manifold_cuboid_capsule` (which runs the same SAT axes through its
//! `sat::cuboid_segment_*` helpers) and of Bullet's capsule special cases.

use super::closest_points::closest_points_segment_segment;
use super::result::Contact;
use crate::math::{Isometry, Real, Vec3, EPSILON};
use crate::shape::{Capsule, Cuboid};

/// Below this many `EPSILON`s (relative to the size of the pair) the cores count as
/// touching, and the separating-axis test gives the normal instead of the closest points,
/// whose difference would be mostly round-off.
const TOUCH_EPS: Real = 1.0e3;

/// Absolute preference (relative to the size of the pair) of a face axis over an edge axis.
const FACE_BIAS: Real = 1.0e-5;

/// Parameter `t ∈ [0, 1]` of the point of the segment `p + t·d` closest to the box of half
/// extents `h` centred at the origin, and its squared distance (zero when it touches).
pub fn segment_box_closest(p: Vec3, d: Vec3, h: Vec3) -> (Real, Real) {
    let sq_dist = |t: Real| {
        let x = p + d * t;
        (x - x.clamp(-h, h)).length_squared()
    };
    let mut breaks: [Real; 8] = [0.0; 8];
    let mut n = 1;
    for i in 0..3 {
        if d[i] != 0.0 {
            for s in [-h[i], h[i]] {
                let t = (s - p[i]) / d[i];
                if t > 0.0 && t < 1.0 {
                    breaks[n] = t;
                    n += 1;
                }
            }
        }
    }
    breaks[n] = 1.0;
    n += 1;
    // At most 8 values: an insertion sort, deterministic and allocation-free.
    for i in 1..n {
        let mut j = i;
        while j > 0 && breaks[j - 1] > breaks[j] {
            breaks.swap(j - 1, j);
            j -= 1;
        }
    }
    let (mut best_t, mut best) = (0.0, sq_dist(0.0));
    for w in breaks[..n].windows(2) {
        let (a, b) = (w[0], w[1]);
        let mid = 0.5 * (a + b);
        // On (a, b) each coordinate stays on one side of its slab: f = A t² + 2 B t + C.
        let (mut qa, mut qb) = (0.0, 0.0);
        for i in 0..3 {
            let y = p[i] + mid * d[i];
            let off = if y > h[i] {
                p[i] - h[i]
            } else if y < -h[i] {
                p[i] + h[i]
            } else {
                continue;
            };
            qa += d[i] * d[i];
            qb += d[i] * off;
        }
        let t = if qa > 0.0 { (-qb / qa).clamp(a, b) } else { a };
        let v = sq_dist(t);
        if v < best {
            best = v;
            best_t = t;
        }
    }
    (best_t, best)
}

/// Contact of a capsule whose core segment runs from `p` to `q` (radius `r`) against the box
/// of half extents `h` centred at the origin, all in the box's frame, with the normal from
/// the capsule towards the box. Exact; not filtered by any prediction distance.
pub fn capsule_cuboid_local(p: Vec3, q: Vec3, r: Real, h: Vec3) -> Contact {
    let d = q - p;
    // The size of the pair, without an absolute floor: `1 + …` made every capsule of a few
    // tenths of a millimetre "touch" any box within 0.1 mm, and the separating-axis answer
    // then stood for the distance (23 % short for a 0.1 mm capsule 0.09 mm from a box).
    let scale = h.max_element() + d.length();
    let (t, sq) = segment_box_closest(p, d, h);
    let tol = TOUCH_EPS * EPSILON * scale;
    if sq > tol * tol {
        let x = p + d * t;
        let c = x.clamp(-h, h);
        let dist = sq.sqrt();
        let n = (c - x) / dist;
        return Contact {
            distance: dist - r,
            point_a: x + n * r,
            point_b: c,
            normal: n,
        };
    }
    sat_segment_box(p, q, r, h, scale)
}

/// The separating-axis test of the segment `p q` and the box: the least overlap over the
/// box's face normals and the segment × edge axes (see the module docs).
fn sat_segment_box(p: Vec3, q: Vec3, r: Real, h: Vec3, scale: Real) -> Contact {
    let d = q - p;
    // Face axes: the normal +e_k (segment on the −k side) or −e_k.
    let (mut face_k, mut face_sign, mut face_ov) = (0, 1.0, Real::INFINITY);
    for k in 0..3 {
        let (lo, hi) = (p[k].min(q[k]), p[k].max(q[k]));
        let (plus, minus) = (hi + h[k], h[k] - lo);
        let (ov, sign) = if plus <= minus {
            (plus, 1.0)
        } else {
            (minus, -1.0)
        };
        if ov < face_ov {
            (face_k, face_sign, face_ov) = (k, sign, ov);
        }
    }
    // Edge axes d × e_k; the segment projects to a single value on each.
    let dl = d.length();
    let mut edge: Option<(usize, Vec3, Real)> = None;
    for k in 0..3 {
        let mut e = Vec3::ZERO;
        e[k] = 1.0;
        let axis = d.cross(e);
        let len = axis.length();
        if len <= 1.0e-6 * dl || len == 0.0 {
            continue;
        }
        let axis = axis / len;
        let s = axis.dot(p);
        let rb = (axis * h).abs().dot(Vec3::ONE);
        let (plus, minus) = (s + rb, rb - s);
        let (ov, n) = if plus <= minus {
            (plus, axis)
        } else {
            (minus, -axis)
        };
        if edge.is_none_or(|(_, _, best)| ov < best) {
            edge = Some((k, n, ov));
        }
    }
    if let Some((k, n, ov)) = edge {
        if ov + FACE_BIAS * scale < face_ov {
            // The box edge along e_k on the capsule's side (towards −n).
            let mut v = Vec3::ZERO;
            for i in 0..3 {
                if i != k {
                    v[i] = if n[i] > 0.0 { -h[i] } else { h[i] };
                }
            }
            let (mut v0, mut v1) = (v, v);
            v0[k] = -h[k];
            v1[k] = h[k];
            let (_, xb) = closest_points_segment_segment(p, q, v0, v1);
            let distance = -ov - r;
            return Contact {
                distance,
                point_a: xb - n * distance,
                point_b: xb,
                normal: n,
            };
        }
    }
    let mut n = Vec3::ZERO;
    n[face_k] = face_sign;
    // The deepest point along n of the part of the segment within the other two slabs
    // (the whole segment if that part is empty, as when the cores only nearly touch).
    let (t0, t1) = clip_to_slabs(p, d, h, face_k).unwrap_or((0.0, 1.0));
    let (x0, x1) = (p + d * t0, p + d * t1);
    let x = if n.dot(x1) > n.dot(x0) { x1 } else { x0 };
    let depth_to_face = n.dot(x) + h[face_k];
    Contact {
        distance: -face_ov - r,
        point_a: x + n * r,
        point_b: x - n * depth_to_face,
        normal: n,
    }
}

/// The parameter range of the segment `p + t·d`, `t ∈ [0, 1]`, within the box's slabs of
/// the two axes other than `k` (the side planes of the faces normal to `e_k`); `None` when
/// empty.
pub fn clip_to_slabs(p: Vec3, d: Vec3, h: Vec3, k: usize) -> Option<(Real, Real)> {
    let (mut t0, mut t1): (Real, Real) = (0.0, 1.0);
    for i in 0..3 {
        if i == k {
            continue;
        }
        if d[i] == 0.0 {
            if p[i].abs() > h[i] {
                return None;
            }
            continue;
        }
        let (a, b) = ((-h[i] - p[i]) / d[i], (h[i] - p[i]) / d[i]);
        t0 = t0.max(a.min(b));
        t1 = t1.min(a.max(b));
    }
    (t0 <= t1).then_some((t0, t1))
}

/// Capsule A against box B (placed by `pose_ab`), in A's frame; `None` when further apart
/// than `prediction`.
pub fn contact_capsule_cuboid(
    a: &Capsule,
    b: &Cuboid,
    pose_ab: &Isometry,
    prediction: Real,
) -> Option<Contact> {
    let (p, q) = a.segment();
    let (p, q) = (
        pose_ab.inverse_transform_point(p),
        pose_ab.inverse_transform_point(q),
    );
    let c = capsule_cuboid_local(p, q, a.radius(), b.half_extents());
    (c.distance <= prediction).then(|| c.transformed(pose_ab))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segment_through_a_box_face_on_and_edge_on() {
        let h = Vec3::new(1.0, 0.5, 1.0);
        // Lying 0.1 below the top face: the face axis, depth 0.1 + r.
        let c = capsule_cuboid_local(Vec3::new(-2.0, 0.4, 0.0), Vec3::new(2.0, 0.4, 0.0), 0.2, h);
        assert!((c.distance + 0.3).abs() < 1e-5, "{c:?}");
        assert!((c.normal - Vec3::new(0.0, -1.0, 0.0)).length() < 1e-6);
        // Above the top face: closest points, along the face normal.
        let c = capsule_cuboid_local(Vec3::new(-0.5, 0.7, 0.3), Vec3::new(0.5, 0.9, 0.3), 0.2, h);
        assert!((c.distance - 0.0).abs() < 1e-5, "{c:?}");
        assert!((c.point_b - Vec3::new(-0.5, 0.5, 0.3)).length() < 1e-5);
    }
}
