//! `carom.Pose`: a rigid transform with a unit quaternion `(x, y, z, w)` as in pybullet.
//!
//! Poses are kept in double precision on the Python side (so `to_array` round-trips exactly)
//! and converted to the core's [`Isometry`] (in [`carom_collision::math::Real`]) when a query
//! takes them. Anywhere a pose is taken, a `Pose`, a `(7,)` array `[x, y, z, qx, qy, qz, qw]`
//! or `None` (the identity) is accepted.

use crate::convert::{array_values, float_array, shape_str, vec3_from};
use crate::errors::invalid;
use carom_collision::math::{real, Isometry, Quat, Real, UNIT_QUAT_TOLERANCE};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyTuple};
use std::hash::{Hash, Hasher};

/// A rigid transform in double precision: `x ↦ R(q) x + p`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose64 {
    /// Translation.
    pub p: [f64; 3],
    /// Unit quaternion `[x, y, z, w]`.
    pub q: [f64; 4],
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Hamilton product of `[x, y, z, w]` quaternions.
fn quat_mul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    let [ax, ay, az, aw] = a;
    let [bx, by, bz, bw] = b;
    [
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ]
}

/// `q / |q|`, leaving quaternions already unit to within rounding untouched, so that
/// validating a pose twice (e.g. `Pose.from_array(p.to_array())`) is exact.
fn normalized(q: [f64; 4]) -> [f64; 4] {
    let len = q.iter().map(|x| x * x).sum::<f64>().sqrt();
    if (len - 1.0).abs() <= 8.0 * f64::EPSILON {
        q
    } else if len > 0.0 {
        q.map(|x| x / len)
    } else {
        [0.0, 0.0, 0.0, 1.0]
    }
}

impl Pose64 {
    /// The identity.
    pub const IDENTITY: Pose64 = Pose64 {
        p: [0.0; 3],
        q: [0.0, 0.0, 0.0, 1.0],
    };

    /// A validated pose: finite position, finite unit quaternion (renormalised).
    pub fn checked(name: &str, p: [f64; 3], q: [f64; 4]) -> PyResult<Pose64> {
        if p.iter().any(|x| !x.is_finite()) {
            return Err(invalid(format!(
                "invalid {name}position = {p:?}: components must be finite"
            )));
        }
        if q.iter().any(|x| !x.is_finite()) {
            return Err(invalid(format!(
                "invalid {name}rotation = {q:?}: components must be finite"
            )));
        }
        let len = q.iter().map(|x| x * x).sum::<f64>().sqrt();
        if (len - 1.0).abs() > f64::from(UNIT_QUAT_TOLERANCE) {
            return Err(invalid(format!(
                "invalid {name}rotation = {q:?}: must be a unit quaternion (x, y, z, w); its length is {len}"
            )));
        }
        // The position must also fit the core's precision.
        vec3_from(&format!("{name}position"), p)?;
        Ok(Pose64 {
            p,
            q: normalized(q),
        })
    }

    /// Rotates a vector.
    pub fn rotate(&self, v: [f64; 3]) -> [f64; 3] {
        // v' = v + 2w (u × v) + 2 u × (u × v)
        let u = [self.q[0], self.q[1], self.q[2]];
        let w = self.q[3];
        let t = cross(u, v).map(|x| 2.0 * x);
        let ut = cross(u, t);
        [
            v[0] + w * t[0] + ut[0],
            v[1] + w * t[1] + ut[1],
            v[2] + w * t[2] + ut[2],
        ]
    }

    /// Transforms a point.
    pub fn transform_point(&self, v: [f64; 3]) -> [f64; 3] {
        let r = self.rotate(v);
        [r[0] + self.p[0], r[1] + self.p[1], r[2] + self.p[2]]
    }

    /// `self * rhs`: applies `rhs` first.
    pub fn mul(&self, rhs: &Pose64) -> Pose64 {
        Pose64 {
            p: self.transform_point(rhs.p),
            q: normalized(quat_mul(self.q, rhs.q)),
        }
    }

    /// The inverse transform.
    pub fn inverse(&self) -> Pose64 {
        let q = [-self.q[0], -self.q[1], -self.q[2], self.q[3]];
        let inv = Pose64 { p: [0.0; 3], q };
        let r = inv.rotate(self.p);
        Pose64 {
            p: [-r[0], -r[1], -r[2]],
            q,
        }
    }

    /// Rotation matrix (row-major).
    pub fn rotation_matrix(&self) -> [[f64; 3]; 3] {
        let [x, y, z, w] = self.q;
        [
            [
                1.0 - 2.0 * (y * y + z * z),
                2.0 * (x * y - z * w),
                2.0 * (x * z + y * w),
            ],
            [
                2.0 * (x * y + z * w),
                1.0 - 2.0 * (x * x + z * z),
                2.0 * (y * z - x * w),
            ],
            [
                2.0 * (x * z - y * w),
                2.0 * (y * z + x * w),
                1.0 - 2.0 * (x * x + y * y),
            ],
        ]
    }

    /// The core's isometry (at the core's precision).
    pub fn to_isometry(self, name: &str) -> PyResult<Isometry> {
        let t = vec3_from(&format!("{name}.position"), self.p)?;
        let [x, y, z, w] = self.q;
        let q = Quat::from_xyzw(real(x), real(y), real(z), real(w)).normalize();
        Ok(Isometry::new(t, q))
    }

    /// From a core isometry.
    pub fn from_isometry(iso: &Isometry) -> Pose64 {
        let t = iso.translation;
        let q = iso.rotation;
        let f = |x: Real| f64::from(x);
        Pose64 {
            p: [f(t.x), f(t.y), f(t.z)],
            q: normalized([f(q.x), f(q.y), f(q.z), f(q.w)]),
        }
    }

    /// `[x, y, z, qx, qy, qz, qw]`.
    pub fn to_array(self) -> [f64; 7] {
        let [x, y, z] = self.p;
        let [qx, qy, qz, qw] = self.q;
        [x, y, z, qx, qy, qz, qw]
    }

    /// From `[x, y, z, qx, qy, qz, qw]` (validated).
    pub fn from_array(name: &str, a: &[f64]) -> PyResult<Pose64> {
        match a {
            [x, y, z, qx, qy, qz, qw] => Pose64::checked(name, [*x, *y, *z], [*qx, *qy, *qz, *qw]),
            _ => Err(invalid(format!("{name} must have 7 values"))),
        }
    }
}

/// A rigid transform: a `position` `(3,)` and a unit quaternion `rotation` `(x, y, z, w)`
/// (pybullet's order), applied as `x ↦ R x + position`.
///
/// `Pose(position=None, rotation=None)` defaults to the origin and the identity rotation.
/// The rotation must have unit length (within 1e-3; it is renormalised), else
/// `carom.CaromError`. Poses compose with `*` (`(a * b).transform_points(x)` applies `b`
/// first), pickle, and compare by value (`q` and `-q` are the same rotation but different
/// poses for `==`). Anywhere Carom takes a pose, a `(7,)` array `[x, y, z, qx, qy, qz, qw]`
/// works too, and `None` means the identity.
#[pyclass(name = "Pose", module = "carom", frozen)]
pub struct PyPose {
    pub(crate) pose: Pose64,
}

impl PyPose {
    /// Wraps a pose.
    pub fn new_py(pose: Pose64) -> Self {
        PyPose { pose }
    }
}

fn fixed<const N: usize>(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<[f64; N]> {
    let (shape, values) = array_values(&float_array(obj, name)?)?;
    match <[f64; N]>::try_from(values.as_slice()) {
        Ok(a) if shape.len() == 1 => Ok(a),
        _ => Err(invalid(format!(
            "{name} must have shape ({N},), got {}",
            shape_str(&shape)
        ))),
    }
}

#[pymethods]
impl PyPose {
    #[new]
    #[pyo3(signature = (position = None, rotation = None))]
    fn new(
        position: Option<&Bound<'_, PyAny>>,
        rotation: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let p = match position {
            Some(p) if !p.is_none() => fixed::<3>(p, "position")?,
            _ => [0.0; 3],
        };
        let q = match rotation {
            Some(q) if !q.is_none() => fixed::<4>(q, "rotation")?,
            _ => [0.0, 0.0, 0.0, 1.0],
        };
        Ok(PyPose {
            pose: Pose64::checked("", p, q)?,
        })
    }

    /// The identity pose.
    #[staticmethod]
    fn identity() -> Self {
        PyPose {
            pose: Pose64::IDENTITY,
        }
    }

    /// A pose from a `(7,)` array `[x, y, z, qx, qy, qz, qw]`.
    #[staticmethod]
    fn from_array(array: &Bound<'_, PyAny>) -> PyResult<Self> {
        let a = fixed::<7>(array, "array")?;
        Ok(PyPose {
            pose: Pose64::from_array("", &a)?,
        })
    }

    /// The pose as a `(7,)` float64 array `[x, y, z, qx, qy, qz, qw]`.
    fn to_array<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.pose.to_array().to_vec())
    }

    /// The translation, a `(3,)` float64 array.
    #[getter]
    fn position<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.pose.p.to_vec())
    }

    /// The rotation, a unit quaternion `(x, y, z, w)` as a `(4,)` float64 array.
    #[getter]
    fn rotation<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.pose.q.to_vec())
    }

    /// The 4x4 homogeneous matrix `[[R, p], [0, 0, 0, 1]]`.
    fn matrix<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let r = self.pose.rotation_matrix();
        let p = self.pose.p;
        Array2::from_shape_fn((4, 4), |(i, j)| match (i, j) {
            (3, 3) => 1.0,
            (3, _) => 0.0,
            (_, 3) => p[i],
            _ => r[i][j],
        })
        .into_pyarray(py)
    }

    /// The inverse pose: `p.inverse() * p` is the identity.
    fn inverse(&self) -> Self {
        PyPose {
            pose: self.pose.inverse(),
        }
    }

    /// Composition: `(self * other)` applies `other` first, then `self`.
    fn __mul__(&self, py: Python<'_>, other: &Bound<'_, PyAny>) -> Py<PyAny> {
        match other.cast::<PyPose>() {
            Ok(o) => match Bound::new(
                py,
                PyPose {
                    pose: self.pose.mul(&o.get().pose),
                },
            ) {
                Ok(b) => b.into_any().unbind(),
                Err(_) => py.NotImplemented(),
            },
            Err(_) => py.NotImplemented(),
        }
    }

    /// Applies the pose to points: `(3,)` → `(3,)` or `(N, 3)` → `(N, 3)`.
    fn transform_points<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.apply(py, points, "points", true)
    }

    /// Applies the rotation only to vectors (directions, normals): `(3,)` or `(N, 3)`.
    fn transform_vectors<'py>(
        &self,
        py: Python<'py>,
        vectors: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.apply(py, vectors, "vectors", false)
    }

    fn __repr__(&self) -> String {
        format!(
            "Pose(position={:?}, rotation={:?})",
            self.pose.p, self.pose.q
        )
    }

    fn __eq__(&self, py: Python<'_>, other: &Bound<'_, PyAny>) -> Py<PyAny> {
        match other.cast::<PyPose>() {
            Ok(o) => PyBool::new(py, self.pose == o.get().pose)
                .to_owned()
                .into_any()
                .unbind(),
            Err(_) => py.NotImplemented(),
        }
    }

    fn __hash__(&self) -> u64 {
        let mut h = std::collections::hash_map::DefaultHasher::new();
        for x in self.pose.to_array() {
            (x + 0.0).to_bits().hash(&mut h);
        }
        h.finish()
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let pose = slf.get().pose;
        let args = (PyTuple::new(py, pose.p)?, PyTuple::new(py, pose.q)?);
        PyTuple::new(
            py,
            [
                slf.get_type().into_any(),
                args.into_pyobject(py)?.into_any(),
            ],
        )
    }
}

impl PyPose {
    fn apply<'py>(
        &self,
        py: Python<'py>,
        obj: &Bound<'py, PyAny>,
        name: &str,
        translate: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (shape, values) = array_values(&float_array(obj, name)?)?;
        let single = shape.len() == 1 && shape[0] == 3;
        if !(single || (shape.len() == 2 && shape[1] == 3)) {
            return Err(invalid(format!(
                "{name} must have shape (3,) or (N, 3), got {}",
                shape_str(&shape)
            )));
        }
        let mut out = Vec::with_capacity(values.len());
        for c in values.chunks_exact(3) {
            let v = [c[0], c[1], c[2]];
            let r = if translate {
                self.pose.transform_point(v)
            } else {
                self.pose.rotate(v)
            };
            out.extend_from_slice(&r);
        }
        if single {
            Ok(PyArray1::from_vec(py, out).into_any())
        } else {
            let n = out.len() / 3;
            Ok(Array2::from_shape_fn((n, 3), |(i, j)| out[3 * i + j])
                .into_pyarray(py)
                .into_any())
        }
    }
}

/// A pose argument: `None` (identity), a `carom.Pose`, or a `(7,)` array.
pub fn extract_pose(obj: Option<&Bound<'_, PyAny>>, name: &str) -> PyResult<Pose64> {
    let Some(obj) = obj else {
        return Ok(Pose64::IDENTITY);
    };
    if obj.is_none() {
        return Ok(Pose64::IDENTITY);
    }
    if let Ok(p) = obj.cast::<PyPose>() {
        return Ok(p.get().pose);
    }
    let (shape, values) = array_values(&float_array(obj, name)?)?;
    if shape.as_slice() != [7] {
        return Err(invalid(format!(
            "{name} must be a carom.Pose or an array of shape (7,) [x, y, z, qx, qy, qz, qw], got shape {}",
            shape_str(&shape)
        )));
    }
    Pose64::from_array(&format!("{name}."), &values)
}

/// A pose or a batch of poses: `None`, a `Pose`, `(7,)` (single, `true`) or `(N, 7)`.
pub fn extract_poses(obj: Option<&Bound<'_, PyAny>>, name: &str) -> PyResult<(Vec<Pose64>, bool)> {
    let Some(o) = obj else {
        return Ok((vec![Pose64::IDENTITY], true));
    };
    if o.is_none() || o.cast::<PyPose>().is_ok() {
        return Ok((vec![extract_pose(obj, name)?], true));
    }
    let (shape, values) = array_values(&float_array(o, name)?)?;
    match shape.as_slice() {
        [7] => Ok((
            vec![Pose64::from_array(&format!("{name}."), &values)?],
            true,
        )),
        [_, 7] => {
            let mut out = Vec::with_capacity(values.len() / 7);
            for (i, c) in values.chunks_exact(7).enumerate() {
                out.push(Pose64::from_array(&format!("{name}[{i}]."), c)?);
            }
            Ok((out, false))
        }
        _ => Err(invalid(format!(
            "{name} must be a carom.Pose, a (7,) array or an (N, 7) array, got shape {}",
            shape_str(&shape)
        ))),
    }
}

/// A core isometry from a pose argument.
pub fn extract_isometry(obj: Option<&Bound<'_, PyAny>>, name: &str) -> PyResult<Isometry> {
    extract_pose(obj, name)?.to_isometry(name)
}
