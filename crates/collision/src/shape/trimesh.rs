//! Triangle mesh: validated storage, its BVH (`midphase::Bvh`), edge adjacency and
//! convexity, and the mesh queries (rays, closest point, box overlap, triangle pairs).
//!
//! The mesh owns a `midphase` BVH, so this one shape uses the midphase module (the BVH is a
//! plain data structure over boxes; it does not depend on shapes).

use super::mass::polyhedron_mass_properties;
use super::trimesh_edges::{compute_edges, weld_vertices, MeshEdge, DEFAULT_FLAT_ANGLE};
use super::MassProperties;
use crate::error::{CaromError, Result};
use crate::math::{check_finite_vec, check_non_negative, Aabb, Isometry, Real, Vec3};
use crate::midphase::{triangle_aabbs, Bvh, BvhLayout, MeshPointProjection, MeshRayHit, MeshView};
use serde::{Deserialize, Serialize};

/// Options of [`TriMesh::with_options`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriMeshOptions {
    /// Merge vertices closer than this (finite, >= 0) before building; `None` keeps them.
    pub weld_tolerance: Option<Real>,
    /// Node layout of the BVH.
    pub layout: BvhLayout,
    /// Dihedral angle (radians) under which an edge is flat.
    pub flat_angle: Real,
}

impl Default for TriMeshOptions {
    fn default() -> Self {
        TriMeshOptions {
            weld_tolerance: None,
            layout: BvhLayout::Quantized,
            flat_angle: DEFAULT_FLAT_ANGLE,
        }
    }
}

/// A triangle mesh: vertices and counter-clockwise index triples, with a BVH and edge
/// adjacency built at construction. Degenerate (zero-area) triangles are kept; they never
/// produce NaN in queries.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TriMesh {
    vertices: Vec<Vec3>,
    indices: Vec<[u32; 3]>,
    local_aabb: Aabb,
    bvh: Bvh,
    edges: Vec<[MeshEdge; 3]>,
    flat_angle: Real,
}

fn validate(vertices: &[Vec3], indices: &[[u32; 3]]) -> Result<()> {
    if vertices.is_empty() {
        return Err(CaromError::invalid(
            "vertices",
            0usize,
            "a mesh needs at least one vertex",
        ));
    }
    if indices.is_empty() {
        return Err(CaromError::invalid(
            "indices",
            0usize,
            "a mesh needs at least one triangle",
        ));
    }
    for (i, v) in vertices.iter().enumerate() {
        check_finite_vec(&format!("vertices[{i}]"), *v)?;
    }
    let n = vertices.len();
    for (t, tri) in indices.iter().enumerate() {
        for (k, &i) in tri.iter().enumerate() {
            if i as usize >= n {
                return Err(CaromError::invalid(
                    format!("indices[{t}][{k}]"),
                    i,
                    format!("out of range for {n} vertices"),
                ));
            }
        }
    }
    Ok(())
}

impl TriMesh {
    /// A mesh; vertices must be finite, there must be at least one triangle, and every index
    /// must be in range. Builds a quantised BVH and the edge adjacency.
    pub fn new(vertices: Vec<Vec3>, indices: Vec<[u32; 3]>) -> Result<Self> {
        Self::with_options(vertices, indices, TriMeshOptions::default())
    }

    /// A mesh with options: optional welding of duplicate vertices, BVH layout, flat-edge
    /// tolerance.
    pub fn with_options(
        vertices: Vec<Vec3>,
        indices: Vec<[u32; 3]>,
        options: TriMeshOptions,
    ) -> Result<Self> {
        validate(&vertices, &indices)?;
        check_non_negative("flat_angle", options.flat_angle)?;
        let (vertices, indices) = match options.weld_tolerance {
            Some(tol) => weld_vertices(&vertices, &indices, tol)?,
            None => (vertices, indices),
        };
        let bvh = Bvh::new(&triangle_aabbs(&vertices, &indices), options.layout)?;
        let edges = compute_edges(&vertices, &indices, options.flat_angle);
        Ok(TriMesh {
            local_aabb: bvh.root_aabb(),
            vertices,
            indices,
            bvh,
            edges,
            flat_angle: options.flat_angle,
        })
    }

    /// Moves the vertices (same count, same triangles) and refits the BVH; edge angles are
    /// recomputed. For deforming meshes.
    pub fn set_vertices(&mut self, vertices: Vec<Vec3>) -> Result<()> {
        if vertices.len() != self.vertices.len() {
            return Err(CaromError::invalid(
                "vertices.len()",
                vertices.len(),
                format!("the mesh has {} vertices", self.vertices.len()),
            ));
        }
        validate(&vertices, &self.indices)?;
        self.bvh.refit(&triangle_aabbs(&vertices, &self.indices))?;
        self.edges = compute_edges(&vertices, &self.indices, self.flat_angle);
        self.local_aabb = self.bvh.root_aabb();
        self.vertices = vertices;
        Ok(())
    }

    /// The vertices.
    pub fn vertices(&self) -> &[Vec3] {
        &self.vertices
    }

    /// The triangles as vertex index triples.
    pub fn indices(&self) -> &[[u32; 3]] {
        &self.indices
    }

    /// Number of triangles.
    pub fn num_triangles(&self) -> usize {
        self.indices.len()
    }

    /// The three corners of triangle `i`.
    pub fn triangle(&self, i: usize) -> [Vec3; 3] {
        let t = self.indices[i];
        [
            self.vertices[t[0] as usize],
            self.vertices[t[1] as usize],
            self.vertices[t[2] as usize],
        ]
    }

    /// Local bounding box.
    pub fn local_aabb(&self) -> Aabb {
        self.local_aabb
    }

    /// The BVH over the triangles.
    pub fn bvh(&self) -> &Bvh {
        &self.bvh
    }

    /// The mesh as a [`MeshView`] (vertices, indices, BVH) for the midphase queries.
    pub fn view(&self) -> MeshView<'_> {
        MeshView {
            bvh: &self.bvh,
            vertices: &self.vertices,
            indices: &self.indices,
        }
    }

    /// Adjacency and convexity of the three edges of every triangle.
    pub fn edges(&self) -> &[[MeshEdge; 3]] {
        &self.edges
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

    /// Enclosed volume, meaningful for a closed, consistently oriented mesh (0 otherwise or
    /// when flat).
    pub fn volume(&self) -> Real {
        polyhedron_mass_properties(&self.vertices, &self.indices).0
    }

    /// Mass properties of the solid bounded by the mesh (closed, outward-oriented meshes).
    pub fn mass_properties(&self, density: Real) -> MassProperties {
        let (_, mp) = polyhedron_mass_properties(&self.vertices, &self.indices);
        MassProperties {
            mass: mp.mass * density,
            center_of_mass: mp.center_of_mass,
            inertia: mp.inertia * density,
        }
    }
}
