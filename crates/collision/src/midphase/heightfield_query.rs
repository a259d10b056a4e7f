//! Heightfield queries: the grid is its own acceleration structure. Boxes map to a range of
//! cells; rays walk the cells they cross with a 2D DDA (Amanatides and Woo, "A Fast Voxel
//! Traversal Algorithm for Ray Tracing", Eurographics 1987) over the XZ projection, testing
//! the two triangles of each cell with the watertight ray–triangle test.

use super::mesh_query::{projection, MeshPointProjection, MeshRayHit, TIE_SLACK};
use super::triangle_query::{closest_point_on_triangle, WatertightRay};
use super::triangle_source::face_normal;
use crate::math::{Aabb, Real, Vec3, EPSILON};
use crate::shape::HeightField;

/// Cells within this fraction of a cell of a corner also test the diagonal neighbour, so a
/// ray through a grid corner cannot skip a cell because of rounding.
const CORNER_SLACK: Real = 1.0e-4;

impl HeightField {
    /// Column and row of the cell holding local `(x, z)`, clamped to the grid.
    #[inline]
    fn cell_of(&self, x: Real, z: Real) -> (isize, isize) {
        let (dx, dz) = self.cell_size();
        let b = self.local_aabb();
        let c = ((x - b.min.x) / dx).floor();
        let r = ((z - b.min.z) / dz).floor();
        let clamp = |v: Real, n: usize| (v.max(0.0).min((n - 2) as Real)) as isize;
        (clamp(c, self.cols()), clamp(r, self.rows()))
    }

    /// Calls `f(triangle)` for every triangle whose bounding box overlaps `aabb` (local
    /// frame), cell by cell in row-major order; `f` returns `false` to stop.
    pub fn for_each_triangle_in_aabb(&self, aabb: &Aabb, mut f: impl FnMut(u32) -> bool) {
        let Some(q) = aabb.intersection(&self.local_aabb()) else {
            return;
        };
        let (c0, r0) = self.cell_of(q.min.x, q.min.z);
        let (c1, r1) = self.cell_of(q.max.x, q.max.z);
        // A box touching a cell boundary from the left also touches the cell before it.
        let (c0, r0) = ((c0 - 1).max(0), (r0 - 1).max(0));
        let (c1, r1) = (
            (c1 + 1).min(self.cols() as isize - 2),
            (r1 + 1).min(self.rows() as isize - 2),
        );
        for r in r0..=r1 {
            for c in c0..=c1 {
                let cell = r as usize * (self.cols() - 1) + c as usize;
                for k in 0..2 {
                    let id = 2 * cell + k;
                    if Aabb::from_points(self.triangle(id)).intersects(aabb) && !f(id as u32) {
                        return;
                    }
                }
            }
        }
    }

    /// Triangles whose bounding boxes overlap `aabb` (local frame), ascending.
    pub fn triangles_in_aabb(&self, aabb: &Aabb) -> Vec<u32> {
        let mut out = Vec::new();
        self.for_each_triangle_in_aabb(aabb, |i| {
            out.push(i);
            true
        });
        out
    }

    /// Tests the two triangles of cell `(r, c)`, keeping the best hit by `(t, triangle)`.
    fn ray_cell(
        &self,
        ray: &WatertightRay,
        origin: Vec3,
        dir: Vec3,
        (c, r): (isize, isize),
        max_t: Real,
        best: &mut Option<MeshRayHit>,
    ) {
        if c < 0 || r < 0 || c > self.cols() as isize - 2 || r > self.rows() as isize - 2 {
            return;
        }
        let cell = r as usize * (self.cols() - 1) + c as usize;
        for k in 0..2 {
            let id = 2 * cell + k;
            let tri = self.triangle(id);
            let limit = best.map_or(max_t, |b| b.t * TIE_SLACK);
            if let Some(h) = ray.intersect(&tri, limit) {
                let better =
                    best.is_none_or(|b| h.t < b.t || (h.t == b.t && (id as u32) < b.triangle));
                if better {
                    let normal = face_normal(&tri, dir);
                    *best = Some(MeshRayHit {
                        triangle: id as u32,
                        t: h.t,
                        barycentric: h.barycentric,
                        point: origin + dir * h.t,
                        normal,
                    });
                }
            }
        }
    }

    /// Closest hit of the ray `origin + t·dir`, `t ∈ [0, max_t]` (local frame), by a 2D DDA
    /// over the cells the ray crosses. Invalid rays (zero or non-finite) miss.
    pub fn raycast(&self, origin: Vec3, dir: Vec3, max_t: Real) -> Option<MeshRayHit> {
        let ray = WatertightRay::new(origin, dir)?;
        if max_t.is_nan() || max_t < 0.0 {
            return None;
        }
        let b = self.local_aabb();
        let grown = b.expanded(b.extents().max_element() * 1e-4 + EPSILON);
        let t_enter = grown.ray_intersection(origin, dir, max_t)?;
        let (dx, dz) = self.cell_size();
        let start = origin + dir * t_enter;
        let (mut c, mut r) = self.cell_of(start.x, start.z);
        let step_c: isize = if dir.x > 0.0 { 1 } else { -1 };
        let step_r: isize = if dir.z > 0.0 { 1 } else { -1 };
        let boundary =
            |i: isize, step: isize, min: Real, d: Real| min + (i + (step > 0) as isize) as Real * d;
        let next_t = |o: Real, dv: Real, bound: Real| {
            if dv != 0.0 {
                (bound - o) / dv
            } else {
                Real::INFINITY
            }
        };
        let mut t_c = next_t(origin.x, dir.x, boundary(c, step_c, b.min.x, dx));
        let mut t_r = next_t(origin.z, dir.z, boundary(r, step_r, b.min.z, dz));
        let dt_c = if dir.x != 0.0 {
            dx / dir.x.abs()
        } else {
            Real::INFINITY
        };
        let dt_r = if dir.z != 0.0 {
            dz / dir.z.abs()
        } else {
            Real::INFINITY
        };
        let mut best: Option<MeshRayHit> = None;
        let cap = 2 * (self.rows() + self.cols()) + 8;
        for _ in 0..cap {
            self.ray_cell(&ray, origin, dir, (c, r), max_t, &mut best);
            let near_corner = (t_c - t_r).abs() <= CORNER_SLACK * dt_c.min(dt_r);
            if near_corner {
                self.ray_cell(&ray, origin, dir, (c + step_c, r), max_t, &mut best);
                self.ray_cell(&ray, origin, dir, (c, r + step_r), max_t, &mut best);
            }
            let t_next = if t_c < t_r {
                c += step_c;
                let t = t_c;
                t_c += dt_c;
                t
            } else {
                r += step_r;
                let t = t_r;
                t_r += dt_r;
                t
            };
            let limit = best.map_or(max_t, |h| h.t);
            let outside =
                c < 0 || r < 0 || c > self.cols() as isize - 2 || r > self.rows() as isize - 2;
            let beyond = t_next.is_nan() || t_next > limit * (1.0 + 16.0 * EPSILON);
            if outside || beyond {
                break;
            }
        }
        best
    }

    /// The closest point of the heightfield's surface to `point` (local frame) within
    /// `max_dist` (ties to the smaller triangle index). The cell under the point (clamped to
    /// the grid) gives a first distance `d`; only triangles whose boxes meet the box of
    /// radius `d` around the point can be closer, and those are found cell by cell.
    pub fn closest_point(&self, point: Vec3, max_dist: Real) -> Option<MeshPointProjection> {
        if !point.is_finite() || max_dist.is_nan() || max_dist < 0.0 {
            return None;
        }
        let (c, r) = self.cell_of(point.x, point.z);
        let cell = r as usize * (self.cols() - 1) + c as usize;
        let mut bound = Real::INFINITY;
        for id in [2 * cell, 2 * cell + 1] {
            let (q, _) = closest_point_on_triangle(point, &self.triangle(id));
            bound = bound.min((q - point).length());
        }
        // Slack for the rounding of the distances.
        let radius = bound.min(max_dist) * (1.0 + 16.0 * EPSILON) + EPSILON;
        let query = Aabb::new(point - Vec3::splat(radius), point + Vec3::splat(radius));
        let mut best: Option<(Real, u32, Vec3, [Real; 3])> = None;
        self.for_each_triangle_in_aabb(&query, |i| {
            let (q, w) = closest_point_on_triangle(point, &self.triangle(i as usize));
            let d = (q - point).length_squared();
            if d <= max_dist * max_dist && best.is_none_or(|b| d < b.0 || (d == b.0 && i < b.1)) {
                best = Some((d, i, q, w));
            }
            true
        });
        projection(best)
    }
}
