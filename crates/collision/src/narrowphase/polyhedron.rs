//! Polyhedral contact manifolds in one shot: the separating-axis test over face normals and
//! edge pairs with Gauss-map pruning of edge pairs (D. Gregorius, "The Separating Axis Test
//! between Convex Polyhedra", GDC 2013), then face clipping (Sutherland–Hodgman) of the
//! incident face against the reference face's side planes, keeping points with penetration
//! or within the speculative margin (Coumans, "Contact Generation", "Contact clipping").
//! Serves boxes, convex hulls and triangles alike.

use super::contact::FeatureId;
use crate::math::{Isometry, Real, Vec3};
use crate::query::closest_points::closest_points_segment_segment;
use crate::query::Contact;
use crate::shape::{ConvexHull, Cuboid, Triangle};
use std::borrow::Cow;
use std::sync::OnceLock;

/// A convex polyhedron view: vertices, faces (plane + counter-clockwise vertex loop) and
/// edges with their two adjacent faces (for the Gauss map).
#[derive(Debug, Clone, Default)]
pub struct Polyhedron {
    /// Vertices.
    pub vertices: Vec<Vec3>,
    /// Faces: unit outward normal, plane offset, range in `loops`.
    pub faces: Vec<(Vec3, Real, u32, u32)>,
    /// Concatenated counter-clockwise vertex loops of the faces (shared by every box).
    pub loops: Cow<'static, [u32]>,
    /// Edges: two vertex indices and the two adjacent faces (shared by every box).
    pub edges: Cow<'static, [[u32; 4]]>,
    /// True for a flat polygon (a triangle): its edges' Gauss arcs are half circles and
    /// are never pruned.
    pub flat: bool,
}

impl Polyhedron {
    /// The loop of face `f`.
    pub fn face_loop(&self, f: usize) -> &[u32] {
        let (_, _, s, c) = self.faces[f];
        &self.loops[s as usize..(s + c) as usize]
    }

    fn from_loops(vertices: Vec<Vec3>, loops: &[Vec<u32>], flat: bool) -> Polyhedron {
        let mut p = Polyhedron {
            vertices,
            flat,
            ..Default::default()
        };
        let (mut loops_out, mut edges_out) = (Vec::new(), Vec::new());
        let mut directed: Vec<(u32, u32, u32)> = Vec::new();
        for (fi, lp) in loops.iter().enumerate() {
            let v = &p.vertices;
            let mut n = Vec3::ZERO;
            for k in 0..lp.len() {
                let a = v[lp[k] as usize];
                let b = v[lp[(k + 1) % lp.len()] as usize];
                n += a.cross(b);
            }
            let n = n.normalize_or_zero();
            let off = n.dot(v[lp[0] as usize]);
            p.faces
                .push((n, off, loops_out.len() as u32, lp.len() as u32));
            loops_out.extend_from_slice(lp);
            for k in 0..lp.len() {
                directed.push((lp[k], lp[(k + 1) % lp.len()], fi as u32));
            }
        }
        // Pair each directed edge i→j with its twin j→i.
        directed.sort_unstable();
        for &(i, j, f) in &directed {
            if i < j {
                if let Ok(t) = directed.binary_search_by(|e| (e.0, e.1).cmp(&(j, i))) {
                    edges_out.push([i, j, f, directed[t].2]);
                }
            }
        }
        p.loops = Cow::Owned(loops_out);
        p.edges = Cow::Owned(edges_out);
        p
    }

    /// The box as a polyhedron (its exact half extents, margin ignored).
    ///
    /// The topology (loops, edges, face normals) is that of the unit box, built once and
    /// shared; only the vertices and face offsets are computed per call (this runs for every
    /// box pair at every step).
    pub fn from_cuboid(b: &Cuboid) -> Polyhedron {
        static UNIT: OnceLock<Polyhedron> = OnceLock::new();
        let unit = UNIT.get_or_init(|| Self::cuboid_with(Vec3::ONE));
        let h = b.half_extents();
        let vertices: Vec<Vec3> = unit.vertices.iter().map(|v| *v * h).collect();
        let faces = unit
            .faces
            .iter()
            .map(|&(n, _, s, c)| (n, n.dot(vertices[unit.loops[s as usize] as usize]), s, c))
            .collect();
        Polyhedron {
            vertices,
            faces,
            loops: Cow::Borrowed(&unit.loops[..]),
            edges: Cow::Borrowed(&unit.edges[..]),
            flat: false,
        }
    }

    fn cuboid_with(h: Vec3) -> Polyhedron {
        let vertices: Vec<Vec3> = (0..8)
            .map(|i| {
                Vec3::new(
                    if i & 1 != 0 { h.x } else { -h.x },
                    if i & 2 != 0 { h.y } else { -h.y },
                    if i & 4 != 0 { h.z } else { -h.z },
                )
            })
            .collect();
        let loops = [
            vec![1, 3, 7, 5],
            vec![0, 4, 6, 2],
            vec![2, 6, 7, 3],
            vec![0, 1, 5, 4],
            vec![4, 5, 7, 6],
            vec![0, 2, 3, 1],
        ];
        Self::from_loops(vertices, &loops, false)
    }

    /// The hull as a polyhedron.
    pub fn from_hull(h: &ConvexHull) -> Polyhedron {
        let loops: Vec<Vec<u32>> = (0..h.faces().len())
            .map(|f| h.face_vertices(f).to_vec())
            .collect();
        Self::from_loops(h.vertices().to_vec(), &loops, false)
    }

    /// The triangle as a flat polyhedron with a front and a back face.
    pub fn from_triangle(t: &Triangle) -> Polyhedron {
        Self::from_loops(t.vertices().to_vec(), &[vec![0, 1, 2], vec![0, 2, 1]], true)
    }

    fn support_dot(&self, pose: &Isometry, dir: Vec3) -> Real {
        let d = pose.inverse_transform_vector(dir);
        let m = self
            .vertices
            .iter()
            .map(|v| v.dot(d))
            .fold(Real::NEG_INFINITY, Real::max);
        m + pose.translation.dot(dir)
    }
}

/// Face query: the face of `a` (identity pose) with the greatest separation from `b` (at
/// `pose_ab`).
fn face_query(a: &Polyhedron, b: &Polyhedron, pose_ab: &Isometry) -> (Real, usize) {
    let mut best = (Real::NEG_INFINITY, 0);
    for (i, &(n, off, _, _)) in a.faces.iter().enumerate() {
        let s = -b.support_dot(pose_ab, -n) - off;
        if s > best.0 {
            best = (s, i);
        }
    }
    best
}

/// Gregorius' Minkowski-face test: arcs AB and CD of the Gauss map intersect.
fn is_minkowski_face(a: Vec3, b: Vec3, c: Vec3, d: Vec3) -> bool {
    let bxa = b.cross(a);
    let dxc = d.cross(c);
    let cba = c.dot(bxa);
    let dba = d.dot(bxa);
    let adc = a.dot(dxc);
    let bdc = b.dot(dxc);
    cba * dba < 0.0 && adc * bdc < 0.0 && cba * bdc > 0.0
}

/// Edge query: the edge pair with the greatest separation among the pairs that build a
/// face of the Minkowski difference.
fn edge_query(a: &Polyhedron, b: &Polyhedron, pose_ab: &Isometry) -> (Real, usize, usize, Vec3) {
    let mut best = (Real::NEG_INFINITY, 0, 0, Vec3::ZERO);
    let ident = Isometry::IDENTITY;
    let a_centre =
        a.vertices.iter().fold(Vec3::ZERO, |s, v| s + *v) / a.vertices.len().max(1) as Real;
    // B's vertices and face normals in A's frame, once (not once per edge pair).
    let b_vertices: Vec<Vec3> = b
        .vertices
        .iter()
        .map(|v| pose_ab.transform_point(*v))
        .collect();
    let b_normals: Vec<Vec3> = b
        .faces
        .iter()
        .map(|f| pose_ab.transform_vector(f.0))
        .collect();
    for (i, ea) in a.edges.iter().enumerate() {
        let (pa, qa) = (a.vertices[ea[0] as usize], a.vertices[ea[1] as usize]);
        let (na0, na1) = (a.faces[ea[2] as usize].0, a.faces[ea[3] as usize].0);
        for (j, eb) in b.edges.iter().enumerate() {
            let (pb, qb) = (b_vertices[eb[0] as usize], b_vertices[eb[1] as usize]);
            let (nb0, nb1) = (b_normals[eb[2] as usize], b_normals[eb[3] as usize]);
            if !a.flat && !b.flat && !is_minkowski_face(na0, na1, -nb0, -nb1) {
                continue;
            }
            let axis = (qa - pa).cross(qb - pb);
            let len = axis.length();
            if len < 1.0e-5 * (qa - pa).length() * (qb - pb).length() || len == 0.0 {
                continue;
            }
            let axis = axis / len;
            let (s, ax) = if a.flat || b.flat {
                // Flat polygons: exact separation along ±axis, keep the larger.
                let s1 = -b.support_dot(pose_ab, -axis) - a.support_dot(&ident, axis);
                let s2 = -b.support_dot(pose_ab, axis) - a.support_dot(&ident, -axis);
                if s1 >= s2 {
                    (s1, axis)
                } else {
                    (s2, -axis)
                }
            } else {
                // Gregorius: orient the axis away from A's centre; the edges are the
                // supporting features of a Minkowski face, so the distance is along them.
                let ax = if axis.dot(pa - a_centre) < 0.0 {
                    -axis
                } else {
                    axis
                };
                (ax.dot(pb - pa), ax)
            };
            if s > best.0 {
                best = (s, i, j, ax);
            }
        }
    }
    best
}

/// Clips the polygon `poly` (points with feature ids) against the half-space
/// `n · x <= d`; new points get id `(start id & 0xFFFF_FF00) | tag`.
fn clip(poly: &[(Vec3, u32)], n: Vec3, d: Real, tag: u32, out: &mut Vec<(Vec3, u32)>) {
    out.clear();
    for k in 0..poly.len() {
        let (p, ip) = poly[k];
        let (q, _) = poly[(k + 1) % poly.len()];
        let (dp, dq) = (n.dot(p) - d, n.dot(q) - d);
        if dp <= 0.0 {
            out.push((p, ip));
        }
        if (dp < 0.0) != (dq < 0.0) && dp != dq {
            let t = dp / (dp - dq);
            out.push((p + (q - p) * t, (ip & 0xFFFF_FF00) | (tag & 0xFF)));
        }
    }
}

/// Clips the incident face of `inc` (at `pose_ri` in the reference frame) against the side
/// planes of face `rf` of `refp`; returns contacts in the reference frame (normal from the
/// reference towards the incident shape).
fn clip_faces(
    refp: &Polyhedron,
    rf: usize,
    inc: &Polyhedron,
    pose_ri: &Isometry,
    prediction: Real,
    id_base: u32,
) -> Vec<(Contact, FeatureId)> {
    let (nr, off, _, _) = refp.faces[rf];
    let n_in_inc = pose_ri.inverse_transform_vector(nr);
    let mut inc_face = 0;
    let mut best = Real::INFINITY;
    for (i, f) in inc.faces.iter().enumerate() {
        let d = f.0.dot(n_in_inc);
        if d < best {
            best = d;
            inc_face = i;
        }
    }
    let id = id_base | ((inc_face as u32 & 0xFF) << 16);
    let mut poly: Vec<(Vec3, u32)> = inc
        .face_loop(inc_face)
        .iter()
        .enumerate()
        .map(|(k, &v)| {
            (
                pose_ri.transform_point(inc.vertices[v as usize]),
                id | ((k as u32 & 0xFF) << 8) | 0xFF,
            )
        })
        .collect();
    let lp = refp.face_loop(rf);
    let mut tmp = Vec::with_capacity(poly.len() + 4);
    for k in 0..lp.len() {
        let a = refp.vertices[lp[k] as usize];
        let b = refp.vertices[lp[(k + 1) % lp.len()] as usize];
        let side = (b - a).cross(nr).normalize_or_zero();
        clip(&poly, side, side.dot(a), k as u32, &mut tmp);
        std::mem::swap(&mut poly, &mut tmp);
        if poly.is_empty() {
            break;
        }
    }
    if poly.is_empty() {
        // Deep or lateral configurations where the incident face misses the reference
        // face's prism: fall back to the deepest vertex of the incident shape.
        let k = (0..inc.vertices.len())
            .min_by(|&i, &j| {
                let (pi, pj) = (inc.vertices[i].dot(n_in_inc), inc.vertices[j].dot(n_in_inc));
                pi.partial_cmp(&pj).unwrap_or(std::cmp::Ordering::Equal)
            })
            .unwrap_or(0);
        if let Some(v) = inc.vertices.get(k) {
            poly.push((pose_ri.transform_point(*v), id | 0xFEFF));
        }
    }
    poly.into_iter()
        .filter_map(|(p, fid)| {
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
        })
        .collect()
}

/// The full contact manifold of two polyhedra (B at `pose_ab` in A's frame), in A's frame
/// with the query convention (normal from A towards B), or empty when they are further
/// apart than `prediction`.
pub fn polyhedron_manifold(
    a: &Polyhedron,
    b: &Polyhedron,
    pose_ab: &Isometry,
    prediction: Real,
) -> Vec<(Contact, FeatureId)> {
    let (sa, fa) = face_query(a, b, pose_ab);
    if sa > prediction {
        return Vec::new();
    }
    let pose_ba = pose_ab.inverse();
    let (sb, fb) = face_query(b, a, &pose_ba);
    if sb > prediction {
        return Vec::new();
    }
    let (se, ia, ib, axis) = edge_query(a, b, pose_ab);
    if se > prediction {
        return Vec::new();
    }
    let face_sep = sa.max(sb);
    let tol = 1.0e-3;
    if se > face_sep + tol * (1.0 + face_sep.abs()) && se > Real::NEG_INFINITY {
        let ea = a.edges[ia];
        let eb = b.edges[ib];
        let (pa, qa) = (a.vertices[ea[0] as usize], a.vertices[ea[1] as usize]);
        let pb = pose_ab.transform_point(b.vertices[eb[0] as usize]);
        let qb = pose_ab.transform_point(b.vertices[eb[1] as usize]);
        let (ca, _) = closest_points_segment_segment(pa, qa, pb, qb);
        let id = 0x8000_0000 | ((ia as u32 & 0x7FFF) << 15) | (ib as u32 & 0x7FFF);
        return vec![(
            Contact {
                distance: se,
                point_a: ca,
                point_b: ca + axis * se,
                normal: axis,
            },
            id,
        )];
    }
    // Prefer A's face unless B's is clearly better (stable reference choice).
    if sb > sa + tol * (1.0 + sa.abs()) {
        let id_base = ((fb as u32 & 0x3F) | 0x40) << 24;
        clip_faces(b, fb, a, &pose_ba, prediction, id_base)
            .into_iter()
            .map(|(c, id)| (c.swapped().transformed(pose_ab), id))
            .collect()
    } else {
        let id_base = (fa as u32 & 0x3F) << 24;
        clip_faces(a, fa, b, pose_ab, prediction, id_base)
    }
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
    b.vertices
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
