//! Triangle against box: the full separating-axis test specialised to 13 axes (the
//! triangle's normal, the box's three face normals and the nine cross products of the box's
//! three edge directions with the triangle's three edges; Akenine-Möller, "Fast 3D
//! Triangle-Box Overlap Testing", 2001), then the same face clipping as the general
//! polyhedral path ([`super::polyhedron::polyhedron_manifold`]), whose result it reproduces
//! up to round-off: same reference-face choice, same feature ids.
//!
//! Why a special case: the general path treats the box's twelve edges one by one against
//! the triangle's three (36 pairs, each projecting all eleven vertices on two axes), where
//! only three edge directions exist; working in the box's frame, a box projects onto an axis
//! `u` as `[-r, r]` with `r = h·|u|`, so each axis costs a few multiplications. This is the
//! inner loop of box-against-mesh contacts (measured: the general SAT was 4x slower than
//! parry3d's per-triangle GJK there).

use super::contact::ContactList;
use super::polyhedron::{
    choose_feature, clip_faces, edge_contact, polyhedron_contact, Feature, Polyhedron, BOX_EDGES,
    EPA_FEATURE, PARALLEL_SIN,
};
use crate::math::{Isometry, Real, Vec3};
use crate::query::Contact;
use crate::shape::{Cuboid, Triangle};
use smallvec::SmallVec;

/// The triangle's edges as vertex pairs, in the order of the general polyhedron view.
const TRI_EDGES: [[usize; 2]; 3] = [[0, 1], [0, 2], [1, 2]];

/// The contact manifold of triangle A and box B (at `pose_ab` in A's frame), in A's frame with
/// the query convention (normal from A towards B), appended to `out`; nothing when they are
/// further apart than `prediction` or the triangle is degenerate. The triangle is two-sided.
pub fn triangle_cuboid_manifold_into(
    tri: &Triangle,
    cuboid: &Cuboid,
    pose_ab: &Isometry,
    prediction: Real,
    out: &mut ContactList,
) {
    let h = cuboid.half_extents();
    let pose_ba = pose_ab.inverse();
    let v = [
        pose_ba.transform_point(tri.a),
        pose_ba.transform_point(tri.b),
        pose_ba.transform_point(tri.c),
    ];
    let Some(n) = (v[1] - v[0]).cross(v[2] - v[0]).try_normalize() else {
        return;
    };
    let radius = |u: Vec3| h.x * u.x.abs() + h.y * u.y.abs() + h.z * u.z.abs();

    // The triangle's faces (0: front, 1: back): the box's gap in front of / behind it.
    let (r, d) = (radius(n), n.dot(v[0]));
    let (front, back) = (-r - d, -r + d);
    let (sa, fa) = if back > front { (back, 1) } else { (front, 0) };
    if sa > prediction {
        return;
    }

    // The box's faces (2k: +axis k, 2k+1: -axis k): the triangle's gap in front of each.
    let mut sb = Real::NEG_INFINITY;
    let mut fb = 0;
    for k in 0..3 {
        let (lo, hi) = (
            v[0][k].min(v[1][k]).min(v[2][k]),
            v[0][k].max(v[1][k]).max(v[2][k]),
        );
        for (i, s) in [(2 * k, lo - h[k]), (2 * k + 1, -hi - h[k])] {
            if s > sb {
                sb = s;
                fb = i;
            }
        }
    }
    if sb > prediction {
        return;
    }

    // Edge pairs: box edge direction k × triangle edge j, oriented from A to B. Only the
    // orientations along which the triangle's edge is the supporting feature count (the
    // flat polygon's Gauss-map condition; the box's support across an axis direction is
    // always an edge along it).
    let mut se = Real::NEG_INFINITY;
    let mut best_edge = (0, 0, Vec3::ZERO);
    for (j, &[p, q]) in TRI_EDGES.iter().enumerate() {
        let o = 3 - p - q; // the opposite vertex
        let dj = v[q] - v[p];
        for k in 0..3 {
            let mut ek = Vec3::ZERO;
            ek[k] = 1.0;
            let c = dj.cross(ek);
            let len = c.length();
            if len < PARALLEL_SIN * dj.length() || len == 0.0 {
                continue;
            }
            let c = c / len;
            let r = radius(c);
            let (pe, po) = (c.dot(v[p]), c.dot(v[o]));
            let eps = 1.0e-4 * dj.length();
            // The triangle's true extent along c: within `eps` the edge counts as its
            // supporting feature, but the gap must not use the edge alone (the opposite
            // vertex may stick out by up to `eps`, which reported a 0.2 mm overlap of a
            // nearly parallel pair as a gap, and lost the contact).
            let (hi, lo) = (pe.max(po), pe.min(po));
            // +c: the edge is the triangle's maximum along c; -c: its minimum.
            let (s, u) = if pe >= po - eps {
                let s1 = -r - hi;
                if pe <= po + eps {
                    // The whole triangle is flat along c (c is the normal): both sides.
                    let s2 = -r + lo;
                    if s2 > s1 {
                        (s2, -c)
                    } else {
                        (s1, c)
                    }
                } else {
                    (s1, c)
                }
            } else {
                (-r + lo, -c)
            };
            if s > prediction {
                return;
            }
            if s > se {
                se = s;
                best_edge = (j, k, u);
            }
        }
    }

    let feature = choose_feature(sa, sb, se);
    if feature == Feature::Edge {
        let (j, k, u) = best_edge;
        let [p, q] = TRI_EDGES[j];
        // The box's edge along k supporting it in -u: the corner signs opposite to u.
        let mut lo = 0usize;
        let mut corner = Vec3::ZERO;
        for m in 0..3 {
            if m != k {
                let plus = u[m] < 0.0;
                corner[m] = if plus { h[m] } else { -h[m] };
                lo |= (plus as usize) << m;
            }
        }
        let hi = lo | (1 << k);
        let (mut b0, mut b1) = (corner, corner);
        b0[k] = -h[k];
        b1[k] = h[k];
        let ib = BOX_EDGES
            .iter()
            .position(|e| e[0] as usize == lo && e[1] as usize == hi)
            .unwrap_or(0);
        let id = 0x8000_0000 | ((j as u32 & 0x7FFF) << 15) | (ib as u32 & 0x7FFF);
        if let Some(c) = edge_contact(v[p], v[q], b0, b1, u, se) {
            out.push((c.transformed(pose_ab), id));
            return;
        }
    }
    let start = out.len();
    let tri_poly = Polyhedron::from_triangle(tri);
    let box_poly = Polyhedron::from_cuboid(cuboid);
    if feature == Feature::FaceB || (feature == Feature::Edge && sb > sa) {
        let id_base = ((fb as u32 & 0x3F) | 0x40) << 24;
        let mut tmp: SmallVec<[(Contact, u32); 16]> = SmallVec::new();
        clip_faces(
            &box_poly, fb, &tri_poly, &pose_ba, prediction, id_base, &mut tmp,
        );
        out.extend(
            tmp.into_iter()
                .map(|(c, id)| (c.swapped().transformed(pose_ab), id)),
        );
    } else {
        let id_base = (fa as u32 & 0x3F) << 24;
        clip_faces(&tri_poly, fa, &box_poly, pose_ab, prediction, id_base, out);
    }
    if out.len() == start {
        out.extend(
            polyhedron_contact(&tri_poly, &box_poly, pose_ab, prediction).map(|c| (c, EPA_FEATURE)),
        );
    }
}
