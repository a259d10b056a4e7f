//! Mesh preprocessing: welding duplicate vertices, per-edge adjacency and the signed
//! dihedral (convexity) angle of every edge, for internal-edge correction.
//!
//! Edge classification follows Jolt's active edges (`Jolt/Physics/Collision/ActiveEdges.h`)
//! and Box3D's mesh edge flags (`src/mesh_contact.c`): an edge between two triangles is
//! convex, flat or concave by the sign and size of the dihedral angle; boundary edges (one
//! triangle, or more than two, or a degenerate neighbour) are treated as convex by users.

use crate::error::{CaromError, Result};
use crate::math::{check_non_negative, Real, Vec3};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;

/// Marker for "no neighbour" in [`MeshEdge::neighbor`].
pub const NO_NEIGHBOR: u32 = u32::MAX;

/// Default angle (radians) under which an edge between two triangles counts as flat.
pub const DEFAULT_FLAT_ANGLE: Real = 1.0e-3;

/// How an edge bends, seen from the front faces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum EdgeKind {
    /// One triangle only, more than two, or a degenerate neighbour: always "active".
    Boundary,
    /// The neighbour bends away (a ridge): contacts on the edge are real.
    Convex,
    /// The neighbour continues the plane within the flat tolerance: an internal edge.
    Flat,
    /// The neighbour bends up (a valley): contacts on the edge come from the faces.
    Concave,
}

/// Adjacency and convexity of one triangle edge (edge `k` runs from corner `k` to `k + 1`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MeshEdge {
    /// The triangle across the edge, or [`NO_NEIGHBOR`].
    pub neighbor: u32,
    /// Signed dihedral angle between the two face normals, in `[-π, π]`: positive for convex
    /// edges, negative for concave ones, 0 for boundaries.
    pub angle: Real,
    /// Classification of the edge.
    pub kind: EdgeKind,
}

const BOUNDARY: MeshEdge = MeshEdge {
    neighbor: NO_NEIGHBOR,
    angle: 0.0,
    kind: EdgeKind::Boundary,
};

/// Merges vertices closer than `tolerance` (finite, >= 0; 0 merges exact duplicates) into
/// the first of them, and remaps the indices. Deterministic: the result depends only on the
/// input order. Uses a uniform grid with cells of the tolerance size.
pub fn weld_vertices(
    vertices: &[Vec3],
    indices: &[[u32; 3]],
    tolerance: Real,
) -> Result<(Vec<Vec3>, Vec<[u32; 3]>)> {
    let tol = check_non_negative("weld_tolerance", tolerance)?;
    let cell = if tol > 0.0 { tol } else { 1.0 };
    let key = |p: Vec3| -> [i64; 3] {
        let c = (p / cell).floor();
        [c.x as i64, c.y as i64, c.z as i64]
    };
    let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    let mut remap = Vec::with_capacity(vertices.len());
    let mut out: Vec<Vec3> = Vec::new();
    for &p in vertices {
        let k = key(p);
        let mut found: Option<u32> = None;
        for dx in -1..=1i64 {
            for dy in -1..=1i64 {
                for dz in -1..=1i64 {
                    let nk = [
                        k[0].saturating_add(dx),
                        k[1].saturating_add(dy),
                        k[2].saturating_add(dz),
                    ];
                    for &j in grid.get(&nk).map(|v| v.as_slice()).unwrap_or(&[]) {
                        let close = (out[j as usize] - p).length_squared() <= tol * tol;
                        if close && found.is_none_or(|f| f > j) {
                            found = Some(j);
                        }
                    }
                }
            }
        }
        let j = match found {
            Some(j) => j,
            None => {
                out.push(p);
                let j = (out.len() - 1) as u32;
                grid.entry(k).or_default().push(j);
                j
            }
        };
        remap.push(j);
    }
    let mut new_indices = Vec::with_capacity(indices.len());
    for (t, tri) in indices.iter().enumerate() {
        let mut r = [0u32; 3];
        for k in 0..3 {
            r[k] = *remap.get(tri[k] as usize).ok_or_else(|| {
                CaromError::invalid(
                    format!("indices[{t}][{k}]"),
                    tri[k],
                    format!("out of range for {} vertices", vertices.len()),
                )
            })?;
        }
        new_indices.push(r);
    }
    Ok((out, new_indices))
}

/// Adjacency and convexity of every edge of every triangle. Edges are matched by vertex
/// indices (weld first to match by position); an edge shared by exactly two triangles gets
/// both as neighbours, any other count gives boundaries. `flat_angle` (radians) is the
/// tolerance of [`EdgeKind::Flat`].
///
/// Sort-based matching, as in Jolt's `MeshEdge` building and parry's topology pass but
/// without a hash map: each edge becomes one `u64` key (low vertex, high vertex) beside its
/// slot `3·t + k`, and the pairs are sorted by a counting sort on the low vertex
/// (`sorted_edge_keys`; unique keys, so the order is deterministic whatever the thread
/// count). Face normals are computed once per triangle; with the `parallel` feature the
/// normals and the per-edge classification run on rayon, each edge writing only its own slot.
pub fn compute_edges(
    vertices: &[Vec3],
    indices: &[[u32; 3]],
    flat_angle: Real,
) -> Vec<[MeshEdge; 3]> {
    let list = sorted_edge_keys(vertices.len(), indices);
    let normal = |tri: &[u32; 3]| -> Option<Vec3> {
        let [a, b, c] = tri.map(|i| vertices[i as usize]);
        (b - a).cross(c - a).try_normalize()
    };
    #[cfg(feature = "parallel")]
    let normals: Vec<Option<Vec3>> = {
        use rayon::prelude::*;
        indices.par_iter().map(normal).collect()
    };
    #[cfg(not(feature = "parallel"))]
    let normals: Vec<Option<Vec3>> = indices.iter().map(normal).collect();
    // The edge at sorted position `i`, if its key is shared by exactly one other slot.
    let classify = |i: usize| -> Option<(u32, MeshEdge)> {
        let key = list[i].0;
        let prev = i > 0 && list[i - 1].0 == key;
        let next = i + 1 < list.len() && list[i + 1].0 == key;
        let partner = match (prev, next) {
            (true, false) if i < 2 || list[i - 2].0 != key => i - 1,
            (false, true) if i + 2 >= list.len() || list[i + 2].0 != key => i + 1,
            _ => return None,
        };
        let (slot, other_slot) = (list[i].1, list[partner].1);
        let (t, k) = (slot / 3, (slot % 3) as usize);
        let (t2, k2) = (other_slot / 3, (other_slot % 3) as usize);
        if t == t2 {
            return None;
        }
        let same_dir = indices[t as usize][k] == indices[t2 as usize][k2];
        let e = edge_info(
            vertices,
            indices,
            normals[t as usize],
            normals[t2 as usize],
            t,
            k,
            t2,
            same_dir,
            flat_angle,
        );
        Some((slot, e))
    };
    #[cfg(feature = "parallel")]
    let found: Vec<Option<(u32, MeshEdge)>> = {
        use rayon::prelude::*;
        (0..list.len()).into_par_iter().map(classify).collect()
    };
    #[cfg(not(feature = "parallel"))]
    let found: Vec<Option<(u32, MeshEdge)>> = (0..list.len()).map(classify).collect();
    let mut edges = vec![[BOUNDARY; 3]; indices.len()];
    for (slot, e) in found.into_iter().flatten() {
        edges[(slot / 3) as usize][(slot % 3) as usize] = e;
    }
    edges
}

/// Every non-degenerate edge as `(low << 32 | high, 3·t + k)`, sorted. A counting sort on
/// the low vertex (one pass to count, one to place, in slot order) leaves only the few
/// edges of each vertex to sort by `(high, slot)`: linear time instead of a comparison sort
/// of all `3·T` edges. Keys with slots are unique, so the result is fully determined.
fn sorted_edge_keys(num_vertices: usize, indices: &[[u32; 3]]) -> Vec<(u64, u32)> {
    let edge = |tri: &[u32; 3], k: usize| {
        let (a, b) = (tri[k], tri[(k + 1) % 3]);
        (a.min(b), a.max(b))
    };
    let mut start = vec![0u32; num_vertices + 1];
    for tri in indices {
        for k in 0..3 {
            let (lo, hi) = edge(tri, k);
            if lo != hi {
                start[lo as usize + 1] += 1;
            }
        }
    }
    for v in 0..num_vertices {
        start[v + 1] += start[v];
    }
    let total = start[num_vertices] as usize;
    let mut list = vec![(0u64, 0u32); total];
    let mut fill = start.clone();
    for (t, tri) in indices.iter().enumerate() {
        for k in 0..3 {
            let (lo, hi) = edge(tri, k);
            if lo != hi {
                let at = &mut fill[lo as usize];
                list[*at as usize] = (
                    (u64::from(lo) << 32) | u64::from(hi),
                    3 * t as u32 + k as u32,
                );
                *at += 1;
            }
        }
    }
    for v in 0..num_vertices {
        let (a, b) = (start[v] as usize, start[v + 1] as usize);
        if b - a > 1 {
            list[a..b].sort_unstable();
        }
    }
    list
}

/// Edge `k` of triangle `t` with neighbour `other`. When both triangles run the edge in the
/// same direction (inconsistent winding) the neighbour's normal is flipped first.
#[allow(clippy::too_many_arguments)]
fn edge_info(
    vertices: &[Vec3],
    indices: &[[u32; 3]],
    n: Option<Vec3>,
    n_other: Option<Vec3>,
    t: u32,
    k: usize,
    other: u32,
    same_dir: bool,
    flat_angle: Real,
) -> MeshEdge {
    let (Some(n), Some(mut m)) = (n, n_other) else {
        return MeshEdge {
            neighbor: other,
            ..BOUNDARY
        };
    };
    if same_dir {
        m = -m;
    }
    let tri = indices[t as usize];
    let p0 = vertices[tri[k] as usize];
    let p1 = vertices[tri[(k + 1) % 3] as usize];
    // The neighbour's far corner tells on which side of this face it bends.
    let far = indices[other as usize]
        .iter()
        .map(|&i| vertices[i as usize])
        .max_by(|a, b| {
            let da = (*a - p0).cross(p1 - p0).length_squared();
            let db = (*b - p0).cross(p1 - p0).length_squared();
            da.total_cmp(&db)
        })
        .unwrap_or(p0);
    classify_edge(n, m, p0, far, other, flat_angle)
}

/// The edge between a face of unit normal `n` and a neighbour `other` of unit normal `m`
/// (consistently wound) whose corner off the shared edge is `far`; `p0` is on the edge.
/// The sign of the dihedral angle says on which side of the face the neighbour bends.
pub fn classify_edge(
    n: Vec3,
    m: Vec3,
    p0: Vec3,
    far: Vec3,
    other: u32,
    flat_angle: Real,
) -> MeshEdge {
    let unsigned = n.cross(m).length().atan2(n.dot(m));
    let below = (far - p0).dot(n) <= 0.0;
    let angle = if below { unsigned } else { -unsigned };
    let kind = if unsigned <= flat_angle {
        EdgeKind::Flat
    } else if below {
        EdgeKind::Convex
    } else {
        EdgeKind::Concave
    };
    MeshEdge {
        neighbor: other,
        angle,
        kind,
    }
}

/// A boundary edge (no neighbour).
pub const BOUNDARY_EDGE: MeshEdge = BOUNDARY;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::consts::FRAC_PI_2;

    #[test]
    fn weld_merges_close_vertices_deterministically() {
        let v = vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(1e-4, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 5e-5),
            Vec3::Y,
        ];
        let i = vec![[0, 1, 2], [3, 5, 4]];
        let (w, wi) = weld_vertices(&v, &i, 1e-3).unwrap();
        assert_eq!(w.len(), 4);
        assert_eq!(wi, vec![[0, 1, 2], [0, 3, 1]]);
        let (w0, _) = weld_vertices(&v, &i, 0.0).unwrap();
        assert_eq!(w0.len(), 6);
        assert!(weld_vertices(&v, &i, -1.0).is_err());
        assert!(weld_vertices(&v, &[[0, 9, 1]], 0.1).is_err());
    }

    #[test]
    fn edges_of_a_folded_strip() {
        // Two triangles sharing edge (1, 2); the fourth corner is lifted or lowered.
        for (lift, kind) in [
            (-1.0, EdgeKind::Convex),
            (0.0, EdgeKind::Flat),
            (1.0, EdgeKind::Concave),
        ] {
            let v = vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
                Vec3::new(1.0, 1.0, lift),
            ];
            let idx = vec![[0, 1, 2], [1, 3, 2]];
            let e = compute_edges(&v, &idx, DEFAULT_FLAT_ANGLE);
            assert_eq!(e[0][1].neighbor, 1);
            assert_eq!(e[1][2].neighbor, 0);
            assert_eq!(e[0][1].kind, kind);
            assert_eq!(e[1][2].kind, kind);
            assert_eq!(e[0][0].kind, EdgeKind::Boundary);
            assert!((e[0][1].angle - e[1][2].angle).abs() < 1e-5);
            assert!(e[0][1].angle * lift <= 0.0);
        }
    }

    #[test]
    fn cube_edges_are_convex_right_angles() {
        let v: Vec<Vec3> = (0..8)
            .map(|i| {
                Vec3::new(
                    (i & 1) as Real,
                    ((i >> 1) & 1) as Real,
                    ((i >> 2) & 1) as Real,
                )
            })
            .collect();
        let idx = vec![
            [0, 2, 1],
            [1, 2, 3],
            [4, 5, 6],
            [5, 7, 6],
            [0, 1, 4],
            [1, 5, 4],
            [2, 6, 3],
            [3, 6, 7],
            [0, 4, 2],
            [2, 4, 6],
            [1, 3, 5],
            [3, 7, 5],
        ];
        let e = compute_edges(&v, &idx, DEFAULT_FLAT_ANGLE);
        let mut right = 0;
        for tri in &e {
            for edge in tri {
                assert!(edge.neighbor != NO_NEIGHBOR);
                assert_ne!(edge.kind, EdgeKind::Concave);
                if edge.kind == EdgeKind::Convex {
                    assert!((edge.angle - FRAC_PI_2).abs() < 1e-5);
                    right += 1;
                }
            }
        }
        assert_eq!(right, 24, "12 cube edges seen from both sides");
    }
}
