//! Triangle mesh storage and validation. The BVH and mesh queries live in `midphase`.

use super::mass::polyhedron_mass_properties;
use super::MassProperties;
use crate::error::{CaromError, Result};
use crate::math::{check_finite_vec, Aabb, Real, Vec3};
use serde::{Deserialize, Serialize};

/// A triangle mesh: vertices and counter-clockwise index triples. Degenerate (zero-area)
/// triangles are kept; they never produce NaN in queries.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TriMesh {
    vertices: Vec<Vec3>,
    indices: Vec<[u32; 3]>,
    local_aabb: Aabb,
}

impl TriMesh {
    /// A mesh; vertices must be finite, there must be at least one triangle, and every index
    /// must be in range.
    pub fn new(vertices: Vec<Vec3>, indices: Vec<[u32; 3]>) -> Result<Self> {
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
        let local_aabb = Aabb::from_points(vertices.iter().copied());
        Ok(TriMesh {
            vertices,
            indices,
            local_aabb,
        })
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
