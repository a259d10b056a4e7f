//! One entry point for the shapes made of triangles (meshes and heightfields), so callers
//! such as `query::raycast` and `query::project_point` use the accelerated traversals (a
//! mesh's BVH, a heightfield's grid) through one code path, with brute-force twins over every
//! triangle as test oracles.

use super::mesh_query::{brute_force_closest, MeshPointProjection, MeshRayHit};
use super::triangle_query::WatertightRay;
use crate::math::{Aabb, Real, Vec3};
use crate::shape::{HeightField, Shape, TriMesh};

/// A shape made of triangles, queried through its own acceleration structure.
#[derive(Debug, Clone, Copy)]
pub enum TriangleSource<'a> {
    /// A triangle mesh (its BVH).
    Mesh(&'a TriMesh),
    /// A heightfield (its grid).
    HeightField(&'a HeightField),
}

impl<'a> TriangleSource<'a> {
    /// The source of a mesh or heightfield shape; `None` for other kinds.
    pub fn of(shape: &'a Shape) -> Option<Self> {
        match shape {
            Shape::TriMesh(m) => Some(TriangleSource::Mesh(m)),
            Shape::HeightField(h) => Some(TriangleSource::HeightField(h)),
            _ => None,
        }
    }

    /// Number of triangles.
    pub fn num_triangles(&self) -> usize {
        match self {
            TriangleSource::Mesh(m) => m.num_triangles(),
            TriangleSource::HeightField(h) => h.num_triangles(),
        }
    }

    /// The corners of triangle `i`.
    pub fn triangle(&self, i: u32) -> [Vec3; 3] {
        match self {
            TriangleSource::Mesh(m) => m.triangle(i as usize),
            TriangleSource::HeightField(h) => h.triangle(i as usize),
        }
    }

    /// Calls `f(triangle)` for every triangle whose bounding box overlaps `aabb` (touching
    /// counts), in no particular order; `f` returns `false` to stop.
    pub fn for_each_triangle_in_aabb(&self, aabb: &Aabb, f: impl FnMut(u32) -> bool) {
        match self {
            TriangleSource::Mesh(m) => m.view().for_each_triangle_in_aabb(aabb, f),
            TriangleSource::HeightField(h) => h.for_each_triangle_in_aabb(aabb, f),
        }
    }

    /// Bounding box of every triangle.
    pub fn local_aabb(&self) -> Aabb {
        match self {
            TriangleSource::Mesh(m) => m.local_aabb(),
            TriangleSource::HeightField(h) => h.local_aabb(),
        }
    }

    /// The closest hit of the ray `origin + t·dir`, `t ∈ [0, max_t]` (ties to the smaller
    /// triangle index).
    pub fn ray_closest(&self, origin: Vec3, dir: Vec3, max_t: Real) -> Option<MeshRayHit> {
        match self {
            TriangleSource::Mesh(m) => m.raycast(origin, dir, max_t),
            TriangleSource::HeightField(h) => h.raycast(origin, dir, max_t),
        }
    }

    /// The closest point to `point` within `max_dist` (ties to the smaller triangle index).
    pub fn closest_point(&self, point: Vec3, max_dist: Real) -> Option<MeshPointProjection> {
        match self {
            TriangleSource::Mesh(m) => m.closest_point(point, max_dist),
            TriangleSource::HeightField(h) => h.closest_point(point, max_dist),
        }
    }

    /// [`TriangleSource::ray_closest`] by testing every triangle: the oracle.
    pub fn brute_force_ray_closest(
        &self,
        origin: Vec3,
        dir: Vec3,
        max_t: Real,
    ) -> Option<MeshRayHit> {
        if max_t.is_nan() || max_t < 0.0 {
            return None;
        }
        let ray = WatertightRay::new(origin, dir)?;
        let mut best: Option<MeshRayHit> = None;
        for i in 0..self.num_triangles() as u32 {
            let tri = self.triangle(i);
            if let Some(h) = ray.intersect(&tri, max_t) {
                if best.is_none_or(|b| h.t < b.t) {
                    best = Some(MeshRayHit {
                        triangle: i,
                        t: h.t,
                        barycentric: h.barycentric,
                        point: origin + dir * h.t,
                        normal: face_normal(&tri, dir),
                    });
                }
            }
        }
        best
    }

    /// [`TriangleSource::closest_point`] by testing every triangle: the oracle.
    pub fn brute_force_closest_point(
        &self,
        point: Vec3,
        max_dist: Real,
    ) -> Option<MeshPointProjection> {
        brute_force_closest(self.num_triangles(), |i| self.triangle(i), point, max_dist)
    }
}

/// Unit counter-clockwise normal of a triangle, `-dir` normalised when degenerate (as
/// [`MeshRayHit::normal`]).
#[inline]
pub(crate) fn face_normal(tri: &[Vec3; 3], dir: Vec3) -> Vec3 {
    (tri[1] - tri[0])
        .cross(tri[2] - tri[0])
        .try_normalize()
        .unwrap_or_else(|| -dir.normalize_or_zero())
}
