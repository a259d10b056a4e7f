//! Convex hull shape built from a point cloud.

use super::hull_lanes::{blocks, support_index, Block};
use super::mass::polyhedron_mass_properties;
use super::quickhull::{quickhull, HullPolygons};
use super::support::SupportMap;
use super::MassProperties;
use crate::error::{CaromError, Result};
use crate::math::{check_finite_vec, Aabb, Mat3, Real, Vec3};
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
///
/// It also stores each vertex's neighbours along the edges, for hill-climbing support queries
/// (above [`ConvexHull::HILL_CLIMB_MIN_VERTICES`] vertices) and later for contact generation.
///
/// Deserialising checks the stored data (see `ConvexHullData`), so corrupted or
/// inconsistent bytes give a [`CaromError`] instead of a panic in a support query.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "ConvexHullData")]
pub struct ConvexHull {
    vertices: Vec<Vec3>,
    faces: Vec<HullFace>,
    face_vertex_indices: Vec<u32>,
    edges: Vec<[u32; 2]>,
    /// For edge `[a, b]`: the face running `a → b` and the face running `b → a`.
    edge_faces: Vec<[u32; 2]>,
    /// Vertex `v`'s neighbours are `neighbors[neighbor_offsets[v]..neighbor_offsets[v + 1]]`.
    neighbor_offsets: Vec<u32>,
    neighbors: Vec<u32>,
    triangles: Vec<[u32; 3]>,
    local_aabb: Aabb,
    volume: Real,
    /// Boxed to keep `Shape` small.
    unit_mass: Box<MassProperties>,
    /// The vertices in blocks of four lanes for the support scan (derived, not serialised).
    #[serde(skip)]
    lanes: Vec<Block>,
}

/// The serialised form of a [`ConvexHull`], checked on load by `TryFrom`: at least 4
/// finite vertices, at least 4 faces of at least 3 in-range vertex indices, and every derived
/// table (planes, edges, edge faces, adjacency, triangles, bounds, mass) equal to the one
/// rebuilt from the vertices and face loops, with a positive volume.
#[derive(Deserialize)]
pub struct ConvexHullData {
    vertices: Vec<Vec3>,
    faces: Vec<HullFace>,
    face_vertex_indices: Vec<u32>,
    edges: Vec<[u32; 2]>,
    edge_faces: Vec<[u32; 2]>,
    neighbor_offsets: Vec<u32>,
    neighbors: Vec<u32>,
    triangles: Vec<[u32; 3]>,
    local_aabb: Aabb,
    volume: Real,
    unit_mass: Box<MassProperties>,
}

impl TryFrom<ConvexHullData> for ConvexHull {
    type Error = CaromError;
    fn try_from(d: ConvexHullData) -> Result<Self> {
        super::serde_check::record(check_hull_data(d))
    }
}

fn check_hull_data(d: ConvexHullData) -> Result<ConvexHull> {
    let bad = |name: &str, value: usize, reason: &str| {
        Err(CaromError::invalid(
            format!("convex hull {name}"),
            value,
            reason,
        ))
    };
    let nv = d.vertices.len();
    if nv < 4 {
        return bad("vertices.len()", nv, "a hull needs at least 4 vertices");
    }
    for (i, v) in d.vertices.iter().enumerate() {
        check_finite_vec(&format!("vertices[{i}]"), *v)?;
    }
    if d.faces.len() < 4 {
        return bad(
            "faces.len()",
            d.faces.len(),
            "a hull needs at least 4 faces",
        );
    }
    let mut loops = Vec::with_capacity(d.faces.len());
    for (i, f) in d.faces.iter().enumerate() {
        let end = u64::from(f.first) + u64::from(f.count);
        if f.count < 3 || end > d.face_vertex_indices.len() as u64 {
            return bad("face", i, "fewer than 3 vertices or a range out of bounds");
        }
        let poly = &d.face_vertex_indices[f.first as usize..end as usize];
        if let Some(&v) = poly.iter().find(|&&v| v as usize >= nv) {
            return bad("face vertex index", v as usize, "out of range");
        }
        loops.push(poly.to_vec());
    }
    let rebuilt = ConvexHull::from_polygons(HullPolygons {
        vertices: d.vertices.clone(),
        faces: loops,
    });
    let lanes = blocks(&d.vertices);
    let stored = ConvexHull {
        vertices: d.vertices,
        faces: d.faces,
        face_vertex_indices: d.face_vertex_indices,
        edges: d.edges,
        edge_faces: d.edge_faces,
        neighbor_offsets: d.neighbor_offsets,
        neighbors: d.neighbors,
        triangles: d.triangles,
        local_aabb: d.local_aabb,
        volume: d.volume,
        unit_mass: d.unit_mass,
        lanes,
    };
    if rebuilt != stored {
        return bad(
            "data",
            stored.faces.len(),
            "derived tables inconsistent with the faces",
        );
    }
    if !(stored.volume.is_finite() && stored.volume > 0.0) {
        return Err(CaromError::invalid(
            "convex hull volume",
            stored.volume,
            "must be finite and > 0",
        ));
    }
    Ok(stored)
}

impl ConvexHull {
    /// Hulls with more vertices than this answer support queries by hill climbing over the
    /// vertex adjacency; smaller ones scan all vertices.
    pub const HILL_CLIMB_MIN_VERTICES: usize = 32;

    /// Hulls with at most this many vertices get their world box ([`Shape::aabb`](super::Shape::aabb)) by
    /// rotating every vertex; larger ones by six hill-climbing support queries.
    pub const AABB_SCAN_MAX_VERTICES: usize = 64;

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
        let mut directed: Vec<([u32; 2], u32)> = Vec::new();
        for (fi, poly) in faces.iter().enumerate() {
            // The normal: the corner cross products (v_k − v_{k−1}) × (v_{k+1} − v_k) all point
            // along it for a convex polygon. Built from edge vectors (differences of nearby
            // floats, exact) rather than positions as in Newell's method, and weighted by the
            // sine of the corner angle, it stays accurate far from the origin and for slivers,
            // where corners between two long, nearly parallel edges carry large relative
            // rounding errors.
            let count = poly.len();
            let at = |k: usize| vertices[poly[k % count] as usize];
            let mut n = Vec3::ZERO;
            for k in 0..count {
                let (e1, e2) = (at(k) - at(k + count - 1), at(k + 1) - at(k));
                let corner = e1.cross(e2);
                let lengths = e1.length() * e2.length();
                if lengths > 0.0 {
                    n += corner * (corner.length() / lengths);
                }
            }
            let normal = n.normalize_or_zero();
            let offset = (0..count).map(|k| normal.dot(at(k))).sum::<Real>() / count as Real;
            hull_faces.push(HullFace {
                normal,
                offset,
                first: face_vertex_indices.len() as u32,
                count: poly.len() as u32,
            });
            face_vertex_indices.extend_from_slice(poly);
            for k in 1..poly.len() - 1 {
                triangles.push([poly[0], poly[k], poly[k + 1]]);
            }
            for k in 0..poly.len() {
                let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
                directed.push(([a, b], fi as u32));
                if a < b {
                    edges.push([a, b]);
                }
            }
        }
        edges.sort_unstable();
        edges.dedup();
        let edge_faces = edge_face_pairs(&edges, directed);
        let (neighbor_offsets, neighbors) = vertex_adjacency(vertices.len(), &edges);
        let local_aabb = Aabb::from_points(vertices.iter().copied());
        let (volume, unit_mass) = scaled_mass_properties(&vertices, &triangles, &local_aabb);
        ConvexHull {
            lanes: blocks(&vertices),
            vertices,
            faces: hull_faces,
            face_vertex_indices,
            edges,
            edge_faces,
            neighbor_offsets,
            neighbors,
            triangles,
            local_aabb,
            volume,
            unit_mass: Box::new(unit_mass),
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

    /// The two faces adjacent to each edge of [`ConvexHull::edges`]: for edge `[a, b]`, the
    /// face whose loop runs `a → b`, then the one running `b → a` (the edge's arc on the Gauss
    /// map, for the separating-axis test of contact generation).
    pub fn edge_faces(&self) -> &[[u32; 2]] {
        &self.edge_faces
    }

    /// The vertices joined to vertex `v` by an edge, in increasing order.
    pub fn vertex_neighbors(&self, v: usize) -> &[u32] {
        &self.neighbors[self.neighbor_offsets[v] as usize..self.neighbor_offsets[v + 1] as usize]
    }

    /// Index of a vertex maximising `vertex · dir` (the support vertex).
    ///
    /// Above [`ConvexHull::HILL_CLIMB_MIN_VERTICES`] vertices it hill-climbs along the edges from vertex 0,
    /// moving to the best neighbour while that improves the dot product: on a convex polyhedron
    /// a vertex no neighbour improves on is a global maximum (the vertex-adjacency walk of
    /// Bullet's `btConvexHullComputer`-based shapes and Jolt's `ConvexHullShape`). Each step
    /// strictly increases the dot product, so it ends; it is also capped at the vertex count.
    /// Below the threshold a linear scan is faster. A zero or NaN `dir` gives vertex 0.
    ///
    /// Inlined into the support functions with the scan; the climb stays out of line.
    #[inline]
    pub fn support_vertex(&self, dir: Vec3) -> usize {
        if self.vertices.len() <= Self::HILL_CLIMB_MIN_VERTICES {
            return self.support_vertex_scan(dir);
        }
        self.support_vertex_climb(dir)
    }

    /// [`Self::support_vertex`] by hill climbing from vertex 0.
    #[inline(never)]
    fn support_vertex_climb(&self, dir: Vec3) -> usize {
        let mut best = 0;
        let mut best_dot = self.vertices[0].dot(dir);
        for _ in 0..self.vertices.len() {
            let current = best;
            for &n in self.vertex_neighbors(current) {
                let d = self.vertices[n as usize].dot(dir);
                if d > best_dot {
                    best = n as usize;
                    best_dot = d;
                }
            }
            if best == current {
                break;
            }
        }
        best
    }

    /// [`Self::support_vertex`] by scanning every vertex, four at a time (the first of the
    /// largest dot products, as a scalar scan would find).
    #[inline]
    fn support_vertex_scan(&self, dir: Vec3) -> usize {
        support_index(&self.lanes, dir)
    }

    /// The box of the vertices rotated by `rotation` (see [`hull_lanes::rotated_bounds`]):
    /// the hull's world box less the translation.
    ///
    /// [`hull_lanes::rotated_bounds`]: super::hull_lanes::rotated_bounds
    pub(crate) fn rotated_bounds(&self, rotation: crate::math::Quat) -> (Vec3, Vec3) {
        let m = crate::math::Mat3::from_quat(rotation);
        super::hull_lanes::rotated_bounds(&self.lanes, m.x_axis, m.y_axis, m.z_axis)
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
        self.vertices[self.support_vertex(dir)]
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

/// The faces on both sides of each edge (see [`ConvexHull::edge_faces`]); a missing twin
/// (never for a closed hull) repeats the known face.
pub(crate) fn edge_face_pairs(
    edges: &[[u32; 2]],
    mut directed: Vec<([u32; 2], u32)>,
) -> Vec<[u32; 2]> {
    directed.sort_unstable();
    let face = |e: [u32; 2]| {
        directed
            .binary_search_by(|d| d.0.cmp(&e))
            .ok()
            .map(|i| directed[i].1)
    };
    edges
        .iter()
        .map(|&[a, b]| {
            let (f, g) = (face([a, b]), face([b, a]));
            let f = f.or(g).unwrap_or(0);
            [f, g.unwrap_or(f)]
        })
        .collect()
}

/// Compressed vertex adjacency (offsets, neighbour lists sorted by index) from unique edges.
fn vertex_adjacency(vertex_count: usize, edges: &[[u32; 2]]) -> (Vec<u32>, Vec<u32>) {
    let mut offsets = vec![0u32; vertex_count + 1];
    for &[a, b] in edges {
        offsets[a as usize + 1] += 1;
        offsets[b as usize + 1] += 1;
    }
    for i in 0..vertex_count {
        offsets[i + 1] += offsets[i];
    }
    let mut fill = offsets.clone();
    let mut neighbors = vec![0u32; 2 * edges.len()];
    for &[a, b] in edges {
        neighbors[fill[a as usize] as usize] = b;
        fill[a as usize] += 1;
        neighbors[fill[b as usize] as usize] = a;
        fill[b as usize] += 1;
    }
    for v in 0..vertex_count {
        neighbors[offsets[v] as usize..offsets[v + 1] as usize].sort_unstable();
    }
    (offsets, neighbors)
}

/// [`polyhedron_mass_properties`] computed on the hull moved to the centre of its bounding box
/// and scaled to unit size by a power of two (exact), then mapped back: volume × s³, centre
/// × s + shift, inertia × s⁵. This keeps tiny, huge and far-from-origin hulls accurate (the
/// mass routine's flatness threshold is absolute).
fn scaled_mass_properties(
    vertices: &[Vec3],
    triangles: &[[u32; 3]],
    aabb: &Aabb,
) -> (Real, MassProperties) {
    let centre = aabb.center();
    let extent = aabb.half_extents().max_element();
    let scale = (2.0 as Real).powi(extent.log2().ceil() as i32);
    if !(scale.is_finite() && scale > 0.0) {
        return polyhedron_mass_properties(vertices, triangles);
    }
    let local: Vec<Vec3> = vertices.iter().map(|v| (*v - centre) / scale).collect();
    let (volume, unit) = polyhedron_mass_properties(&local, triangles);
    let s3 = scale * scale * scale;
    let inertia: Mat3 = unit.inertia * (s3 * scale * scale);
    (
        volume * s3,
        MassProperties {
            mass: unit.mass * s3,
            center_of_mass: unit.center_of_mass * scale + centre,
            inertia,
        },
    )
}
