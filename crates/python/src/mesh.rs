//! `carom.TriMesh` and the triangle-mesh queries in the mesh's own frame (`raycast`,
//! `raycast_any`, `raycast_all`, `closest_points`, `overlapping_triangles`,
//! `overlapping_triangle_pairs`, and the same helpers for heightfields and compounds), thin
//! wrappers of the core's BVH queries (`carom_collision::shape::TriMesh`); batches release
//! the GIL and run in parallel.

use crate::batch;
use crate::convert::{
    index_triples, indices_out, require_finite, scalar, triples_out, vec3, vec3s, vec3s_out,
};
use crate::errors::{carom_err, core, guard, invalid};
use crate::pose::extract_isometry;
use crate::shape::PyShape;
use crate::shapes::{init, shape_of, wrap_shape, wrong_kind};
use carom_collision::math::{vec3_to_f64, Aabb, Real, Vec3};
use carom_collision::midphase::{MeshPointProjection, MeshRayHit};
use carom_collision::shape::{HeightField, Shape, TriMesh, TriMeshOptions, NO_NEIGHBOR};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use std::sync::Arc;

/// Closest ray hits on a mesh, one row per ray: `hit` `(N,)` bool, `distance` `(N,)` along
/// the unit direction, `point` `(N, 3)`, `normal` `(N, 3)` (the triangle's counter-clockwise
/// face normal, not flipped towards the ray), `triangle` `(N,)` int64 and `barycentric`
/// `(N, 3)` (weights of the triangle's corners, in its index order); misses hold NaN and
/// triangle -1. In the mesh's own frame.
#[pyclass(name = "MeshRayHits", module = "carom", frozen, get_all)]
pub struct PyMeshRayHits {
    /// `(N,)` bool: the ray hit the mesh.
    hit: Py<PyArray1<bool>>,
    /// `(N,)` distance along the unit direction (NaN for misses).
    distance: Py<PyArray1<f64>>,
    /// `(N, 3)` hit points (NaN for misses).
    point: Py<PyArray2<f64>>,
    /// `(N, 3)` unit face normals (NaN for misses).
    normal: Py<PyArray2<f64>>,
    /// `(N,)` int64 index of the triangle hit (-1 for misses).
    triangle: Py<PyArray1<i64>>,
    /// `(N, 3)` barycentric weights of the hit triangle's corners at the hit point
    /// (non-negative, summing to 1; NaN for misses).
    barycentric: Py<PyArray2<f64>>,
}

/// Rays from `(N, 3)` arrays (or `(3,)` for one ray): finite origins, non-zero finite
/// directions, normalised.
fn rays(
    origins: &Bound<'_, PyAny>,
    directions: &Bound<'_, PyAny>,
) -> PyResult<(Vec<Vec3>, Vec<Vec3>)> {
    let (o, _) = vec3s(origins, "origins", true)?;
    let (d, _) = vec3s(directions, "directions", true)?;
    rays_checked(o, d, ("origins", "directions"))
}

/// Checks rays (same count, finite, non-zero directions) and normalises the directions;
/// errors name the arguments `names`.
fn rays_checked(
    o: Vec<Vec3>,
    d: Vec<Vec3>,
    names: (&str, &str),
) -> PyResult<(Vec<Vec3>, Vec<Vec3>)> {
    if o.len() != d.len() {
        return Err(invalid(format!(
            "{} and {} must have the same length, got {} and {}",
            names.0,
            names.1,
            o.len(),
            d.len()
        )));
    }
    require_finite(names.0, &o)?;
    require_finite(names.1, &d)?;
    let mut unit = Vec::with_capacity(d.len());
    for (i, v) in d.iter().enumerate() {
        match v.try_normalize() {
            Some(u) => unit.push(u),
            None => {
                return Err(invalid(format!(
                    "invalid {}[{i}] = {:?}: must be non-zero",
                    names.1,
                    vec3_to_f64(*v)
                )))
            }
        }
    }
    Ok((o, unit))
}

fn check_max_distance(max_distance: Real) -> PyResult<()> {
    if max_distance.is_nan() || max_distance < 0.0 {
        return Err(invalid(format!(
            "invalid max_distance = {max_distance:?}: must be >= 0"
        )));
    }
    Ok(())
}

/// Batch ray casts with `cast(origin, unit_direction, max_distance)` per ray (GIL released,
/// parallel above `batch::PARALLEL_MIN`), as a `MeshRayHits`.
pub fn raycast_with(
    py: Python<'_>,
    origins: &Bound<'_, PyAny>,
    directions: &Bound<'_, PyAny>,
    max_distance: Real,
    cast: impl Fn(&[Vec3], &[Vec3], Real) -> carom_collision::Result<Vec<Option<MeshRayHit>>>
        + Send
        + Sync,
) -> PyResult<PyMeshRayHits> {
    check_max_distance(max_distance)?;
    let (o, d) = rays(origins, directions)?;
    let hits = py.detach(|| guard(|| cast(&o, &d, max_distance).map_err(carom_err)))?;
    Ok(hits_out(py, &hits))
}

/// `mesh.raycast(origins, directions, max_distance)`, by the core's `TriMesh::raycast_batch`.
pub fn raycast(
    py: Python<'_>,
    mesh: &TriMesh,
    origins: &Bound<'_, PyAny>,
    directions: &Bound<'_, PyAny>,
    max_distance: Real,
) -> PyResult<PyMeshRayHits> {
    raycast_with(py, origins, directions, max_distance, |o, d, t| {
        mesh.raycast_batch(o, d, t)
    })
}

/// `heightfield.raycast(origins, directions, max_distance)`, by `HeightField::raycast`.
pub fn raycast_heightfield(
    py: Python<'_>,
    hf: &HeightField,
    origins: &Bound<'_, PyAny>,
    directions: &Bound<'_, PyAny>,
    max_distance: Real,
) -> PyResult<PyMeshRayHits> {
    raycast_with(py, origins, directions, max_distance, |o, d, t| {
        let pairs: Vec<(Vec3, Vec3)> = o.iter().copied().zip(d.iter().copied()).collect();
        Ok(batch::map(&pairs, |(o, d)| hf.raycast(*o, *d, t)))
    })
}

fn hits_out(py: Python<'_>, hits: &[Option<MeshRayHit>]) -> PyMeshRayHits {
    let nan = Vec3::splat(Real::NAN);
    let points: Vec<Vec3> = hits.iter().map(|h| h.map_or(nan, |h| h.point)).collect();
    let normals: Vec<Vec3> = hits.iter().map(|h| h.map_or(nan, |h| h.normal)).collect();
    let bary: Vec<Vec3> = hits
        .iter()
        .map(|h| h.map_or(nan, |h| Vec3::from(h.barycentric)))
        .collect();
    PyMeshRayHits {
        hit: PyArray1::from_vec(py, hits.iter().map(Option::is_some).collect()).unbind(),
        distance: PyArray1::from_vec(
            py,
            hits.iter()
                .map(|h| h.map_or(f64::NAN, |h| f64::from(h.t)))
                .collect(),
        )
        .unbind(),
        point: vec3s_out(py, &points).unbind(),
        normal: vec3s_out(py, &normals).unbind(),
        triangle: PyArray1::from_vec(
            py,
            hits.iter()
                .map(|h| h.map_or(-1, |h| i64::from(h.triangle)))
                .collect(),
        )
        .unbind(),
        barycentric: vec3s_out(py, &bary).unbind(),
    }
}

/// `mesh.closest_points(points, max_distance)`: `(points (N, 3), distances (N,),
/// triangles (N,))`.
pub fn closest_points<'py>(
    py: Python<'py>,
    mesh: &TriMesh,
    points: &Bound<'py, PyAny>,
    max_distance: Real,
) -> PyResult<Bound<'py, PyTuple>> {
    closest_points_with(py, points, max_distance, |pts, md| {
        mesh.closest_point_batch(pts, md)
    })
}

/// `heightfield.closest_points(points, max_distance)`, by `HeightField::closest_point`.
pub fn closest_points_heightfield<'py>(
    py: Python<'py>,
    hf: &HeightField,
    points: &Bound<'py, PyAny>,
    max_distance: Real,
) -> PyResult<Bound<'py, PyTuple>> {
    closest_points_with(py, points, max_distance, |pts, md| {
        batch::map(pts, |p| hf.closest_point(*p, md))
    })
}

/// Batch closest points with `query(points, max_distance)` (GIL released) as the
/// `(points, distances, triangles)` tuple.
fn closest_points_with<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    max_distance: Real,
    query: impl Fn(&[Vec3], Real) -> Vec<Option<MeshPointProjection>> + Send + Sync,
) -> PyResult<Bound<'py, PyTuple>> {
    check_max_distance(max_distance)?;
    let (pts, _) = vec3s(points, "points", true)?;
    require_finite("points", &pts)?;
    let res = py.detach(|| guard(|| Ok(query(&pts, max_distance))))?;
    let nan = Vec3::splat(Real::NAN);
    let cp: Vec<Vec3> = res.iter().map(|r| r.map_or(nan, |r| r.point)).collect();
    let dist: Vec<f64> = res
        .iter()
        .map(|r| r.map_or(f64::NAN, |r| f64::from(r.distance)))
        .collect();
    let tri: Vec<i64> = res
        .iter()
        .map(|r| r.map_or(-1, |r| i64::from(r.triangle)))
        .collect();
    PyTuple::new(
        py,
        [
            vec3s_out(py, &cp).into_any(),
            PyArray1::from_vec(py, dist).into_any(),
            PyArray1::from_vec(py, tri).into_any(),
        ],
    )
}

/// The box `[aabb_min, aabb_max]` (finite, `aabb_min <= aabb_max`).
pub fn aabb_arg(aabb_min: &Bound<'_, PyAny>, aabb_max: &Bound<'_, PyAny>) -> PyResult<Aabb> {
    let lo = vec3(aabb_min, "aabb_min")?;
    let hi = vec3(aabb_max, "aabb_max")?;
    require_finite("aabb_min", &[lo])?;
    require_finite("aabb_max", &[hi])?;
    if !lo.cmple(hi).all() {
        return Err(invalid("aabb_min must be <= aabb_max in every component"));
    }
    Ok(Aabb::new(lo, hi))
}

/// Ascending int64 indices of the items (triangles, children) whose boxes overlap the box
/// `[aabb_min, aabb_max]`, by `query`.
pub fn overlapping<'py>(
    py: Python<'py>,
    aabb_min: &Bound<'py, PyAny>,
    aabb_max: &Bound<'py, PyAny>,
    query: impl FnOnce(&Aabb) -> Vec<u32>,
) -> PyResult<Bound<'py, PyArray1<i64>>> {
    let aabb = aabb_arg(aabb_min, aabb_max)?;
    let items = guard(|| Ok(query(&aabb)))?;
    Ok(indices_out(py, &items))
}

fn mesh_of<'a>(slf: &'a Bound<'_, PyTriMesh>) -> PyResult<&'a TriMesh> {
    match shape_of(slf) {
        Shape::TriMesh(m) => Ok(m),
        _ => Err(wrong_kind("TriMesh")),
    }
}

/// A triangle mesh: `vertices` `(V, 3)` (finite) and `indices` `(T, 3)` integers in
/// `[0, V)`, counter-clockwise triangles. With `weld_tolerance` (finite, >= 0), vertices
/// closer than it are merged first (0 merges exact duplicates), so split meshes get their
/// edge adjacency. Volume and mass are those of the enclosed solid for a closed,
/// outward-oriented mesh. Not convex: no support map. Degenerate triangles are kept and
/// never give NaN. Out-of-range indices, non-finite vertices and empty meshes raise
/// `CaromError`.
#[pyclass(name = "TriMesh", module = "carom", extends = PyShape, frozen)]
pub struct PyTriMesh;

#[pymethods]
impl PyTriMesh {
    #[new]
    #[pyo3(signature = (vertices, indices, weld_tolerance = None))]
    fn new(
        vertices: &Bound<'_, PyAny>,
        indices: &Bound<'_, PyAny>,
        weld_tolerance: Option<f64>,
    ) -> PyResult<PyClassInitializer<Self>> {
        let (verts, _) = vec3s(vertices, "vertices", false)?;
        let tris = index_triples(indices, "indices")?;
        let options = TriMeshOptions {
            weld_tolerance: weld_tolerance
                .map(|t| scalar("weld_tolerance", t))
                .transpose()?,
            ..Default::default()
        };
        let mesh = core(|| TriMesh::with_options(verts, tris, options))?;
        Ok(init(mesh.into(), PyTriMesh))
    }

    /// The vertices, `(V, 3)`.
    #[getter]
    fn vertices<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        match shape_of(slf) {
            Shape::TriMesh(m) => Ok(vec3s_out(slf.py(), m.vertices())),
            _ => Err(wrong_kind("TriMesh")),
        }
    }

    /// The triangles as vertex indices, `(T, 3)` int64.
    #[getter]
    fn indices<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        match shape_of(slf) {
            Shape::TriMesh(m) => Ok(triples_out(slf.py(), m.indices())),
            _ => Err(wrong_kind("TriMesh")),
        }
    }

    /// Loads a mesh from a `.obj` or `.stl` file (by extension, case-insensitive; OBJ
    /// polygons are triangulated, STL duplicate vertices merged). With `weld_tolerance`
    /// (finite, >= 0), vertices closer than it are merged as in the constructor. Unreadable
    /// or malformed files and a bad tolerance raise `CaromError`.
    #[staticmethod]
    #[pyo3(signature = (path, weld_tolerance = None))]
    fn load(
        py: Python<'_>,
        path: std::path::PathBuf,
        weld_tolerance: Option<f64>,
    ) -> PyResult<Bound<'_, PyAny>> {
        let options = TriMeshOptions {
            weld_tolerance: weld_tolerance
                .map(|t| scalar("weld_tolerance", t))
                .transpose()?,
            ..Default::default()
        };
        let mesh = py.detach(move || core(|| TriMesh::load_with_options(&path, options)))?;
        wrap_shape(py, Arc::new(mesh.into()))
    }

    /// A mesh from the bytes of an OBJ file (default options).
    #[staticmethod]
    fn from_obj_bytes<'py>(py: Python<'py>, data: &[u8]) -> PyResult<Bound<'py, PyAny>> {
        let mesh = core(|| TriMesh::from_obj_bytes(data, TriMeshOptions::default()))?;
        wrap_shape(py, Arc::new(mesh.into()))
    }

    /// A mesh from the bytes of an STL file, ASCII or binary (default options).
    #[staticmethod]
    fn from_stl_bytes<'py>(py: Python<'py>, data: &[u8]) -> PyResult<Bound<'py, PyAny>> {
        let mesh = core(|| TriMesh::from_stl_bytes(data, TriMeshOptions::default()))?;
        wrap_shape(py, Arc::new(mesh.into()))
    }

    /// Closest hits of rays in the mesh's own frame: `origins` and `directions` `(N, 3)`
    /// (finite; directions non-zero, normalised here), up to `max_distance` (>= 0). Returns
    /// a `MeshRayHits` (`hit`, `distance`, `point`, `normal`, `triangle`, arrays of length
    /// N). Uses the BVH, releases the GIL and runs in parallel.
    #[pyo3(signature = (origins, directions, max_distance = f64::INFINITY))]
    fn raycast(
        slf: &Bound<'_, Self>,
        origins: &Bound<'_, PyAny>,
        directions: &Bound<'_, PyAny>,
        max_distance: f64,
    ) -> PyResult<PyMeshRayHits> {
        let Shape::TriMesh(m) = shape_of(slf) else {
            return Err(wrong_kind("TriMesh"));
        };
        let md = scalar("max_distance", max_distance)?;
        raycast(slf.py(), m, origins, directions, md)
    }

    /// Closest points of the mesh (its surface, in its own frame) to `points` `(N, 3)`
    /// within `max_distance`: `(points (N, 3), distances (N,), triangles (N,) int64)`, NaN
    /// and -1 where no triangle is within `max_distance`. Releases the GIL.
    #[pyo3(signature = (points, max_distance = f64::INFINITY))]
    fn closest_points<'py>(
        slf: &Bound<'py, Self>,
        points: &Bound<'py, PyAny>,
        max_distance: f64,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let Shape::TriMesh(m) = shape_of(slf) else {
            return Err(wrong_kind("TriMesh"));
        };
        let md = scalar("max_distance", max_distance)?;
        closest_points(slf.py(), m, points, md)
    }

    /// Indices (ascending int64) of the triangles whose bounding boxes overlap the box
    /// `[aabb_min, aabb_max]` (mesh frame).
    fn overlapping_triangles<'py>(
        slf: &Bound<'py, Self>,
        aabb_min: &Bound<'py, PyAny>,
        aabb_max: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let Shape::TriMesh(m) = shape_of(slf) else {
            return Err(wrong_kind("TriMesh"));
        };
        overlapping(slf.py(), aabb_min, aabb_max, |b| m.overlapping_triangles(b))
    }

    /// Some hit per ray (the first the BVH walk finds, not necessarily the closest), for
    /// occlusion tests: same arguments and `MeshRayHits` as `raycast`; `hit` is exact.
    #[pyo3(signature = (origins, directions, max_distance = f64::INFINITY))]
    fn raycast_any(
        slf: &Bound<'_, Self>,
        origins: &Bound<'_, PyAny>,
        directions: &Bound<'_, PyAny>,
        max_distance: f64,
    ) -> PyResult<PyMeshRayHits> {
        let m = mesh_of(slf)?;
        let md = scalar("max_distance", max_distance)?;
        raycast_with(slf.py(), origins, directions, md, |o, d, t| {
            let pairs: Vec<(Vec3, Vec3)> = o.iter().copied().zip(d.iter().copied()).collect();
            Ok(batch::map(&pairs, |(o, d)| m.raycast_any(*o, *d, t)))
        })
    }

    /// Every hit of one ray (`origin`, `direction` `(3,)`, direction normalised here) up to
    /// `max_distance`, as a `MeshRayHits` with one row per hit, sorted by distance then
    /// triangle (all `hit` true; no rows when the ray misses).
    #[pyo3(signature = (origin, direction, max_distance = f64::INFINITY))]
    fn raycast_all(
        slf: &Bound<'_, Self>,
        origin: &Bound<'_, PyAny>,
        direction: &Bound<'_, PyAny>,
        max_distance: f64,
    ) -> PyResult<PyMeshRayHits> {
        let m = mesh_of(slf)?;
        let md = scalar("max_distance", max_distance)?;
        check_max_distance(md)?;
        let o = vec3(origin, "origin")?;
        let d = vec3(direction, "direction")?;
        let (o, d) = rays_checked(vec![o], vec![d], ("origin", "direction"))?;
        let hits = guard(|| Ok(m.raycast_all(o[0], d[0], md)))?;
        let hits: Vec<Option<MeshRayHit>> = hits.into_iter().map(Some).collect();
        Ok(hits_out(slf.py(), &hits))
    }

    /// The mesh with its vertices moved to `vertices` `(V, 3)` (same count, same triangles):
    /// the BVH is refitted, not rebuilt (deforming meshes), and the edge angles recomputed;
    /// queries equal those of a freshly built mesh. Shapes are immutable, so this returns a
    /// new `TriMesh` and leaves this one (and any world holding it) unchanged.
    fn with_vertices<'py>(
        slf: &Bound<'py, Self>,
        vertices: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (verts, _) = vec3s(vertices, "vertices", false)?;
        let mut m = mesh_of(slf)?.clone();
        slf.py().detach(|| core(|| m.set_vertices(verts)))?;
        wrap_shape(slf.py(), Arc::new(m.into()))
    }

    /// Triangle index pairs `(i, j)` as an `(N, 2)` int64 array, sorted, where triangle `i`
    /// of this mesh and triangle `j` of `other` (placed at `pose`, its pose in this mesh's
    /// frame; default identity) have overlapping bounding boxes in this mesh's frame (the
    /// box of `j` taken after moving its corners), found by descending both BVHs together.
    #[pyo3(signature = (other, pose = None))]
    fn overlapping_triangle_pairs<'py>(
        slf: &Bound<'py, Self>,
        other: &Bound<'py, PyTriMesh>,
        pose: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray2<i64>>> {
        let (a, b) = (mesh_of(slf)?, mesh_of(other)?);
        let pose = extract_isometry(pose, "pose")?;
        let pairs = slf
            .py()
            .detach(|| guard(|| Ok(a.triangle_pairs(b, &pose))))?;
        Ok(Array2::from_shape_fn((pairs.len(), 2), |(i, j)| {
            i64::from(if j == 0 { pairs[i].0 } else { pairs[i].1 })
        })
        .into_pyarray(slf.py()))
    }

    /// Signed dihedral angle (radians) across each triangle edge, `(T, 3)` float64: edge
    /// `k` runs from corner `k` to corner `k + 1`; positive for convex edges, negative for
    /// concave ones, 0 for boundary edges (see `edge_neighbors`). Precomputed at
    /// construction for internal-edge correction of contacts.
    #[getter]
    fn edge_angles<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let e = mesh_of(slf)?.edges();
        Ok(
            Array2::from_shape_fn((e.len(), 3), |(i, k)| f64::from(e[i][k].angle))
                .into_pyarray(slf.py()),
        )
    }

    /// The triangle across each edge, `(T, 3)` int64 (edge `k` from corner `k` to `k + 1`),
    /// -1 on boundary edges (one triangle, or more than two sharing the edge).
    #[getter]
    fn edge_neighbors<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        let e = mesh_of(slf)?.edges();
        Ok(Array2::from_shape_fn((e.len(), 3), |(i, k)| {
            let n = e[i][k].neighbor;
            if n == NO_NEIGHBOR {
                -1
            } else {
                i64::from(n)
            }
        })
        .into_pyarray(slf.py()))
    }

    /// Number of triangles.
    #[getter]
    fn num_triangles(slf: &Bound<'_, Self>) -> PyResult<usize> {
        match shape_of(slf) {
            Shape::TriMesh(m) => Ok(m.num_triangles()),
            _ => Err(wrong_kind("TriMesh")),
        }
    }
}
