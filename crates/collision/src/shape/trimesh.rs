//! Triangle mesh: validated storage, its BVH ([`crate::bvh::Bvh`]), edge adjacency and
//! convexity. The mesh queries (rays, closest point, box overlap, triangle pairs) are methods
//! of [`TriMesh`] defined in `midphase::trimesh_query`.

use super::mass::polyhedron_mass_properties;
use super::trimesh_edges::{compute_edges, weld_vertices, MeshEdge, DEFAULT_FLAT_ANGLE};
use super::MassProperties;
use crate::bvh::{Bvh, BvhLayout};
use crate::error::{CaromError, Result};
use crate::math::{check_finite_vec, check_non_negative, Aabb, Real, Stamp, Vec3};
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
///
/// Deserialising checks the stored data against its own triangles (see `TriMeshData`), so
/// corrupted or inconsistent bytes give a [`CaromError`] instead of a failure in a query.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "TriMeshData")]
pub struct TriMesh {
    vertices: Vec<Vec3>,
    indices: Vec<[u32; 3]>,
    local_aabb: Aabb,
    bvh: Bvh,
    edges: Vec<[MeshEdge; 3]>,
    flat_angle: Real,
    /// Identifies this mesh's current contents for caches of its queries (not serialised,
    /// ignored by `==`): fresh when the mesh is built, deserialised or changed
    /// ([`TriMesh::set_vertices`]). The narrowphase's per-thread box-query cache
    /// (`narrowphase::mesh`) keys its entries by it, so an entry can never serve another
    /// mesh, or this mesh after its vertices moved.
    #[serde(skip)]
    stamp: Stamp,
}

/// The serialised form of a [`TriMesh`], checked on load by `TryFrom`: the vertices and
/// indices pass the constructor's checks, the flat angle is finite and >= 0, the BVH bounds
/// exactly the triangles ([`Bvh::check_primitives`]: primitive count, leaf ranges,
/// quantisation, node boxes), the cached bounds are the BVH's, and the edge table equals the
/// one computed from the triangles.
#[derive(Deserialize)]
pub struct TriMeshData {
    vertices: Vec<Vec3>,
    indices: Vec<[u32; 3]>,
    local_aabb: Aabb,
    bvh: Bvh,
    edges: Vec<[MeshEdge; 3]>,
    flat_angle: Real,
}

impl TryFrom<TriMeshData> for TriMesh {
    type Error = CaromError;
    fn try_from(d: TriMeshData) -> Result<Self> {
        super::serde_check::record(check_data(d))
    }
}

fn check_data(d: TriMeshData) -> Result<TriMesh> {
    {
        validate(&d.vertices, &d.indices)?;
        check_non_negative("flat_angle", d.flat_angle)?;
        d.bvh
            .check_primitives(&triangle_aabbs(&d.vertices, &d.indices))?;
        if d.local_aabb != d.bvh.root_aabb() {
            return Err(CaromError::invalid(
                "local_aabb",
                d.local_aabb,
                "must equal the bounds of the triangles",
            ));
        }
        if d.edges.len() != d.indices.len() {
            return Err(CaromError::invalid(
                "edges.len()",
                d.edges.len(),
                format!("must equal the {} triangles", d.indices.len()),
            ));
        }
        let expected = compute_edges(&d.vertices, &d.indices, d.flat_angle);
        if let Some(t) = (0..expected.len()).find(|&t| expected[t] != d.edges[t]) {
            return Err(CaromError::invalid(
                format!("edges[{t}]"),
                d.edges[t],
                "inconsistent with the triangles",
            ));
        }
        Ok(TriMesh {
            vertices: d.vertices,
            indices: d.indices,
            local_aabb: d.local_aabb,
            bvh: d.bvh,
            edges: d.edges,
            flat_angle: d.flat_angle,
            stamp: Stamp::fresh(),
        })
    }
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
    // Name the bad vertex only on failure (no string per vertex on the hot path).
    if let Some(i) = vertices.iter().position(|v| !v.is_finite()) {
        check_finite_vec(&format!("vertices[{i}]"), vertices[i])?;
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
            stamp: Stamp::fresh(),
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
        self.stamp = Stamp::fresh();
        Ok(())
    }

    /// The number identifying this mesh's current contents (see the `stamp` field).
    #[inline]
    pub(crate) fn stamp(&self) -> u64 {
        self.stamp.get()
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

    /// Adjacency and convexity of the three edges of every triangle.
    pub fn edges(&self) -> &[[MeshEdge; 3]] {
        &self.edges
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

/// Bounding box of each triangle, the primitive boxes of a mesh BVH (an indexed map, in
/// parallel with the `parallel` feature; the result does not depend on the thread count).
pub fn triangle_aabbs(vertices: &[Vec3], indices: &[[u32; 3]]) -> Vec<Aabb> {
    let aabb = |t: &[u32; 3]| {
        Aabb::from_points([
            vertices[t[0] as usize],
            vertices[t[1] as usize],
            vertices[t[2] as usize],
        ])
    };
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        indices.par_iter().map(aabb).collect()
    }
    #[cfg(not(feature = "parallel"))]
    indices.iter().map(aabb).collect()
}
