//! The primitive shape classes (`carom.Sphere`, `Box`, `Capsule`, `Cylinder`, `Cone`,
//! `Triangle`, `Plane`), the mapping from a core shape to its Python class, and `repr`.
//!
//! Each constructor is the one place its core constructor is called.

use crate::composite::{PyCompound, PyConvexHull, PyHeightField, PyScaled, PyTriMesh};
use crate::convert::{scalar, vec3, vec3_out};
use crate::errors::core;
use crate::shape::PyShape;
use carom_collision::math::{Real, Vec3};
use carom_collision::shape::{Capsule, Cone, Cuboid, Cylinder, Plane, Shape, Sphere, Triangle};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::PyClass;
use std::sync::Arc;

/// The core shape behind a subclass instance.
pub fn shape_of<'a, T: PyClass<BaseType = PyShape>>(slf: &'a Bound<'_, T>) -> &'a Shape {
    &slf.as_super().get().inner
}

/// Error for a subclass whose core shape is of another kind (cannot happen through the API).
pub fn wrong_kind(class: &str) -> PyErr {
    PyRuntimeError::new_err(format!(
        "internal error in carom: a {class} object holds another kind of shape"
    ))
}

/// The initializer of a subclass object around a core shape.
pub fn init<T: PyClass<BaseType = PyShape>>(shape: Shape, sub: T) -> PyClassInitializer<T> {
    PyClassInitializer::from(PyShape::new_base(shape)).add_subclass(sub)
}

fn wrap<T: PyClass<BaseType = PyShape>>(
    py: Python<'_>,
    shape: Arc<Shape>,
    sub: T,
) -> PyResult<Bound<'_, PyAny>> {
    let init = PyClassInitializer::from(PyShape { inner: shape }).add_subclass(sub);
    Ok(Bound::new(py, init)?.into_any())
}

/// A Python object of the right class for a core shape.
pub fn wrap_shape(py: Python<'_>, shape: Arc<Shape>) -> PyResult<Bound<'_, PyAny>> {
    match &*shape {
        Shape::Sphere(_) => wrap(py, shape, PySphere),
        Shape::Cuboid(_) => wrap(py, shape, PyBox),
        Shape::Capsule(_) => wrap(py, shape, PyCapsule),
        Shape::Cylinder(_) => wrap(py, shape, PyCylinder),
        Shape::Cone(_) => wrap(py, shape, PyCone),
        Shape::ConvexHull(_) => wrap(py, shape, PyConvexHull),
        Shape::Triangle(_) => wrap(py, shape, PyTriangle),
        Shape::Plane(_) => wrap(py, shape, PyPlane),
        Shape::TriMesh(_) => wrap(py, shape, PyTriMesh),
        Shape::HeightField(_) => wrap(py, shape, PyHeightField),
        Shape::Compound(_) => wrap(py, shape, PyCompound),
        Shape::Scaled(_) => wrap(py, shape, PyScaled),
    }
}

/// The `kind` string of a shape.
pub fn kind_str(shape: &Shape) -> &'static str {
    match shape {
        Shape::Sphere(_) => "sphere",
        Shape::Cuboid(_) => "box",
        Shape::Capsule(_) => "capsule",
        Shape::Cylinder(_) => "cylinder",
        Shape::Cone(_) => "cone",
        Shape::ConvexHull(_) => "convex_hull",
        Shape::Triangle(_) => "triangle",
        Shape::Plane(_) => "plane",
        Shape::TriMesh(_) => "trimesh",
        Shape::HeightField(_) => "heightfield",
        Shape::Compound(_) => "compound",
        Shape::Scaled(_) => "scaled",
    }
}

fn class_name(shape: &Shape) -> &'static str {
    match shape {
        Shape::Sphere(_) => "Sphere",
        Shape::Cuboid(_) => "Box",
        Shape::Capsule(_) => "Capsule",
        Shape::Cylinder(_) => "Cylinder",
        Shape::Cone(_) => "Cone",
        Shape::ConvexHull(_) => "ConvexHull",
        Shape::Triangle(_) => "Triangle",
        Shape::Plane(_) => "Plane",
        Shape::TriMesh(_) => "TriMesh",
        Shape::HeightField(_) => "HeightField",
        Shape::Compound(_) => "Compound",
        Shape::Scaled(_) => "Scaled",
    }
}

fn fmt_vec(v: Vec3) -> String {
    format!("[{:?}, {:?}, {:?}]", v.x, v.y, v.z)
}

fn fmt_real(x: Real) -> String {
    format!("{x:?}")
}

/// A readable `repr`: constructor syntax for parametric shapes, a summary for big ones.
pub fn repr_shape(shape: &Shape) -> String {
    match shape {
        Shape::Sphere(s) => format!("Sphere(radius={})", fmt_real(s.radius())),
        Shape::Cuboid(s) => format!("Box(half_extents={})", fmt_vec(s.half_extents())),
        Shape::Capsule(s) => format!(
            "Capsule(radius={}, half_height={})",
            fmt_real(s.radius()),
            fmt_real(s.half_height())
        ),
        Shape::Cylinder(s) => format!(
            "Cylinder(radius={}, half_height={})",
            fmt_real(s.radius()),
            fmt_real(s.half_height())
        ),
        Shape::Cone(s) => format!(
            "Cone(radius={}, half_height={})",
            fmt_real(s.radius()),
            fmt_real(s.half_height())
        ),
        Shape::ConvexHull(h) => format!(
            "ConvexHull(<{} vertices, {} faces>)",
            h.vertices().len(),
            h.faces().len()
        ),
        Shape::Triangle(t) => format!(
            "Triangle(a={}, b={}, c={})",
            fmt_vec(t.a),
            fmt_vec(t.b),
            fmt_vec(t.c)
        ),
        Shape::Plane(p) => format!(
            "Plane(normal={}, offset={})",
            fmt_vec(p.normal()),
            fmt_real(p.offset())
        ),
        Shape::TriMesh(m) => format!(
            "TriMesh(<{} vertices, {} triangles>)",
            m.vertices().len(),
            m.num_triangles()
        ),
        Shape::HeightField(h) => {
            let (dx, dz) = h.cell_size();
            format!(
                "HeightField(<{} x {} samples, cell_size=({}, {})>)",
                h.rows(),
                h.cols(),
                fmt_real(dx),
                fmt_real(dz)
            )
        }
        Shape::Compound(c) => {
            let names: Vec<&str> = c
                .children()
                .iter()
                .take(4)
                .map(|(_, s)| class_name(s))
                .collect();
            let more = if c.children().len() > 4 { ", ..." } else { "" };
            format!(
                "Compound(<{} children: {}{more}>)",
                c.children().len(),
                names.join(", ")
            )
        }
        Shape::Scaled(s) => format!("{}.scaled({})", repr_shape(s.inner()), fmt_vec(s.scale())),
    }
}

/// A sphere of `radius` (finite, > 0) centred at the origin. Its core is the centre point and
/// its margin the radius.
#[pyclass(name = "Sphere", module = "carom", extends = PyShape, frozen)]
pub struct PySphere;

#[pymethods]
impl PySphere {
    #[new]
    fn new(radius: f64) -> PyResult<PyClassInitializer<Self>> {
        let r = scalar("radius", radius)?;
        Ok(init(core(|| Sphere::new(r))?.into(), PySphere))
    }

    /// The radius.
    #[getter]
    fn radius(slf: &Bound<'_, Self>) -> PyResult<f64> {
        match shape_of(slf) {
            Shape::Sphere(s) => Ok(f64::from(s.radius())),
            _ => Err(wrong_kind("Sphere")),
        }
    }
}

/// A box centred at the origin with `half_extents` `(3,)` (each finite, > 0) along the local
/// axes. It keeps a small collision margin inside the box; `support` is exact.
#[pyclass(name = "Box", module = "carom", extends = PyShape, frozen)]
pub struct PyBox;

#[pymethods]
impl PyBox {
    #[new]
    fn new(half_extents: &Bound<'_, PyAny>) -> PyResult<PyClassInitializer<Self>> {
        let he = vec3(half_extents, "half_extents")?;
        Ok(init(core(|| Cuboid::new(he))?.into(), PyBox))
    }

    /// The half extents, `(3,)`.
    #[getter]
    fn half_extents<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        match shape_of(slf) {
            Shape::Cuboid(s) => Ok(vec3_out(slf.py(), s.half_extents())),
            _ => Err(wrong_kind("Box")),
        }
    }
}

macro_rules! radius_half_height {
    ($py_ty:ident, $variant:ident, $class:literal) => {
        #[pymethods]
        impl $py_ty {
            #[new]
            fn new(radius: f64, half_height: f64) -> PyResult<PyClassInitializer<Self>> {
                let r = scalar("radius", radius)?;
                let h = scalar("half_height", half_height)?;
                Ok(init(core(|| $variant::new(r, h))?.into(), $py_ty))
            }

            /// The radius.
            #[getter]
            fn radius(slf: &Bound<'_, Self>) -> PyResult<f64> {
                match shape_of(slf) {
                    Shape::$variant(s) => Ok(f64::from(s.radius())),
                    _ => Err(wrong_kind($class)),
                }
            }

            /// Half the height along the local Y axis.
            #[getter]
            fn half_height(slf: &Bound<'_, Self>) -> PyResult<f64> {
                match shape_of(slf) {
                    Shape::$variant(s) => Ok(f64::from(s.half_height())),
                    _ => Err(wrong_kind($class)),
                }
            }
        }
    };
}

/// A capsule along the local **Y** axis: the points within `radius` of the segment from
/// `(0, -half_height, 0)` to `(0, half_height, 0)` (total length `2 (half_height + radius)`;
/// pybullet's `height` is `2 half_height`). Both finite and > 0. Its core is the segment and
/// its margin the radius.
#[pyclass(name = "Capsule", module = "carom", extends = PyShape, frozen)]
pub struct PyCapsule;
radius_half_height!(PyCapsule, Capsule, "Capsule");

/// A solid cylinder along the local **Y** axis, centred at the origin, from
/// `y = -half_height` to `y = half_height`, of `radius`. Both finite and > 0.
#[pyclass(name = "Cylinder", module = "carom", extends = PyShape, frozen)]
pub struct PyCylinder;
radius_half_height!(PyCylinder, Cylinder, "Cylinder");

/// A solid cone along the local **Y** axis, centred on its bounding box: apex at
/// `(0, half_height, 0)`, base disc of `radius` at `y = -half_height`; its centre of mass is
/// at `(0, -half_height / 2, 0)`. Both finite and > 0.
#[pyclass(name = "Cone", module = "carom", extends = PyShape, frozen)]
pub struct PyCone;
radius_half_height!(PyCone, Cone, "Cone");

/// A single triangle with corners `a`, `b`, `c` (each `(3,)`, finite); its front face is
/// counter-clockwise, normal `(b - a) × (c - a)`. Zero-area triangles are allowed. It has no
/// volume or mass.
#[pyclass(name = "Triangle", module = "carom", extends = PyShape, frozen)]
pub struct PyTriangle;

fn triangle_of(slf: &Bound<'_, PyTriangle>) -> PyResult<Triangle> {
    match shape_of(slf) {
        Shape::Triangle(t) => Ok(*t),
        _ => Err(wrong_kind("Triangle")),
    }
}

#[pymethods]
impl PyTriangle {
    #[new]
    fn new(
        a: &Bound<'_, PyAny>,
        b: &Bound<'_, PyAny>,
        c: &Bound<'_, PyAny>,
    ) -> PyResult<PyClassInitializer<Self>> {
        let (a, b, c) = (vec3(a, "a")?, vec3(b, "b")?, vec3(c, "c")?);
        Ok(init(core(|| Triangle::new(a, b, c))?.into(), PyTriangle))
    }

    /// First corner, `(3,)`.
    #[getter]
    fn a<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(vec3_out(slf.py(), triangle_of(slf)?.a))
    }

    /// Second corner, `(3,)`.
    #[getter]
    fn b<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(vec3_out(slf.py(), triangle_of(slf)?.b))
    }

    /// Third corner, `(3,)`.
    #[getter]
    fn c<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(vec3_out(slf.py(), triangle_of(slf)?.c))
    }

    /// The corners as a `(3, 3)` array (one per row).
    #[getter]
    fn vertices<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let v = triangle_of(slf)?.vertices();
        Ok(Array2::from_shape_fn((3, 3), |(i, j)| f64::from(v[i][j])).into_pyarray(slf.py()))
    }

    /// Unit normal `(3,)`, or `None` for a zero-area triangle.
    #[getter]
    fn normal<'py>(slf: &Bound<'py, Self>) -> PyResult<Option<Bound<'py, PyArray1<f64>>>> {
        Ok(triangle_of(slf)?.normal().map(|n| vec3_out(slf.py(), n)))
    }
}

/// The infinite half-space `normal · x <= offset` (the solid lies opposite the normal), for
/// static bodies only. `normal` `(3,)` must be finite and non-zero (it is normalised);
/// `offset` is measured along the unit normal. It has no support map, volume or mass.
#[pyclass(name = "Plane", module = "carom", extends = PyShape, frozen)]
pub struct PyPlane;

#[pymethods]
impl PyPlane {
    #[new]
    #[pyo3(signature = (normal, offset = 0.0))]
    fn new(normal: &Bound<'_, PyAny>, offset: f64) -> PyResult<PyClassInitializer<Self>> {
        let n = vec3(normal, "normal")?;
        let o = scalar("offset", offset)?;
        Ok(init(core(|| Plane::new(n, o))?.into(), PyPlane))
    }

    /// Unit outward normal, `(3,)`.
    #[getter]
    fn normal<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        match shape_of(slf) {
            Shape::Plane(p) => Ok(vec3_out(slf.py(), p.normal())),
            _ => Err(wrong_kind("Plane")),
        }
    }

    /// Offset along the normal: the boundary is `normal · x = offset`.
    #[getter]
    fn offset(slf: &Bound<'_, Self>) -> PyResult<f64> {
        match shape_of(slf) {
            Shape::Plane(p) => Ok(f64::from(p.offset())),
            _ => Err(wrong_kind("Plane")),
        }
    }
}
