//! The separating-axis queries of [`super::polyhedron`]: face queries, and the edge query
//! with Gauss-map pruning (D. Gregorius, "The Separating Axis Test between Convex
//! Polyhedra", GDC 2013), on a polyhedron placed once in the other's frame
//! ([`PosedPolyhedron`]).

use super::polyhedron::{Polyhedron, PARALLEL_SIN};
use crate::math::{Isometry, Real, Vec3};
use smallvec::SmallVec;

/// Scratch arrays of transformed vertices or normals: on the stack up to 64 entries.
pub(crate) type Buf = SmallVec<[Vec3; 64]>;

/// Polyhedron B placed in A's frame: its vertices, face normals and plane offsets, and (when
/// a flat polygon takes part) its edges' Gauss-map arcs ([`edge_arcs`]). Built once per
/// pair, or once per mesh pair and reused for every triangle.
#[derive(Debug, Clone)]
pub(crate) struct PosedPolyhedron {
    /// Vertices in A's frame.
    pub vertices: Buf,
    /// Face normals in A's frame.
    pub normals: Buf,
    /// Face plane offsets in A's frame.
    pub offsets: SmallVec<[Real; 64]>,
    /// Per edge, its Gauss-map arc (empty unless built `with_arcs`).
    pub arcs: Buf2,
}

impl PosedPolyhedron {
    /// `b` placed by `pose_ab`; `with_arcs` when the other shape or `b` is flat.
    pub fn new(b: &Polyhedron, pose_ab: &Isometry, with_arcs: bool) -> Self {
        let vertices: Buf = b
            .vertices()
            .iter()
            .map(|v| pose_ab.transform_point(*v))
            .collect();
        let normals: Buf = b
            .faces()
            .iter()
            .map(|f| pose_ab.transform_vector(f.normal))
            .collect();
        let offsets = b
            .faces()
            .iter()
            .zip(&normals)
            .map(|(f, n)| f.offset + n.dot(pose_ab.translation))
            .collect();
        let arcs = if with_arcs {
            edge_arcs(b, &vertices, &normals)
        } else {
            Buf2::new()
        };
        PosedPolyhedron {
            vertices,
            normals,
            offsets,
            arcs,
        }
    }
}

#[inline]
pub(crate) fn max_dot(points: &[Vec3], dir: Vec3) -> Real {
    points
        .iter()
        .map(|v| v.dot(dir))
        .fold(Real::NEG_INFINITY, Real::max)
}

/// Face query: the face (given by normals and offsets in A's frame) with the greatest
/// separation from the points `others` (the other shape's vertices in the same frame).
pub(crate) fn face_query(
    planes: impl Iterator<Item = (Vec3, Real)>,
    others: &[Vec3],
) -> (Real, usize) {
    let mut best = (Real::NEG_INFINITY, 0);
    for (i, (n, off)) in planes.enumerate() {
        let s = -max_dot(others, -n) - off;
        if s > best.0 {
            best = (s, i);
        }
    }
    best
}

/// Gregorius' Minkowski-face test: arcs AB and CD of the Gauss map intersect.
#[inline]
fn is_minkowski_face(a: Vec3, b: Vec3, c: Vec3, d: Vec3) -> bool {
    let bxa = b.cross(a);
    let dxc = d.cross(c);
    let cba = c.dot(bxa);
    let dba = d.dot(bxa);
    let adc = a.dot(dxc);
    let bdc = b.dot(dxc);
    cba * dba < 0.0 && adc * bdc < 0.0 && cba * bdc > 0.0
}

/// The Gauss-map arc of each edge of `p` (vertices `v`, face normals `n`, both in the frame
/// of the query), as two vectors `(g0, g1)` such that a direction `u` perpendicular to the
/// edge lies on the arc exactly when `u · g0 >= 0` and `u · g1 >= 0`. A solid's edge maps to
/// the arc between its faces' normals `n0`, `n1` (with `c = n0 × n1`: `g0 = c × n0`,
/// `g1 = n1 × c`); a flat polygon's edge to the half circle from its normal to the opposite
/// one through the edge's outward in-plane normal `o` (`g0 = g1 = o`).
fn edge_arcs(p: &Polyhedron, v: &[Vec3], n: &[Vec3]) -> Buf2 {
    let centre = v.iter().fold(Vec3::ZERO, |s, x| s + *x) / v.len().max(1) as Real;
    p.edges()
        .iter()
        .zip(p.edge_faces())
        .map(|(e, f)| {
            let (n0, n1) = (n[f[0] as usize], n[f[1] as usize]);
            if p.flat {
                let (a, b) = (v[e[0] as usize], v[e[1] as usize]);
                let o = (b - a).cross(n0);
                let o = if o.dot((a + b) * 0.5 - centre) < 0.0 {
                    -o
                } else {
                    o
                };
                (o, o)
            } else {
                let c = n0.cross(n1);
                (c.cross(n0), n1.cross(c))
            }
        })
        .collect()
}

/// Per-edge pairs of vectors (see [`edge_arcs`]), on the stack up to 64 edges.
type Buf2 = SmallVec<[(Vec3, Vec3); 64]>;

/// Edge query: the edge pair with the greatest separation among the pairs that build a
/// face of the Minkowski difference. `vb` and `nb` are B's vertices and face normals in A's
/// frame.
///
/// Between solids the Gauss-map test is Gregorius' on the face normals. With a flat polygon
/// (a triangle) an edge's arc is a half circle, which that test cannot take, so the pair's
/// axis `u = d_A × d_B` is tested directly against both arcs ([`edge_arcs`]): `u` (pointing
/// from A to B) must lie on A's arc and `-u` on B's, i.e. both edges are supporting features
/// along `u`. Either orientation may qualify; the larger separation wins.
pub(crate) fn edge_query(
    a: &Polyhedron,
    b: &Polyhedron,
    posed: &PosedPolyhedron,
) -> (Real, usize, usize, Vec3) {
    if a.flat || b.flat {
        return edge_query_flat(a, b, posed);
    }
    let nb = &posed.normals[..];
    let mut best = (Real::NEG_INFINITY, 0, 0, Vec3::ZERO);
    let va = a.vertices();
    let a_centre = va.iter().fold(Vec3::ZERO, |s, v| s + *v) / va.len().max(1) as Real;
    let b_faces = face_edge_masks(b);
    for (i, (ea, fa)) in a.edges().iter().zip(a.edge_faces()).enumerate() {
        let (pa, qa) = (va[ea[0] as usize], va[ea[1] as usize]);
        let (na0, na1) = (
            a.faces()[fa[0] as usize].normal,
            a.faces()[fa[1] as usize].normal,
        );
        let da = qa - pa;
        let edge_a = EdgeOf {
            index: i,
            p: pa,
            d: da,
            n0: na0,
            n1: na1,
        };
        // The first condition of Gregorius' test for every B edge at once: B's arc must
        // cross the plane of A's (normal `na1 × na0`), i.e. its two face normals lie strictly
        // on opposite sides. The same dot products as `is_minkowski_face`, so this only
        // skips pairs that test would reject.
        let d = na1.cross(na0);
        match &b_faces {
            Some(masks) => {
                let mut crossing = crossing_edges(nb, masks, d);
                // Lowest edge first, as the loop below visits them.
                while crossing != 0 {
                    edge_pair(
                        &edge_a,
                        crossing.trailing_zeros() as usize,
                        b,
                        posed,
                        va,
                        a_centre,
                        &mut best,
                    );
                    crossing &= crossing - 1;
                }
            }
            None => {
                for (j, fb) in b.edge_faces().iter().enumerate() {
                    if !one_side(None, *fb, nb, d) {
                        edge_pair(&edge_a, j, b, posed, va, a_centre, &mut best);
                    }
                }
            }
        }
    }
    best
}

/// An edge of A in the edge query: its index, first vertex, direction and faces' normals.
struct EdgeOf {
    index: usize,
    p: Vec3,
    d: Vec3,
    n0: Vec3,
    n1: Vec3,
}

/// The edge query's test of A's edge `ea` against B's edge `j`: when they build a face of
/// the Minkowski difference (Gregorius' test) and are not parallel, their separation along
/// the axis oriented away from A's centre is a candidate for `best`.
#[inline(always)]
fn edge_pair(
    ea: &EdgeOf,
    j: usize,
    b: &Polyhedron,
    posed: &PosedPolyhedron,
    va: &[Vec3],
    a_centre: Vec3,
    best: &mut (Real, usize, usize, Vec3),
) {
    let (vb, nb) = (&posed.vertices[..], &posed.normals[..]);
    let (eb, fb) = (b.edges()[j], b.edge_faces()[j]);
    let (nb0, nb1) = (nb[fb[0] as usize], nb[fb[1] as usize]);
    if !is_minkowski_face(ea.n0, ea.n1, -nb0, -nb1) {
        return;
    }
    let (pb, qb) = (vb[eb[0] as usize], vb[eb[1] as usize]);
    let Some(axis) = pair_axis(ea.d, qb - pb) else {
        return;
    };
    // Gregorius: orient the axis away from A's centre; the edges are the supporting
    // features of a Minkowski face, so the distance is along them.
    let ax = if axis.dot(ea.p - a_centre) < 0.0 {
        -axis
    } else {
        axis
    };
    consider(best, ax.dot(pb - ea.p), (ea.index, j, ax), va, vb);
}

/// For each face of `p`, the edges whose first face it is and those whose second face it is,
/// as bit masks over the edges; `None` when `p` has more than 64 faces or edges.
fn face_edge_masks(p: &Polyhedron) -> Option<SmallVec<[(u64, u64); 64]>> {
    let (faces, edges) = (p.faces().len(), p.edge_faces().len());
    if faces > 64 || edges > 64 {
        return None;
    }
    let mut masks: SmallVec<[(u64, u64); 64]> = SmallVec::from_elem((0, 0), faces);
    for (e, f) in p.edge_faces().iter().enumerate() {
        masks[f[0] as usize].0 |= 1 << e;
        masks[f[1] as usize].1 |= 1 << e;
    }
    Some(masks)
}

/// The edges (bits, from [`face_edge_masks`]) whose two faces have normals `normals`
/// strictly on opposite sides of `d`: one face's `n · d > 0` and the other's `< 0`. The
/// same edges as testing each edge's faces against [`side_masks`], found with one pass over
/// the faces instead of one over the edges for every edge of the other shape.
#[inline]
fn crossing_edges(normals: &[Vec3], masks: &[(u64, u64)], d: Vec3) -> u64 {
    let (mut pos0, mut pos1, mut neg0, mut neg1) = (0u64, 0u64, 0u64, 0u64);
    for (n, &(m0, m1)) in normals.iter().zip(masks) {
        let x = n.dot(d);
        let pos = 0u64.wrapping_sub(u64::from(x > 0.0));
        let neg = 0u64.wrapping_sub(u64::from(x < 0.0));
        pos0 |= m0 & pos;
        pos1 |= m1 & pos;
        neg0 |= m0 & neg;
        neg1 |= m1 & neg;
    }
    (pos0 & neg1) | (neg0 & pos1)
}

/// The unit axis `da × db` of an edge pair, `None` for (nearly) parallel edges: they form
/// no face of the Minkowski difference and the face axes decide.
#[inline]
fn pair_axis(da: Vec3, db: Vec3) -> Option<Vec3> {
    let axis = da.cross(db);
    let len = axis.length();
    (len >= PARALLEL_SIN * da.length() * db.length() && len != 0.0).then(|| axis / len)
}

/// Takes the candidate `(i, j, ax)` with edge-formula separation `s` when it beats `best`.
/// The edge distance holds only for a true Minkowski face; near the Gauss-map test's
/// round-off it can overstate the separation (the polytope oracle caught depths 15 % short),
/// so a new best is checked by projecting both shapes, which is exact for any axis.
#[inline]
fn consider(
    best: &mut (Real, usize, usize, Vec3),
    s: Real,
    (i, j, ax): (usize, usize, Vec3),
    va: &[Vec3],
    vb: &[Vec3],
) {
    if s > best.0 {
        let exact = -max_dot(vb, -ax) - max_dot(va, ax);
        if exact > best.0 {
            *best = (exact, i, j, ax);
        }
    }
}

/// Bits of the `normals` (at most 64, else `None`) that lie strictly on the positive side
/// of `d`, and those strictly on its negative side.
fn side_masks(normals: &[Vec3], d: Vec3) -> Option<(u64, u64)> {
    if normals.len() > 64 {
        return None;
    }
    let (mut pos, mut neg) = (0u64, 0u64);
    for (k, n) in normals.iter().enumerate() {
        let x = n.dot(d);
        pos |= u64::from(x > 0.0) << k;
        neg |= u64::from(x < 0.0) << k;
    }
    Some((pos, neg))
}

/// True when the Gauss-map arc between faces `f` (normals `normals`) lies strictly on one
/// side of the great circle perpendicular to `d` (so it cannot cross it); `masks` are
/// [`side_masks`] of `normals` along `d` when available.
#[inline]
fn one_side(masks: Option<(u64, u64)>, f: [u32; 2], normals: &[Vec3], d: Vec3) -> bool {
    match masks {
        Some((pos, neg)) => {
            let bits = (1u64 << f[0]) | (1u64 << f[1]);
            pos & bits == bits || neg & bits == bits
        }
        None => normals[f[0] as usize].dot(d) * normals[f[1] as usize].dot(d) > 0.0,
    }
}

/// [`edge_query`] when A or B is a flat polygon: the pair's axis `u = d_A × d_B` is tested
/// against both edges' arcs ([`edge_arcs`]). A solid's arc must first cross the great circle
/// perpendicular to the other edge (which holds the pair's axis): the signs of its two face
/// normals along that edge, taken from per-edge bit masks, reject most pairs before any
/// axis is formed.
fn edge_query_flat(
    a: &Polyhedron,
    b: &Polyhedron,
    posed: &PosedPolyhedron,
) -> (Real, usize, usize, Vec3) {
    let (vb, nb) = (&posed.vertices[..], &posed.normals[..]);
    let mut best = (Real::NEG_INFINITY, 0, 0, Vec3::ZERO);
    let va = a.vertices();
    let na: Buf = a.faces().iter().map(|f| f.normal).collect();
    let arcs_a = edge_arcs(a, va, &na);
    let arcs_b = &posed.arcs;
    debug_assert!(arcs_b.len() == b.edges().len());
    let dir = |v: &[Vec3], e: [u32; 2]| v[e[1] as usize] - v[e[0] as usize];
    // For a solid A: per edge of B, the sides of A's face normals along it.
    let masks_a: SmallVec<[Option<(u64, u64)>; 64]> = if a.flat {
        SmallVec::new()
    } else {
        b.edges()
            .iter()
            .map(|e| side_masks(&na, dir(vb, *e)))
            .collect()
    };
    for (i, (ea, fa)) in a.edges().iter().zip(a.edge_faces()).enumerate() {
        let pa = va[ea[0] as usize];
        let da = dir(va, *ea);
        let mask_b = if b.flat { None } else { side_masks(nb, da) };
        for (j, (eb, fb)) in b.edges().iter().zip(b.edge_faces()).enumerate() {
            if (!b.flat && one_side(mask_b, *fb, nb, da))
                || (!a.flat && one_side(masks_a[j], *fa, &na, dir(vb, *eb)))
            {
                continue;
            }
            let pb = vb[eb[0] as usize];
            let Some(axis) = pair_axis(da, dir(vb, *eb)) else {
                continue;
            };
            let ((a0, a1), (b0, b1)) = (arcs_a[i], arcs_b[j]);
            let (ua0, ua1, ub0, ub1) = (axis.dot(a0), axis.dot(a1), axis.dot(b0), axis.dot(b1));
            let sep = pb.dot(axis) - pa.dot(axis);
            // `axis` on A's arc and `-axis` on B's; or the reverse orientation.
            let fwd = (ua0 >= 0.0 && ua1 >= 0.0 && ub0 <= 0.0 && ub1 <= 0.0).then_some(sep);
            let bwd = (ua0 <= 0.0 && ua1 <= 0.0 && ub0 >= 0.0 && ub1 >= 0.0).then_some(-sep);
            let (s, ax) = match (fwd, bwd) {
                (Some(s1), Some(s2)) if s2 > s1 => (s2, -axis),
                (Some(s1), _) => (s1, axis),
                (None, Some(s2)) => (s2, -axis),
                (None, None) => continue,
            };
            consider(&mut best, s, (i, j, ax), va, vb);
        }
    }
    best
}

#[cfg(test)]
#[path = "polyhedron_sat_tests.rs"]
mod tests;
