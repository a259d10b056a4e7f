//! The shape classes built from many parts: `carom.ConvexHull`, `carom.TriMesh`,
//! `carom.Compound` and `carom.Scaled`.
//!
//! Each constructor is the one place its core constructor is called.

use crate::convert::{
    array_values, float_array, indices_out, scalar, shape_str, to_real, triples_out, vec3_out,
    vec3s, vec3s_out,
};
use crate::errors::{carom_err, core, invalid};
/// `carom.TriMesh` lives with the other mesh bindings in `mesh.rs`.
pub use crate::mesh::PyTriMesh;
use crate::pose::{extract_isometry, Pose64, PyPose};
use crate::serialize::hull_problem;
use crate::shape::{scale_factors, PyShape};
use crate::shapes::{init, shape_of, wrap_shape, wrong_kind};
use carom_collision::math::Isometry;
use carom_collision::shape::{Compound, ConvexHull, HeightField, Scaled, Shape};
use carom_collision::CaromError;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyList, PyTuple};
use std::sync::Arc;

/// The convex hull of `points` `(N, 3)`: at least 4 finite points spanning a 3D volume
/// (coplanar or collinear points raise `CaromError`). Duplicate and interior points are
/// dropped; coplanar triangles are merged into polygonal faces. No margin.
#[pyclass(name = "ConvexHull", module = "carom", extends = PyShape, frozen)]
pub struct PyConvexHull;

fn hull_of(slf: &Bound<'_, PyConvexHull>) -> PyResult<ConvexHull> {
    match shape_of(slf) {
        Shape::ConvexHull(h) => Ok(h.clone()),
        _ => Err(wrong_kind("ConvexHull")),
    }
}

#[pymethods]
impl PyConvexHull {
    #[new]
    fn new(py: Python<'_>, points: &Bound<'_, PyAny>) -> PyResult<PyClassInitializer<Self>> {
        let (pts, _) = vec3s(points, "points", false)?;
        let hull = py.detach(move || core(|| ConvexHull::new(&pts)))?;
        // Guard against degenerate hulls the core builder lets through (nearly coplanar
        // points far from the origin can give a hull without faces or volume).
        if let Some(reason) = hull_problem(&hull) {
            return Err(carom_err(CaromError::degenerate(
                "convex hull",
                format!(
                    "the points are (nearly) coplanar or collinear for this precision: {reason}"
                ),
            )));
        }
        Ok(init(hull.into(), PyConvexHull))
    }

    /// The hull's vertices, `(V, 3)` (only points on the hull).
    #[getter]
    fn vertices<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        match shape_of(slf) {
            Shape::ConvexHull(h) => Ok(vec3s_out(slf.py(), h.vertices())),
            _ => Err(wrong_kind("ConvexHull")),
        }
    }

    /// The polygonal faces: a list of int64 arrays of vertex indices, each loop
    /// counter-clockwise seen from outside.
    #[getter]
    fn faces<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyList>> {
        let h = hull_of(slf)?;
        let loops: Vec<Bound<'py, PyArray1<i64>>> = (0..h.faces().len())
            .map(|f| indices_out(slf.py(), h.face_vertices(f)))
            .collect();
        PyList::new(slf.py(), loops)
    }

    /// A triangulation of the faces, `(T, 3)` int64, counter-clockwise from outside.
    #[getter]
    fn triangles<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        match shape_of(slf) {
            Shape::ConvexHull(h) => Ok(triples_out(slf.py(), h.triangles())),
            _ => Err(wrong_kind("ConvexHull")),
        }
    }
}

/// A heightfield over the local XZ plane, Y up, for static bodies: `heights` `(rows, cols)`
/// (finite, each at least 2), sample `(r, c)` at
/// `(c dx - (cols - 1) dx / 2, heights[r, c], r dz - (rows - 1) dz / 2)` (rows along Z,
/// columns along X, centred on the origin in X and Z), `cell_size` `(dx, dz)` finite and > 0.
/// Cell `(r, c)` holds triangles `2 (r (cols - 1) + c)` and `+ 1`, facing +Y. Not convex, no
/// volume or mass.
#[pyclass(name = "HeightField", module = "carom", extends = PyShape, frozen)]
pub struct PyHeightField;

fn heightfield_of(slf: &Bound<'_, PyHeightField>) -> PyResult<HeightField> {
    match shape_of(slf) {
        Shape::HeightField(h) => Ok(h.clone()),
        _ => Err(wrong_kind("HeightField")),
    }
}

#[pymethods]
impl PyHeightField {
    #[new]
    #[pyo3(signature = (heights, cell_size = (1.0, 1.0)))]
    fn new(
        heights: &Bound<'_, PyAny>,
        cell_size: (f64, f64),
    ) -> PyResult<PyClassInitializer<Self>> {
        let (shape, values) = array_values(&float_array(heights, "heights")?)?;
        let [rows, cols] = shape.as_slice() else {
            return Err(invalid(format!(
                "heights must have shape (rows, cols), got {}",
                shape_str(&shape)
            )));
        };
        let (rows, cols) = (*rows, *cols);
        let hs = values
            .iter()
            .enumerate()
            .map(|(i, &h)| to_real(&|| format!("heights[{}, {}]", i / cols, i % cols), h))
            .collect::<PyResult<Vec<_>>>()?;
        let dx = scalar("cell_size[0]", cell_size.0)?;
        let dz = scalar("cell_size[1]", cell_size.1)?;
        Ok(init(
            core(|| HeightField::new(rows, cols, hs, dx, dz))?.into(),
            PyHeightField,
        ))
    }

    /// The heights, `(rows, cols)` (rows along Z, columns along X).
    #[getter]
    fn heights<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let h = heightfield_of(slf)?;
        let (rows, cols) = (h.rows(), h.cols());
        let hs = h.heights();
        Ok(
            Array2::from_shape_fn((rows, cols), |(r, c)| f64::from(hs[r * cols + c]))
                .into_pyarray(slf.py()),
        )
    }

    /// The cell sizes `(dx, dz)` along X and Z.
    #[getter]
    fn cell_size(slf: &Bound<'_, Self>) -> PyResult<(f64, f64)> {
        let (dx, dz) = heightfield_of(slf)?.cell_size();
        Ok((f64::from(dx), f64::from(dz)))
    }

    /// Closest hits of rays in the heightfield's own frame (a 2D walk over the cells the ray
    /// crosses): same arguments and `MeshRayHits` result as `TriMesh.raycast`, with the
    /// triangle numbering of the class docstring.
    #[pyo3(signature = (origins, directions, max_distance = f64::INFINITY))]
    fn raycast(
        slf: &Bound<'_, Self>,
        origins: &Bound<'_, PyAny>,
        directions: &Bound<'_, PyAny>,
        max_distance: f64,
    ) -> PyResult<crate::mesh::PyMeshRayHits> {
        let Shape::HeightField(h) = shape_of(slf) else {
            return Err(wrong_kind("HeightField"));
        };
        let md = scalar("max_distance", max_distance)?;
        crate::mesh::raycast_heightfield(slf.py(), h, origins, directions, md)
    }

    /// Closest points of the heightfield's surface (its own frame) to `points` `(N, 3)`
    /// within `max_distance`: `(points (N, 3), distances (N,), triangles (N,) int64)`, NaN
    /// and -1 where no triangle is within `max_distance`, as `TriMesh.closest_points`.
    #[pyo3(signature = (points, max_distance = f64::INFINITY))]
    fn closest_points<'py>(
        slf: &Bound<'py, Self>,
        points: &Bound<'py, PyAny>,
        max_distance: f64,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let Shape::HeightField(h) = shape_of(slf) else {
            return Err(wrong_kind("HeightField"));
        };
        let md = scalar("max_distance", max_distance)?;
        crate::mesh::closest_points_heightfield(slf.py(), h, points, md)
    }

    /// Indices (ascending int64) of the triangles whose bounding boxes overlap the box
    /// `[aabb_min, aabb_max]` (heightfield frame).
    fn overlapping_triangles<'py>(
        slf: &Bound<'py, Self>,
        aabb_min: &Bound<'py, PyAny>,
        aabb_max: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let Shape::HeightField(h) = shape_of(slf) else {
            return Err(wrong_kind("HeightField"));
        };
        crate::mesh::overlapping(slf.py(), aabb_min, aabb_max, |b| h.triangles_in_aabb(b))
    }

    /// Number of triangles, `2 (rows - 1) (cols - 1)`.
    #[getter]
    fn num_triangles(slf: &Bound<'_, Self>) -> PyResult<usize> {
        Ok(heightfield_of(slf)?.num_triangles())
    }
}

/// A rigid assembly of child shapes: `children` is a non-empty sequence of
/// `(shape, pose)` pairs (a pose is a `Pose`, a `(7,)` array or `None`; a bare shape means
/// the identity pose). Planes cannot be children. Volume and mass sum the children
/// (overlaps count twice).
#[pyclass(name = "Compound", module = "carom", extends = PyShape, frozen)]
pub struct PyCompound;

fn type_name(obj: &Bound<'_, PyAny>) -> String {
    match obj.get_type().name() {
        Ok(n) => n.to_string(),
        Err(_) => "object".to_string(),
    }
}

fn child(i: usize, item: &Bound<'_, PyAny>) -> PyResult<(Isometry, Arc<Shape>)> {
    if let Ok(s) = item.cast::<PyShape>() {
        return Ok((Isometry::IDENTITY, s.get().inner.clone()));
    }
    let pair = item
        .cast::<PyTuple>()
        .map(|t| t.as_any().clone())
        .or_else(|_| item.cast::<PyList>().map(|l| l.as_any().clone()));
    let pair = match pair {
        Ok(p) if p.len()? == 2 => p,
        _ => {
            return Err(PyTypeError::new_err(format!(
                "children[{i}] must be a (shape, pose) pair, got {}",
                type_name(item)
            )))
        }
    };
    let shape = pair.get_item(0)?;
    let shape = shape.cast::<PyShape>().map_err(|_| {
        PyTypeError::new_err(format!(
            "children[{i}][0] must be a carom.Shape, got {}",
            type_name(&shape)
        ))
    })?;
    let pose = extract_isometry(Some(&pair.get_item(1)?), &format!("children[{i}].pose"))?;
    Ok((pose, shape.get().inner.clone()))
}

fn compound_of<'a>(slf: &'a Bound<'_, PyCompound>) -> PyResult<&'a Compound> {
    match shape_of(slf) {
        Shape::Compound(c) => Ok(c),
        _ => Err(wrong_kind("Compound")),
    }
}

/// A checked child index: negative or too large raises `CaromError` naming it.
fn child_index(slf: &Bound<'_, PyCompound>, index: i64) -> PyResult<u32> {
    let n = compound_of(slf)?.children().len();
    match u32::try_from(index) {
        Ok(i) if (i as usize) < n => Ok(i),
        _ => Err(invalid(format!(
            "invalid index = {index}: must be in [0, {n}) for a compound of {n} children"
        ))),
    }
}

/// Copy-on-write edit: a new `Compound` from a copy of this one changed by `edit`; on an
/// error nothing is created and this one is untouched.
fn edited<'py>(
    slf: &Bound<'py, PyCompound>,
    edit: impl FnOnce(&mut Compound) -> carom_collision::Result<()>,
) -> PyResult<Bound<'py, PyAny>> {
    let mut c = compound_of(slf)?.clone();
    core(|| edit(&mut c))?;
    wrap_shape(slf.py(), Arc::new(c.into()))
}

#[pymethods]
impl PyCompound {
    #[new]
    fn new(children: &Bound<'_, PyAny>) -> PyResult<PyClassInitializer<Self>> {
        let iter = children.try_iter().map_err(|_| {
            PyTypeError::new_err(format!(
                "children must be a sequence of (shape, pose) pairs, got {}",
                type_name(children)
            ))
        })?;
        let mut parts = Vec::new();
        for (i, item) in iter.enumerate() {
            parts.push(child(i, &item?)?);
        }
        Ok(init(core(|| Compound::new(parts))?.into(), PyCompound))
    }

    /// Indices (ascending int64) of the children whose bounding boxes overlap the box
    /// `[aabb_min, aabb_max]` (compound frame), found with the children's BVH.
    fn overlapping_children<'py>(
        slf: &Bound<'py, Self>,
        aabb_min: &Bound<'py, PyAny>,
        aabb_max: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let Shape::Compound(c) = shape_of(slf) else {
            return Err(wrong_kind("Compound"));
        };
        crate::mesh::overlapping(slf.py(), aabb_min, aabb_max, |b| c.children_in_aabb(b))
    }

    /// Child index pairs `(i, j)` as an `(N, 2)` int64 array, sorted, where child `i` of
    /// this compound and child `j` of `other` (placed at `pose`, its pose in this
    /// compound's frame; default identity) have overlapping bounding boxes, found by
    /// descending both children's dynamic trees together.
    #[pyo3(signature = (other, pose=None))]
    fn overlapping_child_pairs<'py>(
        slf: &Bound<'py, Self>,
        other: &Bound<'py, PyCompound>,
        pose: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray2<i64>>> {
        let (Shape::Compound(a), Shape::Compound(b)) = (shape_of(slf), shape_of(other)) else {
            return Err(wrong_kind("Compound"));
        };
        let pose = extract_isometry(pose, "pose")?;
        let pairs = a.child_pairs(b, &pose);
        Ok(Array2::from_shape_fn((pairs.len(), 2), |(i, j)| {
            i64::from(if j == 0 { pairs[i].0 } else { pairs[i].1 })
        })
        .into_pyarray(slf.py()))
    }

    /// Number of children.
    #[getter]
    fn num_children(slf: &Bound<'_, Self>) -> PyResult<usize> {
        Ok(compound_of(slf)?.children().len())
    }

    /// A new compound with `shape` added at `pose` (a `Pose`, a `(7,)` array or `None` for
    /// the identity) as the last child, index `num_children`. Shapes are immutable: this
    /// compound, and any world or compound already holding it, is unchanged (the children
    /// list is copied, O(children); child geometry is shared, not copied). Bad input raises
    /// (`CaromError` for a bad pose or a plane, `TypeError` for a non-shape).
    #[pyo3(signature = (shape, pose = None))]
    fn with_child<'py>(
        slf: &Bound<'py, Self>,
        shape: &Bound<'py, PyAny>,
        pose: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let shape = shape.cast::<PyShape>().map_err(|_| {
            PyTypeError::new_err(format!(
                "shape must be a carom.Shape, got {}",
                type_name(shape)
            ))
        })?;
        let pose = extract_isometry(pose, "pose")?;
        let inner = shape.get().inner.clone();
        edited(slf, |c| c.add_child(pose, inner).map(|_| ()))
    }

    /// A new compound without child `index` (0 <= index < num_children); as in the Rust
    /// `Compound::remove_child`, the last child takes its index. The only child cannot be
    /// removed. This compound is unchanged (see `with_child`).
    fn without_child<'py>(
        slf: &Bound<'py, Self>,
        #[pyo3(from_py_with = crate::convert::int_arg::<i64>)] index: i64,
    ) -> PyResult<Bound<'py, PyAny>> {
        let i = child_index(slf, index)?;
        edited(slf, |c| c.remove_child(i).map(|_| ()))
    }

    /// A new compound with child `index` moved to `pose` (compound frame); its tree leaf is
    /// moved, the other children keep their indices. This compound is unchanged (see
    /// `with_child`).
    fn with_child_pose<'py>(
        slf: &Bound<'py, Self>,
        #[pyo3(from_py_with = crate::convert::int_arg::<i64>)] index: i64,
        pose: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let i = child_index(slf, index)?;
        let pose = extract_isometry(Some(pose), "pose")?;
        edited(slf, |c| c.set_child_pose(i, pose))
    }

    /// The children as a list of `(shape, Pose)` pairs (poses at the core's precision,
    /// see `carom.REAL_BITS`).
    #[getter]
    fn children<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyList>> {
        let py = slf.py();
        let Shape::Compound(c) = shape_of(slf) else {
            return Err(wrong_kind("Compound"));
        };
        let mut out = Vec::with_capacity(c.children().len());
        for (pose, shape) in c.children() {
            let s = wrap_shape(py, shape.clone())?;
            let p = Bound::new(py, PyPose::new_py(Pose64::from_isometry(pose)))?;
            out.push(PyTuple::new(py, [s, p.into_any()])?);
        }
        PyList::new(py, out)
    }
}

/// A convex shape scaled along its local axes: `Scaled(shape, factors)` is
/// `shape.scaled(factors)` (factors a scalar or `(3,)`, finite, non-zero; negative factors
/// mirror). The support map and mass properties are exact; no margin.
#[pyclass(name = "Scaled", module = "carom", extends = PyShape, frozen)]
pub struct PyScaled;

#[pymethods]
impl PyScaled {
    #[new]
    fn new(
        shape: &Bound<'_, PyAny>,
        factors: &Bound<'_, PyAny>,
    ) -> PyResult<PyClassInitializer<Self>> {
        let inner = shape.cast::<PyShape>().map_err(|_| {
            PyTypeError::new_err(format!(
                "shape must be a carom.Shape, got {}",
                type_name(shape)
            ))
        })?;
        let scale = scale_factors(factors)?;
        let inner = inner.get().inner.clone();
        Ok(init(core(|| Scaled::new(inner, scale))?.into(), PyScaled))
    }

    /// The shape being scaled.
    #[getter]
    fn inner<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        match shape_of(slf) {
            Shape::Scaled(s) => wrap_shape(slf.py(), s.inner().clone()),
            _ => Err(wrong_kind("Scaled")),
        }
    }

    /// The scale factors, `(3,)`.
    #[getter]
    fn scale<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        match shape_of(slf) {
            Shape::Scaled(s) => Ok(vec3_out(slf.py(), s.scale())),
            _ => Err(wrong_kind("Scaled")),
        }
    }
}
