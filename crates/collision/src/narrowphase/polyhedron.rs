//! Polyhedral contact manifolds in one shot: the separating-axis test over face normals and
//! edge pairs with Gauss-map pruning of edge pairs (D. Gregorius, "The Separating Axis Test
//! between Convex Polyhedra", GDC 2013), then face clipping (Sutherland–Hodgman) of the
//! incident face against the reference face's side planes, keeping points with penetration
//! or within the speculative margin (Coumans, "Contact Generation", "Contact clipping").
//! Serves boxes, convex hulls and triangles alike.

use super::contact::FeatureId;
pub use super::polyhedron_guided::{
    polyhedron_contact, polyhedron_manifold_guided, EPA_FEATURE, SAT_MAX_EDGE_PAIRS,
};
pub(crate) use super::polyhedron_sat::PosedPolyhedron;
use super::polyhedron_sat::{edge_query, face_query};
use crate::math::{Isometry, Real, Vec3};
use crate::query::closest_points::closest_points_segment_segment;
use crate::query::Contact;
use crate::shape::convex_hull::edge_face_pairs;
use crate::shape::{ConvexHull, Cuboid, HullFace, Triangle};
use smallvec::SmallVec;
use std::sync::OnceLock;

/// Borrowed (hulls) or inline (boxes, triangles) storage, so that building a view never
/// allocates.
#[derive(Debug, Clone, Copy)]
enum Store<'a, T: Copy, const N: usize> {
    Borrowed(&'a [T]),
    Inline([T; N], usize),
}

impl<T: Copy, const N: usize> std::ops::Deref for Store<'_, T, N> {
    type Target = [T];
    #[inline]
    fn deref(&self) -> &[T] {
        match self {
            Store::Borrowed(s) => s,
            Store::Inline(a, n) => &a[..*n],
        }
    }
}

/// A convex polyhedron view: vertices, faces (plane + counter-clockwise vertex loop) and
/// edges with their two adjacent faces (for the Gauss map).
///
/// The view never allocates: a hull lends its precomputed faces and edge adjacency
/// ([`ConvexHull::edge_faces`]); a box or a triangle keeps its few vertices and planes inline
/// and shares a static topology.
#[derive(Debug, Clone, Copy)]
pub struct Polyhedron<'a> {
    vertices: Store<'a, Vec3, 8>,
    faces: Store<'a, HullFace, 6>,
    loops: &'a [u32],
    edges: &'a [[u32; 2]],
    edge_faces: &'a [[u32; 2]],
    /// True for a flat polygon (a triangle): its edges' Gauss-map arcs are half circles
    /// through their outward in-plane normals (see `polyhedron_sat`), pruned as such; only
    /// a view of a real flat polygon may set it.
    pub flat: bool,
}

/// Corner `i` of a box has coordinate signs from bits 0 (x), 1 (y), 2 (z).
pub(crate) const BOX_LOOPS: [u32; 24] = [
    1, 3, 7, 5, 0, 4, 6, 2, 2, 6, 7, 3, 0, 1, 5, 4, 4, 5, 7, 6, 0, 2, 3, 1,
];
/// The box's edges as corner pairs (the lower corner has the edge's axis bit clear).
pub(crate) const BOX_EDGES: [[u32; 2]; 12] = [
    [0, 1],
    [0, 2],
    [0, 4],
    [1, 3],
    [1, 5],
    [2, 3],
    [2, 6],
    [3, 7],
    [4, 5],
    [4, 6],
    [5, 7],
    [6, 7],
];
const TRI_LOOPS: [u32; 6] = [0, 1, 2, 0, 2, 1];
const TRI_EDGES: [[u32; 2]; 3] = [[0, 1], [0, 2], [1, 2]];
const TRI_EDGE_FACES: [[u32; 2]; 3] = [[0, 1], [1, 0], [0, 1]];

/// The box's edge adjacency, derived once from its face loops.
fn box_edge_faces() -> &'static [[u32; 2]] {
    static CELL: OnceLock<Vec<[u32; 2]>> = OnceLock::new();
    CELL.get_or_init(|| {
        let directed = (0..6)
            .flat_map(|f| {
                let lp = &BOX_LOOPS[4 * f..4 * f + 4];
                (0..4).map(move |k| ([lp[k], lp[(k + 1) % 4]], f as u32))
            })
            .collect();
        edge_face_pairs(&BOX_EDGES, directed)
    })
}

impl<'a> Polyhedron<'a> {
    /// The vertices.
    #[inline]
    pub fn vertices(&self) -> &[Vec3] {
        &self.vertices
    }

    /// The faces (unit outward normal, plane offset, range of the loop).
    #[inline]
    pub fn faces(&self) -> &[HullFace] {
        &self.faces
    }

    /// The edges (vertex pairs).
    #[inline]
    pub fn edges(&self) -> &[[u32; 2]] {
        self.edges
    }

    /// For each edge, its two adjacent faces.
    #[inline]
    pub fn edge_faces(&self) -> &[[u32; 2]] {
        self.edge_faces
    }

    /// The loop of face `f`.
    #[inline]
    pub fn face_loop(&self, f: usize) -> &[u32] {
        let h = &self.faces[f];
        &self.loops[h.first as usize..(h.first + h.count) as usize]
    }

    /// The box as a polyhedron (its exact half extents, margin ignored).
    pub fn from_cuboid(b: &Cuboid) -> Polyhedron<'static> {
        let h = b.half_extents();
        let corner = |i: usize| {
            Vec3::new(
                if i & 1 != 0 { h.x } else { -h.x },
                if i & 2 != 0 { h.y } else { -h.y },
                if i & 4 != 0 { h.z } else { -h.z },
            )
        };
        let face = |i: usize| {
            let mut normal = Vec3::ZERO;
            normal[i / 2] = if i.is_multiple_of(2) { 1.0 } else { -1.0 };
            HullFace {
                normal,
                offset: h[i / 2],
                first: 4 * i as u32,
                count: 4,
            }
        };
        Polyhedron {
            vertices: Store::Inline(std::array::from_fn(corner), 8),
            faces: Store::Inline(std::array::from_fn(face), 6),
            loops: &BOX_LOOPS,
            edges: &BOX_EDGES,
            edge_faces: box_edge_faces(),
            flat: false,
        }
    }

    /// The hull as a polyhedron (borrows the hull's faces and edge adjacency).
    pub fn from_hull(h: &'a ConvexHull) -> Polyhedron<'a> {
        Polyhedron {
            vertices: Store::Borrowed(h.vertices()),
            faces: Store::Borrowed(h.faces()),
            loops: h.face_vertex_indices(),
            edges: h.edges(),
            edge_faces: h.edge_faces(),
            flat: false,
        }
    }

    /// The triangle as a flat polyhedron with a front and a back face.
    pub fn from_triangle(t: &Triangle) -> Polyhedron<'static> {
        let n = t.scaled_normal().normalize_or_zero();
        let off = n.dot(t.a);
        let mut v = [Vec3::ZERO; 8];
        v[..3].copy_from_slice(&t.vertices());
        let mut f = [HullFace {
            normal: n,
            offset: off,
            first: 0,
            count: 3,
        }; 6];
        f[1] = HullFace {
            normal: -n,
            offset: -off,
            first: 3,
            count: 3,
        };
        Polyhedron {
            vertices: Store::Inline(v, 3),
            faces: Store::Inline(f, 2),
            loops: &TRI_LOOPS,
            edges: &TRI_EDGES,
            edge_faces: &TRI_EDGE_FACES,
            flat: true,
        }
    }
}

/// Relative preference for faces in the separating-axis test: an edge pair (or the other
/// shape's face) becomes the contact feature only when its separation beats the best face's
/// by more than `FACE_PREFERENCE · (1 + |separation|)`, so that resting contacts keep the
/// same reference face from step to step. The reported depth may exceed the exact minimum
/// penetration by that much.
pub const FACE_PREFERENCE: Real = 1.0e-3;

/// Edge pairs whose directions make an angle with sine below this are skipped by the
/// separating-axis test (parallel edges form no face of the Minkowski difference). Kept
/// small: nearly parallel pairs still bound the depth (Gregorius' 0.005 overstated it by
/// 1.4 mm at 2 cm in the polytope oracle); their witnesses are checked by `edge_contact`.
pub const PARALLEL_SIN: Real = 1.0e-5;

/// Relative tolerance (of the reference face's longest edge) within which a vertex counts as
/// over the reference face: its projection becomes the contact point on the reference shape,
/// so it may lie off that shape by this much. At `1e-4` the polytope oracle caught points
/// 0.2-0.3 mm off a triangle of 3 m edges; `1e-5` keeps vertices exactly on a side plane
/// (coplanar, touching) above f32 round-off.
const PRISM_TOL: Real = 1.0e-5;

/// A polygon being clipped: points with feature ids, on the stack up to 16 corners.
type Poly = SmallVec<[(Vec3, u32); 16]>;

/// Clips the polygon `poly` (points with feature ids) against the half-space
/// `n · x <= d` (`n` need not be unit: the clip is scale-invariant); new points get id
/// `(start id & 0xFFFF_FF00) | tag`. Each corner's signed distance is computed once (not
/// once per adjacent edge) and the wrap-around takes no division.
///
/// Returns false, leaving `out` untouched, when every corner lies strictly inside
/// (`n · x - d < 0`): the clip would copy `poly` unchanged (no corner is dropped and no
/// edge crosses the plane), so the caller keeps `poly` instead. A corner exactly on the
/// plane takes the full loop, which may add a point there. An incident face well inside
/// the reference face skips most of its side planes this way (Sutherland–Hodgman's trivial
/// accept).
fn clip(poly: &[(Vec3, u32)], n: Vec3, d: Real, tag: u32, out: &mut Poly) -> bool {
    if poly.iter().all(|&(p, _)| n.dot(p) - d < 0.0) {
        return false;
    }
    out.clear();
    let Some(&(first, _)) = poly.first() else {
        return true;
    };
    let first_d = n.dot(first) - d;
    let mut dp = first_d;
    for k in 0..poly.len() {
        let (p, ip) = poly[k];
        let (q, dq) = match poly.get(k + 1) {
            Some(&(q, _)) => (q, n.dot(q) - d),
            None => (first, first_d),
        };
        if dp <= 0.0 {
            out.push((p, ip));
        }
        if (dp < 0.0) != (dq < 0.0) && dp != dq {
            let t = dp / (dp - dq);
            out.push((p + (q - p) * t, (ip & 0xFFFF_FF00) | (tag & 0xFF)));
        }
        dp = dq;
    }
    true
}

/// Clips the incident face of `inc` (at `pose_ri` in the reference frame) against the side
/// planes of face `rf` of `refp`; appends contacts in the reference frame (normal from the
/// reference towards the incident shape) to `out`.
pub(crate) fn clip_faces(
    refp: &Polyhedron,
    rf: usize,
    inc: &Polyhedron,
    pose_ri: &Isometry,
    prediction: Real,
    id_base: u32,
    out: &mut impl Extend<(Contact, FeatureId)>,
) {
    let HullFace {
        normal: nr,
        offset: off,
        ..
    } = refp.faces[rf];
    let n_in_inc = pose_ri.inverse_transform_vector(nr);
    let mut inc_face = 0;
    let mut best = Real::INFINITY;
    for (i, f) in inc.faces.iter().enumerate() {
        let d = f.normal.dot(n_in_inc);
        if d < best {
            best = d;
            inc_face = i;
        }
    }
    let id = id_base | ((inc_face as u32 & 0xFF) << 16);
    let iv = inc.vertices();
    // The incident face's corners placed by the pose's matrix (cheaper than a quaternion
    // rotation per corner).
    let (m, t) = (pose_ri.rotation_matrix(), pose_ri.translation);
    // Two buffers used in turn (swapping them moved both inline arrays at every clip).
    let mut bufs: [Poly; 2] = [
        inc.face_loop(inc_face)
            .iter()
            .enumerate()
            .map(|(k, &v)| (m * iv[v as usize] + t, id | ((k as u32 & 0xFF) << 8) | 0xFF))
            .collect(),
        Poly::new(),
    ];
    let mut cur = 0;
    let lp = refp.face_loop(rf);
    let rv = refp.vertices();
    let first = lp.first().map_or(0, |&v| v as usize);
    let mut a = rv.get(first).copied().unwrap_or(Vec3::ZERO);
    for k in 0..lp.len() {
        let b = rv[lp.get(k + 1).map_or(first, |&v| v as usize)];
        // Side plane through the edge, not normalised (the clip is scale-invariant).
        let side = (b - a).cross(nr);
        let [b0, b1] = &mut bufs;
        let (from, to) = if cur == 0 { (b0, b1) } else { (b1, b0) };
        let clipped = clip(from, side, side.dot(a), k as u32, to);
        a = b;
        if !clipped {
            continue;
        }
        cur = 1 - cur;
        if bufs[cur].is_empty() {
            break;
        }
    }
    let [b0, b1] = bufs;
    let mut poly = if cur == 0 { b0 } else { b1 };
    if poly.is_empty() {
        // Deep or lateral configurations where the incident face misses the reference
        // face's prism: fall back to the deepest vertex of the incident shape among those
        // inside the prism (a vertex touching the prism's side is on the contact region),
        // else nothing: the caller falls back to GJK/EPA (a vertex beside the prism would
        // give a point off the reference shape).
        let size = (0..lp.len())
            .map(|k| (rv[lp[(k + 1) % lp.len()] as usize] - rv[lp[k] as usize]).length())
            .fold(0.0, Real::max);
        let in_prism = |p: Vec3| {
            (0..lp.len()).all(|k| {
                let a = rv[lp[k] as usize];
                let b = rv[lp[(k + 1) % lp.len()] as usize];
                let side = (b - a).cross(nr).normalize_or_zero();
                side.dot(p - a) <= PRISM_TOL * size
            })
        };
        let depth = |i: usize| iv[i].dot(n_in_inc);
        let deepest = |filter: &dyn Fn(usize) -> bool| {
            (0..iv.len())
                .filter(|&i| filter(i))
                .min_by(|&i, &j| depth(i).total_cmp(&depth(j)))
        };
        let k = deepest(&|i| in_prism(pose_ri.transform_point(iv[i])));
        if let Some(v) = k.and_then(|k| iv.get(k)) {
            poly.push((pose_ri.transform_point(*v), id | 0xFEFF));
        }
    }
    out.extend(poly.into_iter().filter_map(|(p, fid)| {
        let s = nr.dot(p) - off;
        (s <= prediction).then(|| {
            (
                Contact {
                    distance: s,
                    point_a: p - nr * s,
                    point_b: p,
                    normal: nr,
                },
                fid,
            )
        })
    }));
}

/// The full contact manifold of two polyhedra (B at `pose_ab` in A's frame), in A's frame
/// with the query convention (normal from A towards B), or empty when they are further
/// apart than `prediction`. Allocates only the returned vector (see
/// [`polyhedron_manifold_into`]).
pub fn polyhedron_manifold(
    a: &Polyhedron,
    b: &Polyhedron,
    pose_ab: &Isometry,
    prediction: Real,
) -> Vec<(Contact, FeatureId)> {
    let mut out = Vec::new();
    polyhedron_manifold_into(a, b, pose_ab, prediction, &mut out);
    out
}

/// [`polyhedron_manifold`] appending to `out`: no heap allocation for shapes with at most
/// 64 vertices and faces and faces of at most 16 corners (after clipping).
pub fn polyhedron_manifold_into(
    a: &Polyhedron,
    b: &Polyhedron,
    pose_ab: &Isometry,
    prediction: Real,
    out: &mut Vec<(Contact, FeatureId)>,
) {
    let posed = PosedPolyhedron::new(b, pose_ab, a.flat || b.flat);
    polyhedron_manifold_posed(a, b, &posed, pose_ab, prediction, out);
}

/// [`polyhedron_manifold_into`] with B already placed in A's frame (`posed`, built from `b`
/// and `pose_ab` with edge arcs when either shape is flat): a convex against many triangles
/// of a mesh places it once and runs this per triangle.
pub(crate) fn polyhedron_manifold_posed(
    a: &Polyhedron,
    b: &Polyhedron,
    posed: &PosedPolyhedron,
    pose_ab: &Isometry,
    prediction: Real,
    out: &mut Vec<(Contact, FeatureId)>,
) {
    let (vb, nb, ob) = (&posed.vertices[..], &posed.normals[..], &posed.offsets[..]);
    let (sa, fa) = face_query(a.faces.iter().map(|f| (f.normal, f.offset)), vb);
    if sa > prediction {
        return;
    }
    let (sb, fb) = face_query(nb.iter().copied().zip(ob.iter().copied()), a.vertices());
    if sb > prediction {
        return;
    }
    let edge = edge_query(a, b, posed);
    if edge.0 > prediction {
        return;
    }
    manifold_from_sat(
        a,
        b,
        posed,
        pose_ab,
        prediction,
        (sa, fa),
        (sb, fb),
        edge,
        out,
    );
}

/// The manifold of [`polyhedron_manifold_posed`] once the separating-axis test has run and
/// found no separating axis beyond `prediction`: the best face of A `(sa, fa)`, of B
/// `(sb, fb)` and the best edge pair `(se, ia, ib, axis)` (axis from A towards B). Shared
/// with the triangle-specialised test of [`super::mesh_hull`].
#[allow(clippy::too_many_arguments)]
pub(crate) fn manifold_from_sat(
    a: &Polyhedron,
    b: &Polyhedron,
    posed: &PosedPolyhedron,
    pose_ab: &Isometry,
    prediction: Real,
    (sa, fa): (Real, usize),
    (sb, fb): (Real, usize),
    (se, ia, ib, axis): (Real, usize, usize, Vec3),
    out: &mut Vec<(Contact, FeatureId)>,
) {
    let vb = &posed.vertices[..];
    let start = out.len();
    let feature = choose_feature(sa, sb, se);
    if feature == Feature::Edge {
        let ea = a.edges[ia];
        let eb = b.edges[ib];
        let va = a.vertices();
        let (pa, qa) = (va[ea[0] as usize], va[ea[1] as usize]);
        let (pb, qb) = (vb[eb[0] as usize], vb[eb[1] as usize]);
        let id = 0x8000_0000 | ((ia as u32 & 0x7FFF) << 15) | (ib as u32 & 0x7FFF);
        if let Some(c) = edge_contact(pa, qa, pb, qb, axis, se) {
            out.push((c, id));
            return;
        }
    }
    // A's face unless B's is the choice (or the better face after a rejected edge pair).
    let ref_b = feature == Feature::FaceB || (feature == Feature::Edge && sb > sa);
    if ref_b {
        let id_base = ((fb as u32 & 0x3F) | 0x40) << 24;
        let mut tmp: SmallVec<[(Contact, FeatureId); 16]> = SmallVec::new();
        clip_faces(b, fb, a, &pose_ab.inverse(), prediction, id_base, &mut tmp);
        out.extend(
            tmp.into_iter()
                .map(|(c, id)| (c.swapped().transformed(pose_ab), id)),
        );
    } else {
        let id_base = (fa as u32 & 0x3F) << 24;
        clip_faces(a, fa, b, pose_ab, prediction, id_base, out);
    }
    let best = sa.max(sb).max(se);
    let slack = FACE_PREFERENCE * (1.0 + best.abs());
    let reference = if ref_b {
        RefFace::B(fb)
    } else {
        RefFace::A(fa)
    };
    let s_ref = if ref_b { sb } else { sa };
    let clipped_min = out[start..]
        .iter()
        .map(|(c, _)| c.distance)
        .fold(Real::INFINITY, Real::min);
    if out.len() > start && clipped_min > best + slack && s_ref >= best - slack {
        // The incident face does not hold the deepest vertex (deep or lateral contact). The
        // deepest vertex along the reference face's normal joins when it lies over the
        // reference face (the same normal as the clipped points, the depth the SAT found);
        // when it lies beside the face its projection would be off the reference shape, so
        // the clipped points (too shallow alone) give way to the single point below.
        match sat_point(a, b, posed, reference) {
            Some(c) => out.push((c, EPA_FEATURE)),
            None => out.truncate(start),
        }
    }
    if out.len() == start {
        // The clipped face lies beyond the prediction or beside the reference face while
        // the shapes overlap (the deepest vertex is not on the incident face): one GJK/EPA
        // point on the polyhedra themselves, if it agrees with the SAT's separation (EPA
        // stopping early returns its lower bound, a shallower depth); else the deepest
        // vertex along the SAT's best face axis, when it lies over that face.
        match polyhedron_contact(a, b, pose_ab, prediction) {
            Some(c) if c.distance <= best + slack => {
                out.push((c, EPA_FEATURE));
            }
            _ if best <= prediction && (sa >= best || sb >= best) => {
                let face = if sa >= best {
                    RefFace::A(fa)
                } else {
                    RefFace::B(fb)
                };
                if let Some(c) = sat_point(a, b, posed, face) {
                    out.push((c, EPA_FEATURE));
                }
            }
            _ => {}
        }
    }
}

/// A reference face of the separating-axis test: face `.0` of A or of B.
#[derive(Debug, Clone, Copy)]
enum RefFace {
    A(usize),
    B(usize),
}

/// The deepest vertex of the other shape along the normal of face `face` (of A, or of B
/// given in A's frame by `posed`), as a contact in A's frame with that face's normal; `None`
/// when the vertex's projection on the face's plane falls outside the face (beyond
/// [`PRISM_TOL`] of its size), where it would not lie on the reference shape.
fn sat_point(
    a: &Polyhedron,
    b: &Polyhedron,
    posed: &PosedPolyhedron,
    face: RefFace,
) -> Option<Contact> {
    let (vb, nb, ob) = (&posed.vertices[..], &posed.normals[..], &posed.offsets[..]);
    let (normal, offset, verts, lp, others) = match face {
        RefFace::A(f) => {
            let h = a.faces[f];
            (h.normal, h.offset, a.vertices(), a.face_loop(f), vb)
        }
        RefFace::B(f) => (nb[f], ob[f], vb, b.face_loop(f), a.vertices()),
    };
    let p = deepest(others, normal);
    let d = normal.dot(p) - offset;
    let on_face = p - normal * d;
    let edge = |k: usize| {
        (
            verts[lp[k] as usize],
            verts[lp[(k + 1) % lp.len()] as usize],
        )
    };
    let size = (0..lp.len())
        .map(|k| {
            let (u, v) = edge(k);
            (v - u).length()
        })
        .fold(0.0, Real::max);
    let inside = (0..lp.len()).all(|k| {
        let (u, v) = edge(k);
        (v - u).cross(normal).normalize_or_zero().dot(on_face - u) <= PRISM_TOL * size
    });
    if !inside {
        return None;
    }
    Some(match face {
        RefFace::A(_) => Contact {
            distance: d,
            point_a: on_face,
            point_b: p,
            normal,
        },
        RefFace::B(_) => Contact {
            distance: d,
            point_a: p,
            point_b: on_face,
            normal: -normal,
        },
    })
}

/// The point of `points` with the smallest projection on `n` (first on ties).
fn deepest(points: &[Vec3], n: Vec3) -> Vec3 {
    let mut best = points.first().copied().unwrap_or(Vec3::ZERO);
    for p in points.iter().skip(1) {
        if p.dot(n) < best.dot(n) {
            best = *p;
        }
    }
    best
}

/// The contact feature the separating-axis test settles on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Feature {
    /// A's face is the reference face.
    FaceA,
    /// B's face is the reference face.
    FaceB,
    /// An edge pair.
    Edge,
}

/// Picks the contact feature from the best separations of A's faces, B's faces and the edge
/// pairs: A's face when it is within [`FACE_PREFERENCE`] of the best axis, else B's face
/// when it is, else the edge pair. The chosen axis is thus never worse than the best by
/// more than the preference (preferences do not stack).
pub(crate) fn choose_feature(sa: Real, sb: Real, se: Real) -> Feature {
    let best = sa.max(sb).max(se);
    let slack = FACE_PREFERENCE * (1.0 + best.abs());
    if sa >= best - slack {
        Feature::FaceA
    } else if sb >= best - slack {
        Feature::FaceB
    } else {
        Feature::Edge
    }
}

/// The contact of edge `pa qa` (on A) and edge `pb qb` (on B) at separation `se` along
/// `axis`, or `None` when the segments' closest points do not realise that separation (the
/// lines' closest points fall outside the segments: nearly parallel edges whose Minkowski
/// face is a sliver), in which case the caller clips faces instead.
pub(crate) fn edge_contact(
    pa: Vec3,
    qa: Vec3,
    pb: Vec3,
    qb: Vec3,
    axis: Vec3,
    se: Real,
) -> Option<Contact> {
    let (ca, cb) = closest_points_segment_segment(pa, qa, pb, qb);
    let scale = (qa - pa).length() + (qb - pb).length();
    let off = (cb - ca - axis * se).length();
    (off <= 1.0e-4 * scale + FACE_PREFERENCE * se.abs()).then_some(Contact {
        distance: se,
        point_a: ca,
        point_b: ca + axis * se,
        normal: axis,
    })
}

/// Polyhedron B (at `pose_ab`) against the half-space `n · x <= offset` of A: every vertex
/// within `prediction` of the plane gives a point (query convention, A's frame).
pub fn plane_polyhedron_manifold(
    n: Vec3,
    offset: Real,
    b: &Polyhedron,
    pose_ab: &Isometry,
    prediction: Real,
) -> Vec<(Contact, FeatureId)> {
    b.vertices()
        .iter()
        .enumerate()
        .filter_map(|(i, v)| {
            let p = pose_ab.transform_point(*v);
            let d = n.dot(p) - offset;
            (d <= prediction).then(|| {
                (
                    Contact {
                        distance: d,
                        point_a: p - n * d,
                        point_b: p,
                        normal: n,
                    },
                    i as u32,
                )
            })
        })
        .collect()
}

#[cfg(test)]
#[path = "polyhedron_clip_tests.rs"]
mod clip_tests;
