//! `carom.Shape`: the base class of every shape, with the queries all shapes share.
//!
//! Each Python shape wraps an `Arc<carom_collision::shape::Shape>`; the subclasses
//! (`carom.Sphere`, `carom.Box`, ...) in `shapes.rs` add constructors and read-only
//! properties.

use crate::batch;
use crate::convert::{
    aabb_out, array_values, float_array, mat3_out, require_finite, scalar, shape_str, vec3_from,
    vec3_out, vec3s, vec3s_or_single_out, vec3s_out,
};
use crate::errors::{core, guard, invalid};
use crate::pose::{extract_isometry, extract_poses};
use crate::serialize;
use crate::shapes::{kind_str, repr_shape, wrap_shape};
use carom_collision::math::Vec3;
use carom_collision::shape::Shape;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyBytes, PyTuple, PyType};
use std::hash::{Hash, Hasher};
use std::sync::Arc;

/// Base class of all Carom shapes (`isinstance(s, carom.Shape)`). Shapes are immutable,
/// compare by value, hash, pickle, and are cheap to share (the geometry is reference
/// counted). Capsules, cylinders and cones lie along the local **Y** axis.
///
/// Construct a concrete shape (`carom.Sphere`, `carom.Box`, ...); `Shape` itself has no
/// constructor.
#[pyclass(name = "Shape", module = "carom", subclass, frozen)]
pub struct PyShape {
    pub(crate) inner: Arc<Shape>,
}

impl PyShape {
    /// Wraps a core shape.
    pub fn new_base(shape: Shape) -> Self {
        PyShape {
            inner: Arc::new(shape),
        }
    }

    fn support_impl<'py>(
        &self,
        py: Python<'py>,
        directions: &Bound<'py, PyAny>,
        pose: Option<&Bound<'py, PyAny>>,
        core_only: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let what = if core_only { "support_core" } else { "support" };
        core(|| self.inner.require_convex(what).map(|_| ()))?;
        let (dirs, single) = vec3s(directions, "directions", true)?;
        require_finite("directions", &dirs)?;
        let pose = match pose {
            Some(p) if !p.is_none() => Some(extract_isometry(Some(p), "pose")?),
            _ => None,
        };
        let shape = self.inner.clone();
        let points = if dirs.len() >= batch::PARALLEL_MIN {
            py.detach(move || core(|| batch::support_points(&shape, &dirs, pose, core_only)))?
        } else {
            core(|| batch::support_points(&shape, &dirs, pose, core_only))?
        };
        Ok(vec3s_or_single_out(py, &points, single))
    }
}

#[pymethods]
impl PyShape {
    /// The kind of shape: `"sphere"`, `"box"`, `"capsule"`, `"cylinder"`, `"cone"`,
    /// `"convex_hull"`, `"triangle"`, `"plane"`, `"trimesh"`, `"heightfield"`, `"compound"` or
    /// `"scaled"`.
    #[getter]
    fn kind(&self) -> &'static str {
        kind_str(&self.inner)
    }

    /// True for shapes with a support map (all but planes, meshes, heightfields and compounds).
    #[getter]
    fn is_convex(&self) -> bool {
        self.inner.is_convex()
    }

    /// Volume (0 for triangles, planes, heightfields and open meshes; compounds sum their
    /// children).
    #[getter]
    fn volume(&self) -> PyResult<f64> {
        guard(|| Ok(f64::from(self.inner.volume())))
    }

    /// Collision margin of a convex shape (the radius for spheres and capsules; a small
    /// margin kept inside boxes, cylinders and cones; 0 for hulls, triangles and scaled
    /// shapes), or `None` for non-convex shapes.
    #[getter]
    fn margin(&self) -> PyResult<Option<f64>> {
        guard(|| Ok(self.inner.margin().map(f64::from)))
    }

    /// Bounding box in the shape's own frame: `(min (3,), max (3,))`.
    #[getter]
    fn local_aabb<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let aabb = guard(|| Ok(self.inner.local_aabb()))?;
        aabb_out(py, &aabb)
    }

    /// World bounding box of the shape placed at `pose` (a `Pose`, a `(7,)` array or `None`
    /// for the identity): `(min (3,), max (3,))`, tight for convex shapes. With `(N, 7)`
    /// poses, `(min (N, 3), max (N, 3))`.
    #[pyo3(signature = (pose = None))]
    fn aabb<'py>(
        &self,
        py: Python<'py>,
        pose: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let (poses, single) = extract_poses(pose, "pose")?;
        let isos = poses
            .iter()
            .map(|p| p.to_isometry("pose"))
            .collect::<PyResult<Vec<_>>>()?;
        let shape = self.inner.clone();
        let boxes = if isos.len() >= batch::PARALLEL_MIN {
            py.detach(move || guard(|| Ok(batch::aabbs(&shape, &isos))))?
        } else {
            guard(|| Ok(batch::aabbs(&shape, &isos)))?
        };
        match (single, boxes.as_slice()) {
            (true, [b]) => aabb_out(py, b),
            _ => {
                let mins: Vec<Vec3> = boxes.iter().map(|b| b.min).collect();
                let maxs: Vec<Vec3> = boxes.iter().map(|b| b.max).collect();
                PyTuple::new(py, [vec3s_out(py, &mins), vec3s_out(py, &maxs)])
            }
        }
    }

    /// Support points of a convex shape: for each direction `d`, a point `p` of the shape
    /// maximising `p · d`. `directions` is `(3,)` (returns `(3,)`) or `(N, 3)` (returns
    /// `(N, 3)`); directions need not be normalised (a zero direction gives some point of the
    /// shape). In the shape's frame, or in the world frame when `pose` is given. Large
    /// batches release the GIL and run in parallel. Non-convex shapes raise `CaromError`.
    #[pyo3(signature = (directions, pose = None))]
    fn support<'py>(
        &self,
        py: Python<'py>,
        directions: &Bound<'py, PyAny>,
        pose: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.support_impl(py, directions, pose, false)
    }

    /// Support points of the core shape, without the margin (the shape is its core swept by
    /// a sphere of radius `margin`): a sphere's core is its centre, a capsule's its segment.
    /// Same arguments and shapes as `support`.
    #[pyo3(signature = (directions, pose = None))]
    fn support_core<'py>(
        &self,
        py: Python<'py>,
        directions: &Bound<'py, PyAny>,
        pose: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.support_impl(py, directions, pose, true)
    }

    /// `(mass, center_of_mass (3,), inertia (3, 3))` for a uniform `density` (> 0): the
    /// centre of mass in the shape's frame and the inertia tensor about the centre of mass,
    /// in the shape's axes. Zero mass for triangles and planes.
    #[pyo3(signature = (density = 1.0))]
    fn mass_properties<'py>(&self, py: Python<'py>, density: f64) -> PyResult<Bound<'py, PyTuple>> {
        let d = scalar("density", density)?;
        let mp = core(|| self.inner.checked_mass_properties(d))?;
        let mass = f64::from(mp.mass).into_pyobject(py)?.into_any();
        PyTuple::new(
            py,
            [
                mass,
                vec3_out(py, mp.center_of_mass).into_any(),
                mat3_out(py, mp.inertia).into_any(),
            ],
        )
    }

    /// This shape scaled by `factors` along its local axes: a scalar or `(3,)`, finite and
    /// non-zero (negative factors mirror). Only convex shapes can be scaled; the result is a
    /// `carom.Scaled` (scaling a scaled shape multiplies the factors).
    fn scaled<'py>(
        &self,
        py: Python<'py>,
        factors: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let scale = scale_factors(factors)?;
        let shape = core(|| self.inner.scaled(scale))?;
        wrap_shape(py, Arc::new(shape))
    }

    /// The shape encoded as bytes (exact; `Shape.from_bytes` decodes it).
    fn to_bytes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let bytes = core(|| serialize::to_bytes(&self.inner))?;
        Ok(PyBytes::new(py, &bytes))
    }

    /// Decodes bytes made by `to_bytes` into a shape of the right class. Corrupted bytes
    /// raise `CaromError`; when called on a subclass (e.g. `Sphere.from_bytes`), bytes of
    /// another kind of shape are rejected too.
    #[classmethod]
    fn from_bytes<'py>(cls: &Bound<'py, PyType>, data: &[u8]) -> PyResult<Bound<'py, PyAny>> {
        let shape = core(|| serialize::from_bytes(data))?;
        let obj = wrap_shape(cls.py(), Arc::new(shape))?;
        if !obj.is_instance(cls)? {
            return Err(invalid(format!(
                "the bytes hold a {}, not a {}",
                obj.get_type().name()?,
                cls.name()?
            )));
        }
        Ok(obj)
    }

    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let ctor = py.get_type::<PyShape>().getattr("from_bytes")?;
        let args = PyTuple::new(py, [self.to_bytes(py)?])?;
        PyTuple::new(py, [ctor, args.into_any()])
    }

    fn __repr__(&self) -> String {
        repr_shape(&self.inner)
    }

    fn __eq__(&self, py: Python<'_>, other: &Bound<'_, PyAny>) -> Py<PyAny> {
        match other.cast::<PyShape>() {
            Ok(o) => PyBool::new(py, *self.inner == *o.get().inner)
                .to_owned()
                .into_any()
                .unbind(),
            Err(_) => py.NotImplemented(),
        }
    }

    fn __hash__(&self) -> u64 {
        // Equal shapes have equal kinds and bounds (-0.0 and 0.0 hash alike).
        let mut h = std::collections::hash_map::DefaultHasher::new();
        kind_str(&self.inner).hash(&mut h);
        let b = self.inner.local_aabb();
        for v in [b.min, b.max] {
            for x in v.to_array() {
                (f64::from(x) + 0.0).to_bits().hash(&mut h);
            }
        }
        h.finish()
    }
}

/// Scale factors: a scalar (uniform) or `(3,)`.
pub fn scale_factors(factors: &Bound<'_, PyAny>) -> PyResult<Vec3> {
    let (shape, values) = array_values(&float_array(factors, "factors")?)?;
    match (shape.as_slice(), values.as_slice()) {
        ([], [s]) => vec3_from("factors", [*s, *s, *s]),
        ([3], [x, y, z]) => vec3_from("factors", [*x, *y, *z]),
        _ => Err(invalid(format!(
            "factors must be a scalar or have shape (3,), got {}",
            shape_str(&shape)
        ))),
    }
}
