//! Triangle-mesh queries in the mesh's own frame (`TriMesh.raycast`, `closest_points`,
//! `overlapping_triangles`, and the same on heightfields and compounds), thin wrappers of the core's BVH queries
//! (`carom_collision::shape::TriMesh`); batches release the GIL and run in parallel.

use crate::batch;
use crate::convert::{indices_out, require_finite, vec3, vec3s, vec3s_out};
use crate::errors::{carom_err, guard, invalid};
use carom_collision::math::{vec3_to_f64, Aabb, Real, Vec3};
use carom_collision::midphase::MeshRayHit;
use carom_collision::shape::{HeightField, TriMesh};
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyTuple;

/// Closest ray hits on a mesh, one row per ray: `hit` `(N,)` bool, `distance` `(N,)` along
/// the unit direction, `point` `(N, 3)`, `normal` `(N, 3)` (the triangle's counter-clockwise
/// face normal, not flipped towards the ray) and `triangle` `(N,)` int64; misses hold NaN
/// and triangle -1. In the mesh's own frame.
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
}

/// Rays from `(N, 3)` arrays (or `(3,)` for one ray): finite origins, non-zero finite
/// directions, normalised.
fn rays(
    origins: &Bound<'_, PyAny>,
    directions: &Bound<'_, PyAny>,
) -> PyResult<(Vec<Vec3>, Vec<Vec3>)> {
    let (o, _) = vec3s(origins, "origins", true)?;
    let (d, _) = vec3s(directions, "directions", true)?;
    if o.len() != d.len() {
        return Err(invalid(format!(
            "origins and directions must have the same length, got {} and {}",
            o.len(),
            d.len()
        )));
    }
    require_finite("origins", &o)?;
    require_finite("directions", &d)?;
    let mut unit = Vec::with_capacity(d.len());
    for (i, v) in d.iter().enumerate() {
        match v.try_normalize() {
            Some(u) => unit.push(u),
            None => {
                return Err(invalid(format!(
                    "invalid directions[{i}] = {:?}: must be non-zero",
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
    check_max_distance(max_distance)?;
    let (pts, _) = vec3s(points, "points", true)?;
    require_finite("points", &pts)?;
    let res = py.detach(|| guard(|| Ok(mesh.closest_point_batch(&pts, max_distance))))?;
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
