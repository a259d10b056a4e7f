//! The mesh queries of [`TriMesh`]: closest, any and all ray hits (single and batched),
//! closest point, box overlap and triangle pairs, all through the mesh's BVH via
//! [`MeshView`]. They are inherent methods of the shape defined here, in the midphase, so
//! `shape` does not depend on `midphase` (the shape only owns the BVH).

use super::mesh_query::{MeshPointProjection, MeshRayHit, MeshView};
use crate::error::{CaromError, Result};
use crate::math::{Aabb, Isometry, Real, Vec3};
use crate::shape::TriMesh;

impl TriMesh {
    /// The mesh as a [`MeshView`] (vertices, indices, BVH) for the midphase queries.
    pub fn view(&self) -> MeshView<'_> {
        MeshView {
            bvh: self.bvh(),
            vertices: self.vertices(),
            indices: self.indices(),
        }
    }

    /// Closest hit of the ray `origin + t·dir`, `t ∈ [0, max_t]`, in the mesh frame.
    pub fn raycast(&self, origin: Vec3, dir: Vec3, max_t: Real) -> Option<MeshRayHit> {
        self.view().ray_closest(origin, dir, max_t)
    }

    /// Any hit of the ray (occlusion test).
    pub fn raycast_any(&self, origin: Vec3, dir: Vec3, max_t: Real) -> Option<MeshRayHit> {
        self.view().ray_any(origin, dir, max_t)
    }

    /// All hits of the ray, sorted by `(t, triangle)`.
    pub fn raycast_all(&self, origin: Vec3, dir: Vec3, max_t: Real) -> Vec<MeshRayHit> {
        let mut out = Vec::new();
        self.view().ray_all(origin, dir, max_t, &mut out);
        out
    }

    /// Closest hits of many rays (`origins[i]`, `dirs[i]`), in parallel with the `parallel`
    /// feature. Errors when the slices differ in length.
    pub fn raycast_batch(
        &self,
        origins: &[Vec3],
        dirs: &[Vec3],
        max_t: Real,
    ) -> Result<Vec<Option<MeshRayHit>>> {
        if origins.len() != dirs.len() {
            return Err(CaromError::invalid(
                "dirs.len()",
                dirs.len(),
                format!("must equal origins.len() = {}", origins.len()),
            ));
        }
        #[cfg(feature = "parallel")]
        {
            use rayon::prelude::*;
            Ok(origins
                .par_iter()
                .zip(dirs.par_iter())
                .with_min_len(64)
                .map(|(&o, &d)| self.raycast(o, d, max_t))
                .collect())
        }
        #[cfg(not(feature = "parallel"))]
        Ok(origins
            .iter()
            .zip(dirs)
            .map(|(&o, &d)| self.raycast(o, d, max_t))
            .collect())
    }

    /// Closest point of the mesh to `point` within `max_dist` (use `Real::INFINITY` for no
    /// bound).
    pub fn closest_point(&self, point: Vec3, max_dist: Real) -> Option<MeshPointProjection> {
        self.view().closest_point(point, max_dist)
    }

    /// Closest points of many query points within `max_dist`, in parallel with the
    /// `parallel` feature.
    pub fn closest_point_batch(
        &self,
        points: &[Vec3],
        max_dist: Real,
    ) -> Vec<Option<MeshPointProjection>> {
        #[cfg(feature = "parallel")]
        {
            use rayon::prelude::*;
            points
                .par_iter()
                .with_min_len(64)
                .map(|&p| self.closest_point(p, max_dist))
                .collect()
        }
        #[cfg(not(feature = "parallel"))]
        points
            .iter()
            .map(|&p| self.closest_point(p, max_dist))
            .collect()
    }

    /// Triangles whose bounding boxes overlap `aabb` (mesh frame), ascending.
    pub fn overlapping_triangles(&self, aabb: &Aabb) -> Vec<u32> {
        let mut out = Vec::new();
        self.view().triangles_in_aabb(aabb, &mut out);
        out
    }

    /// Triangle pairs `(a, b)` with `a` of `self` and `b` of `other` placed at `pose_ab` whose
    /// boxes overlap, sorted.
    pub fn triangle_pairs(&self, other: &TriMesh, pose_ab: &Isometry) -> Vec<(u32, u32)> {
        let mut out = Vec::new();
        self.view().triangle_pairs(&other.view(), pose_ab, &mut out);
        out
    }
}
