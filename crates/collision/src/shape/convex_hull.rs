//! Convex hull shape built from a point cloud.

use super::mass::polyhedron_mass_properties;
use super::quickhull::{quickhull, HullPolygons};
use super::support::SupportMap;
use super::MassProperties;
use crate::error::Result;
use crate::math::{check_finite_vec, Aabb, Real, Vec3};
use serde::{Deserialize, Serialize};

/// One polygonal face of a hull: a plane and a counter-clockwise (seen from outside) loop of
/// vertex indices stored in [`ConvexHull::face_vertex_indices`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct HullFace {
    /// Unit outward normal.
    pub normal: Vec3,
    /// Plane offset: the face lies in `normal · x = offset`.
    pub offset: Real,
    /// Index of the face's first vertex index in [`ConvexHull::face_vertex_indices`].
    pub first: u32,
    /// Number of vertices of the face polygon.
    pub count: u32,
}

/// A convex polyhedron: the convex hull of a point cloud, with polygonal faces (coplanar
/// triangles merged), unique edges and a triangulation.
///
/// Its margin is zero: the core is the hull itself, so `support` and `support_core` agree.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ConvexHull {
    vertices: Vec<Vec3>,
    faces: Vec<HullFace>,
    face_vertex_indices: Vec<u32>,
    edges: Vec<[u32; 2]>,
    triangles: Vec<[u32; 3]>,
    local_aabb: Aabb,
    volume: Real,
    unit_mass: MassProperties,
}

impl ConvexHull {
    /// The convex hull of `points` (quickhull). Duplicate, coplanar and interior points are
    /// handled; at least 4 points are needed and they must span a 3D volume, else a
    /// [`crate::CaromError`] says why (too few, collinear, coplanar, or NaN).
    pub fn new(points: &[Vec3]) -> Result<Self> {
        for (i, p) in points.iter().enumerate() {
            check_finite_vec(&format!("points[{i}]"), *p)?;
        }
        let polys = quickhull(points)?;
        Ok(Self::from_polygons(polys))
    }

    /// Builds the derived data (planes, edges, triangles, mass) from hull polygons.
    fn from_polygons(polys: HullPolygons) -> Self {
        let HullPolygons { vertices, faces } = polys;
        let mut hull_faces = Vec::with_capacity(faces.len());
        let mut face_vertex_indices = Vec::new();
        let mut triangles = Vec::new();
        let mut edges = Vec::new();
        for poly in &faces {
            // Newell's method: a robust normal for a planar polygon.
            let mut n = Vec3::ZERO;
            let mut centroid = Vec3::ZERO;
            for (k, &i) in poly.iter().enumerate() {
                let p = vertices[i as usize];
                let q = vertices[poly[(k + 1) % poly.len()] as usize];
                n += Vec3::new(
                    (p.y - q.y) * (p.z + q.z),
                    (p.z - q.z) * (p.x + q.x),
                    (p.x - q.x) * (p.y + q.y),
                );
                centroid += p;
            }
            centroid /= poly.len() as Real;
            let normal = n.normalize_or_zero();
            hull_faces.push(HullFace {
                normal,
                offset: normal.dot(centroid),
                first: face_vertex_indices.len() as u32,
                count: poly.len() as u32,
            });
            face_vertex_indices.extend_from_slice(poly);
            for k in 1..poly.len() - 1 {
                triangles.push([poly[0], poly[k], poly[k + 1]]);
            }
            for k in 0..poly.len() {
                let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
                if a < b {
                    edges.push([a, b]);
                }
            }
        }
        edges.sort_unstable();
        edges.dedup();
        let (volume, unit_mass) = polyhedron_mass_properties(&vertices, &triangles);
        let local_aabb = Aabb::from_points(vertices.iter().copied());
        ConvexHull {
            vertices,
            faces: hull_faces,
            face_vertex_indices,
            edges,
            triangles,
            local_aabb,
            volume,
            unit_mass,
        }
    }

    /// The hull's vertices (only points on the hull; interior and duplicate input points are
    /// dropped).
    pub fn vertices(&self) -> &[Vec3] {
        &self.vertices
    }

    /// The polygonal faces.
    pub fn faces(&self) -> &[HullFace] {
        &self.faces
    }

    /// The vertex loop of face `f`.
    pub fn face_vertices(&self, f: usize) -> &[u32] {
        let face = &self.faces[f];
        &self.face_vertex_indices[face.first as usize..(face.first + face.count) as usize]
    }

    /// All face loops, flattened (see [`HullFace::first`]).
    pub fn face_vertex_indices(&self) -> &[u32] {
        &self.face_vertex_indices
    }

    /// Unique edges as vertex index pairs `(a, b)` with `a < b`.
    pub fn edges(&self) -> &[[u32; 2]] {
        &self.edges
    }

    /// A triangulation of the faces (fans), counter-clockwise from outside.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Local bounding box.
    pub fn local_aabb(&self) -> Aabb {
        self.local_aabb
    }

    /// Volume.
    pub fn volume(&self) -> Real {
        self.volume
    }

    /// Mass properties for a uniform `density`.
    pub fn mass_properties(&self, density: Real) -> MassProperties {
        MassProperties {
            mass: self.unit_mass.mass * density,
            center_of_mass: self.unit_mass.center_of_mass,
            inertia: self.unit_mass.inertia * density,
        }
    }
}

impl SupportMap for ConvexHull {
    #[inline]
    fn support(&self, dir: Vec3) -> Vec3 {
        let mut best = self.vertices[0];
        let mut best_dot = best.dot(dir);
        for v in &self.vertices[1..] {
            let d = v.dot(dir);
            if d > best_dot {
                best_dot = d;
                best = *v;
            }
        }
        best
    }
    #[inline]
    fn support_core(&self, dir: Vec3) -> Vec3 {
        self.support(dir)
    }
    #[inline]
    fn margin(&self) -> Real {
        0.0
    }
}
