//! Merging quickhull's triangles into convex polygons.
//!
//! Quickhull (see `quickhull`) produces a closed triangle mesh in which coplanar points give
//! several triangles per flat face, and rounding can leave edges that are very slightly
//! concave. As in D. Gregorius, "Implementing Quickhull" (GDC 2014), faces whose vertices lie
//! within the tolerance of a common plane are merged into one polygon. Here it is done once,
//! after construction, by region growing:
//!
//! 1. Triangles are taken as seeds in order of decreasing area (the largest triangles have the
//!    best-conditioned planes; ties by index, so the result is deterministic).
//! 2. A region grows across edges while the new triangle's vertices are within the tolerance
//!    of the seed plane and the region stays a topological disk (its boundary one simple
//!    loop). If the final polygon is not convex (a boundary vertex reflex by more than the
//!    tolerance, possible only for nearly coplanar triangles), it is regrown keeping it convex
//!    at every step.
//! 3. Vertices shared by only two faces and collinear with their neighbours are removed.
//! 4. The result is checked to be a closed 2-manifold with `V − E + F = 2`; otherwise the
//!    caller retries with a larger tolerance.

use super::quickhull::NONE;
use crate::math::{Real, Vec3};

/// A triangle of the finished quickhull mesh.
pub(super) struct Triangle {
    /// Vertices (point indices), counter-clockwise seen from outside.
    pub v: [u32; 3],
    /// `adj[i]`: the triangle across the edge `v[i] → v[(i + 1) % 3]`.
    pub adj: [u32; 3],
    /// Unit outward normal.
    pub normal: Vec3,
    /// Plane offset.
    pub offset: Real,
}

/// Merges the closed triangle mesh `tris` over `pts` into convex polygons (point-index loops,
/// counter-clockwise from outside), or `None` if the result is not a valid closed polyhedron.
///
/// Also returns the redundant vertices: those reflex or collinear (within `tol`) in a merged
/// face. They lie within the tolerance of the hull of the other vertices (quickhull never
/// removes a vertex that later points made redundant), and the caller builds again without
/// them.
pub(super) fn merge_triangles(
    pts: &[Vec3],
    tris: &[Triangle],
    tol: Real,
) -> Option<(Vec<Vec<u32>>, Vec<u32>)> {
    let area: Vec<Real> = tris
        .iter()
        .map(|t| {
            let [a, b, c] = t.v.map(|i| pts[i as usize]);
            (b - a).cross(c - a).length()
        })
        .collect();
    let mut order: Vec<u32> = (0..tris.len() as u32).collect();
    order.sort_by(|&x, &y| {
        area[y as usize]
            .total_cmp(&area[x as usize])
            .then(x.cmp(&y))
    });
    let mut grower = Grower {
        pts,
        tris,
        tol,
        region: vec![NONE; tris.len()],
        next: vec![NONE; pts.len()],
        prev: vec![NONE; pts.len()],
        vertex_region: vec![NONE; pts.len()],
    };
    let mut polygons = Vec::new();
    let mut normals = Vec::new();
    let mut redundant = vec![false; pts.len()];
    for &seed in &order {
        if grower.region[seed as usize] != NONE {
            continue;
        }
        let r = polygons.len() as u32;
        // First grow freely (a fan around an interior vertex is only convex once complete);
        // if the final polygon is not convex, regrow keeping it convex at every step.
        let members = grower.grow(seed, r, false);
        let face = grower.boundary_loop(&members, r)?;
        let normal = tris[seed as usize].normal;
        normals.push(normal);
        if mark_redundant(pts, &face, normal, -tol, &mut redundant) == 0 {
            polygons.push(face);
        } else {
            for &m in &members {
                grower.region[m as usize] = NONE;
                for v in tris[m as usize].v {
                    grower.vertex_region[v as usize] = NONE;
                }
            }
            let members = grower.grow(seed, r, true);
            polygons.push(grower.boundary_loop(&members, r)?);
        }
    }
    remove_collinear(pts, &mut polygons, tol);
    for (face, &normal) in polygons.iter().zip(&normals) {
        mark_redundant(pts, face, normal, tol, &mut redundant);
    }
    let redundant = (0..pts.len() as u32)
        .filter(|&i| redundant[i as usize])
        .collect();
    is_closed_polyhedron(&polygons).then_some((polygons, redundant))
}

/// Signed distance of `v` from the line `u w`, positive where the polygon `… u v w …`
/// (counter-clockwise about `normal`) is convex at `v`.
fn turn(pts: &[Vec3], u: u32, v: u32, w: u32, normal: Vec3) -> Real {
    let [u, v, w] = [u, v, w].map(|i| pts[i as usize]);
    // Twice the signed area of (u, v, w) = |w − u| · signed distance of v to line uw.
    let base = (w - u).length();
    if base > 0.0 {
        (v - u).cross(w - v).dot(normal) / base
    } else {
        0.0
    }
}

/// Marks in `removed` the vertices of `face` whose turn is at most `limit`, one at a time:
/// each removal is taken into account (with the vertices already marked, possibly by other
/// faces) before judging the next, so of two nearly coincident vertices only one goes.
/// Returns how many it marked.
fn mark_redundant(
    pts: &[Vec3],
    face: &[u32],
    normal: Vec3,
    limit: Real,
    removed: &mut [bool],
) -> usize {
    let mut ring: Vec<u32> = face
        .iter()
        .copied()
        .filter(|&v| !removed[v as usize])
        .collect();
    let mut marked = 0;
    let mut k = 0;
    let mut unchanged = 0;
    while ring.len() > 3 && unchanged < ring.len() {
        let n = ring.len();
        let (u, v, w) = (ring[(k + n - 1) % n], ring[k % n], ring[(k + 1) % n]);
        if turn(pts, u, v, w, normal) <= limit {
            removed[v as usize] = true;
            marked += 1;
            let i = k % n;
            ring.remove(i);
            // Judge the previous vertex again with its new neighbour.
            k = (i + n - 2) % (n - 1);
            unchanged = 0;
        } else {
            k = (k + 1) % n;
            unchanged += 1;
        }
    }
    marked
}

/// Region-growing state. The boundary of the region being grown is a doubly linked loop over
/// vertices (`next`/`prev`, valid for vertices on it).
struct Grower<'a> {
    pts: &'a [Vec3],
    tris: &'a [Triangle],
    tol: Real,
    /// Per triangle: its region, or `NONE`.
    region: Vec<u32>,
    next: Vec<u32>,
    prev: Vec<u32>,
    /// Per vertex: the last region that touched it.
    vertex_region: Vec<u32>,
}

impl Grower<'_> {
    /// Grows region `r` from `seed`, keeping it convex at every step if `strict`; returns its
    /// triangles.
    fn grow(&mut self, seed: u32, r: u32, strict: bool) -> Vec<u32> {
        let t = &self.tris[seed as usize];
        let (normal, offset) = (t.normal, t.offset);
        self.region[seed as usize] = r;
        for k in 0..3 {
            let (u, v) = (t.v[k], t.v[(k + 1) % 3]);
            self.next[u as usize] = v;
            self.prev[v as usize] = u;
            self.vertex_region[u as usize] = r;
        }
        let mut members = vec![seed];
        let mut candidates: Vec<u32> = t.adj.to_vec();
        // A rejected candidate is retried when another of its neighbours joins.
        while let Some(c) = candidates.pop() {
            if self.region[c as usize] == NONE && self.try_add(c, r, normal, offset, strict) {
                self.region[c as usize] = r;
                members.push(c);
                candidates.extend(self.tris[c as usize].adj);
            }
        }
        members
    }

    /// Whether vertex `v` between `u` and `w` is convex (or reflex by at most the tolerance)
    /// seen along `normal`.
    fn convex(&self, u: u32, v: u32, w: u32, normal: Vec3) -> bool {
        turn(self.pts, u, v, w, normal) >= -self.tol
    }

    /// Adds triangle `c` to region `r` (plane `normal · x = offset`) if it is coplanar, keeps
    /// the region a disk (and convex if `strict`), and updates the boundary loop.
    fn try_add(&mut self, c: u32, r: u32, normal: Vec3, offset: Real, strict: bool) -> bool {
        let t = &self.tris[c as usize];
        if t.normal.dot(normal) <= 0.0
            || t.v
                .iter()
                .any(|&i| (normal.dot(self.pts[i as usize]) - offset).abs() > self.tol)
        {
            return false;
        }
        let shared = t.adj.map(|a| self.region[a as usize] == r);
        let at = |k: usize| t.v[k % 3];
        match shared.iter().filter(|&&s| s).count() {
            1 => {
                // Shared edge x → y: the boundary runs y → x; z is new.
                let k = shared.iter().position(|&s| s).unwrap_or(0);
                let (x, y, z) = (at(k), at(k + 1), at(k + 2));
                if self.next[y as usize] != x || self.vertex_region[z as usize] == r {
                    return false; // z already on the region: adding t would pinch it
                }
                let (before, after) = (self.prev[y as usize], self.next[x as usize]);
                if strict
                    && (!self.convex(before, y, z, normal) || !self.convex(z, x, after, normal))
                {
                    return false;
                }
                self.next[y as usize] = z;
                self.prev[z as usize] = y;
                self.next[z as usize] = x;
                self.prev[x as usize] = z;
                self.vertex_region[z as usize] = r;
                true
            }
            2 => {
                // Unshared edge z → x; the boundary runs z → y → x and y becomes interior.
                let k = shared.iter().position(|&s| !s).unwrap_or(0);
                let (z, x, y) = (at(k), at(k + 1), at(k + 2));
                if self.next[z as usize] != y || self.next[y as usize] != x {
                    return false;
                }
                let (before, after) = (self.prev[z as usize], self.next[x as usize]);
                if strict
                    && (!self.convex(before, z, x, normal) || !self.convex(z, x, after, normal))
                {
                    return false;
                }
                self.next[z as usize] = x;
                self.prev[x as usize] = z;
                true
            }
            _ => false,
        }
    }

    /// The boundary loop of region `r` (made of `members`), or `None` if it is broken.
    fn boundary_loop(&self, members: &[u32], r: u32) -> Option<Vec<u32>> {
        let start = members.iter().find_map(|&m| {
            let t = &self.tris[m as usize];
            (0..3)
                .find(|&k| self.region[t.adj[k] as usize] != r)
                .map(|k| t.v[k])
        })?;
        let mut face = vec![start];
        let mut v = self.next[start as usize];
        while v != start {
            if face.len() > members.len() + 2 || v == NONE {
                return None;
            }
            face.push(v);
            v = self.next[v as usize];
        }
        Some(face)
    }
}

/// Removes vertices that belong to exactly two faces and lie within `tol` of the line through
/// their neighbours (they are points on an edge, not corners), unless a face would be left
/// with fewer than three vertices.
fn remove_collinear(pts: &[Vec3], polygons: &mut [Vec<u32>], tol: Real) {
    let mut count = vec![0u32; pts.len()];
    for &v in polygons.iter().flatten() {
        count[v as usize] += 1;
    }
    // Decide each vertex once (in the first face holding it), so both faces agree.
    let mut remove = vec![false; pts.len()];
    let mut decided = vec![false; pts.len()];
    for face in polygons.iter() {
        let n = face.len();
        for k in 0..n {
            let v = face[k] as usize;
            if count[v] != 2 || decided[v] {
                continue;
            }
            decided[v] = true;
            let (u, w) = (
                pts[face[(k + n - 1) % n] as usize],
                pts[face[(k + 1) % n] as usize],
            );
            let base = (w - u).length();
            remove[v] = base > 0.0 && (pts[v] - u).cross(w - u).length() <= tol * base;
        }
    }
    // Keep every face a polygon: un-remove the vertices of faces that would degenerate.
    let mut changed = true;
    while changed {
        changed = false;
        for face in polygons.iter() {
            if face.iter().filter(|&&v| !remove[v as usize]).count() < 3 {
                for &v in face {
                    changed |= remove[v as usize];
                    remove[v as usize] = false;
                }
            }
        }
    }
    for face in polygons.iter_mut() {
        face.retain(|&v| !remove[v as usize]);
    }
}

/// Whether the polygons form a closed, consistently oriented 2-manifold of genus 0: every
/// directed edge once, its reverse once, no repeated vertex in a face, `V − E + F = 2`.
pub(super) fn is_closed_polyhedron(polygons: &[Vec<u32>]) -> bool {
    let mut edges: Vec<(u32, u32)> = Vec::new();
    let mut vertices: Vec<u32> = Vec::new();
    for face in polygons {
        if face.len() < 3 {
            return false;
        }
        let mut sorted = face.clone();
        sorted.sort_unstable();
        if sorted.windows(2).any(|w| w[0] == w[1]) {
            return false;
        }
        for k in 0..face.len() {
            edges.push((face[k], face[(k + 1) % face.len()]));
        }
        vertices.extend_from_slice(face);
    }
    edges.sort_unstable();
    if edges.windows(2).any(|w| w[0] == w[1]) {
        return false;
    }
    if edges
        .iter()
        .any(|&(u, v)| edges.binary_search(&(v, u)).is_err())
    {
        return false;
    }
    vertices.sort_unstable();
    vertices.dedup();
    vertices.len() as i64 - (edges.len() / 2) as i64 + polygons.len() as i64 == 2
}
