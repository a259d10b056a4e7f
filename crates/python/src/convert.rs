//! Conversions between Python objects and Carom's types.
//!
//! Inputs follow `numpy.asarray(x, dtype=float64)`: lists, tuples, integer arrays and
//! float32/float64 arrays are all accepted; strings, `None` and non-numeric objects are a
//! `TypeError`. Array shapes are checked with messages such as
//! `directions must have shape (N, 3), got (4, 2)`. Outputs are float64 numpy arrays.

use crate::errors::invalid;
use carom_collision::math::{real, vec3_to_f64, Aabb, Mat3, Real, Vec3};
use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayDyn, PyArrayMethods};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyString, PyTuple};

/// `(4, 2)` / `(3,)` — a shape formatted as Python prints it.
pub fn shape_str(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => {
            let parts: Vec<String> = shape.iter().map(|n| n.to_string()).collect();
            format!("({})", parts.join(", "))
        }
    }
}

fn type_name(obj: &Bound<'_, PyAny>) -> String {
    match obj.get_type().name() {
        Ok(n) => n.to_string(),
        Err(_) => "object".to_string(),
    }
}

/// Converts `obj` to an ndarray view-able float64 array with `numpy.asarray` semantics.
/// Non-numeric input is a `TypeError` naming the argument.
pub fn float_array<'py>(
    obj: &Bound<'py, PyAny>,
    name: &str,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    if let Ok(a) = obj.cast::<PyArrayDyn<f64>>() {
        return Ok(a.clone());
    }
    if obj.is_none() || obj.is_instance_of::<PyString>() || obj.is_instance_of::<PyBytes>() {
        return Err(PyTypeError::new_err(format!(
            "{name} must be an array-like of real numbers, got {}",
            type_name(obj)
        )));
    }
    let py = obj.py();
    let np = py.import("numpy")?;
    let arr = np.call_method1("asarray", (obj,)).map_err(|e| {
        PyTypeError::new_err(format!(
            "{name} must be an array-like of real numbers, got {}: {e}",
            type_name(obj)
        ))
    })?;
    let dtype = arr.getattr("dtype")?;
    let kind: String = dtype.getattr("kind")?.extract()?;
    if !matches!(kind.as_str(), "b" | "i" | "u" | "f" | "O") {
        return Err(PyTypeError::new_err(format!(
            "{name} must contain real numbers, got an array of dtype {}",
            dtype.str()?
        )));
    }
    let kwargs = PyDict::new(py);
    kwargs.set_item("dtype", np.getattr("float64")?)?;
    let converted = np
        .call_method("asarray", (arr,), Some(&kwargs))
        .map_err(|e| PyTypeError::new_err(format!("{name} must contain real numbers: {e}")))?;
    converted
        .cast_into::<PyArrayDyn<f64>>()
        .map_err(|_| PyTypeError::new_err(format!("{name}: cannot convert to a float64 array")))
}

/// The values of a float64 array in row-major order, with its shape.
pub fn array_values(a: &Bound<'_, PyArrayDyn<f64>>) -> PyResult<(Vec<usize>, Vec<f64>)> {
    let ro = a.try_readonly()?;
    let view = ro.as_array();
    Ok((view.shape().to_vec(), view.iter().copied().collect()))
}

/// Converts a user value to [`Real`]; a finite value that over- or underflows the build's
/// precision is rejected (NaN and infinities pass through for the core to name).
pub fn to_real(name: &dyn Fn() -> String, x: f64) -> PyResult<Real> {
    let r = real(x);
    if !fits(x, r) {
        return Err(invalid(format!(
            "invalid {} = {x:?}: out of range for the {}-bit floating point precision of this build",
            name(),
            std::mem::size_of::<Real>() * 8
        )));
    }
    Ok(r)
}

/// True unless converting the finite `x` to `r` over- or underflowed (a subnormal result
/// counts as underflow: it has lost precision).
#[inline(always)]
fn fits(x: f64, r: Real) -> bool {
    !x.is_finite() || x == 0.0 || r.is_normal()
}

/// A scalar [`Real`] argument.
pub fn scalar(name: &str, x: f64) -> PyResult<Real> {
    to_real(&|| name.to_string(), x)
}

/// Converts three f64 values to a [`Vec3`], element names `name[i]`.
pub fn vec3_from(name: &str, v: [f64; 3]) -> PyResult<Vec3> {
    let mut out = Vec3::ZERO;
    for (i, &x) in v.iter().enumerate() {
        out[i] = to_real(&|| format!("{name}[{i}]"), x)?;
    }
    Ok(out)
}

/// A `(3,)` vector.
pub fn vec3(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec3> {
    let (shape, values) = array_values(&float_array(obj, name)?)?;
    match values.as_slice() {
        [x, y, z] if shape.len() == 1 => vec3_from(name, [*x, *y, *z]),
        _ => Err(invalid(format!(
            "{name} must have shape (3,), got {}",
            shape_str(&shape)
        ))),
    }
}

/// Points or directions: `(N, 3)` gives `N` vectors; with `allow_single`, `(3,)` gives one
/// vector and `true`.
pub fn vec3s(
    obj: &Bound<'_, PyAny>,
    name: &str,
    allow_single: bool,
) -> PyResult<(Vec<Vec3>, bool)> {
    let (shape, values) = array_values(&float_array(obj, name)?)?;
    let single = allow_single && shape.len() == 1 && shape[0] == 3;
    if !(single || (shape.len() == 2 && shape[1] == 3)) {
        let expected = if allow_single {
            "(3,) or (N, 3)"
        } else {
            "(N, 3)"
        };
        return Err(invalid(format!(
            "{name} must have shape {expected}, got {}",
            shape_str(&shape)
        )));
    }
    let mut out = Vec::with_capacity(values.len() / 3);
    for (i, c) in values.chunks_exact(3).enumerate() {
        let v = Vec3::new(real(c[0]), real(c[1]), real(c[2]));
        if !(fits(c[0], v.x) && fits(c[1], v.y) && fits(c[2], v.z)) {
            // Slow path, only to build the error naming the element.
            vec3_from(&format!("{name}[{i}]"), [c[0], c[1], c[2]])?;
        }
        out.push(v);
    }
    Ok((out, single))
}

/// Rejects non-finite vectors, naming the first one.
pub fn require_finite(name: &str, vs: &[Vec3]) -> PyResult<()> {
    match vs.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => Err(invalid(format!(
            "invalid {name}[{i}] = {:?}: components must be finite",
            vec3_to_f64(vs[i])
        ))),
    }
}

/// `numpy.asarray(obj)` checked to hold integers (an empty array of any dtype passes);
/// `None`, strings and non-integer arrays are a `TypeError` saying `name` must be `what`.
pub fn integer_array<'py>(
    obj: &Bound<'py, PyAny>,
    name: &str,
    what: &str,
) -> PyResult<Bound<'py, PyAny>> {
    if obj.is_none() || obj.is_instance_of::<PyString>() || obj.is_instance_of::<PyBytes>() {
        return Err(PyTypeError::new_err(format!(
            "{name} must be {what}, got {}",
            type_name(obj)
        )));
    }
    let np = obj.py().import("numpy")?;
    let arr = np
        .call_method1("asarray", (obj,))
        .map_err(|e| PyTypeError::new_err(format!("{name} must be {what}: {e}")))?;
    let kind: String = arr.getattr("dtype")?.getattr("kind")?.extract()?;
    let size: usize = arr.getattr("size")?.extract()?;
    if !(matches!(kind.as_str(), "i" | "u") || size == 0) {
        return Err(PyTypeError::new_err(format!(
            "{name} must contain integers, got an array of dtype {}",
            arr.getattr("dtype")?.str()?
        )));
    }
    Ok(arr)
}

/// Triangle (or other) index triples from an integer array of shape `(M, 3)`.
pub fn index_triples(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<[u32; 3]>> {
    let arr = integer_array(obj, name, "an integer array of shape (M, 3)")?;
    let kind: String = arr.getattr("dtype")?.getattr("kind")?.extract()?;
    let shape: Vec<usize> = arr.getattr("shape")?.extract()?;
    if !(shape.len() == 2 && shape[1] == 3) {
        return Err(invalid(format!(
            "{name} must have shape (M, 3), got {}",
            shape_str(&shape)
        )));
    }
    let flat: Vec<i128> = if kind == "u" {
        let v: Vec<u64> = arr
            .call_method1("astype", ("uint64",))?
            .call_method0("ravel")?
            .extract()?;
        v.into_iter().map(i128::from).collect()
    } else {
        let v: Vec<i64> = arr
            .call_method1("astype", ("int64",))?
            .call_method0("ravel")?
            .extract()?;
        v.into_iter().map(i128::from).collect()
    };
    let mut out = Vec::with_capacity(flat.len() / 3);
    for (t, c) in flat.chunks_exact(3).enumerate() {
        let mut tri = [0u32; 3];
        for k in 0..3 {
            tri[k] = u32::try_from(c[k]).map_err(|_| {
                invalid(format!(
                    "invalid {name}[{t}][{k}] = {}: must be in [0, {}]",
                    c[k],
                    u32::MAX
                ))
            })?;
        }
        out.push(tri);
    }
    Ok(out)
}

/// `(3,)` float64 array.
pub fn vec3_out<'py>(py: Python<'py>, v: Vec3) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_vec(py, vec3_to_f64(v).to_vec())
}

/// `(N, 3)` float64 array.
pub fn vec3s_out<'py>(py: Python<'py>, vs: &[Vec3]) -> Bound<'py, PyArray2<f64>> {
    Array2::from_shape_fn((vs.len(), 3), |(i, j)| f64::from(vs[i][j])).into_pyarray(py)
}

/// `(3,)` for a single vector, else `(N, 3)`.
pub fn vec3s_or_single_out<'py>(py: Python<'py>, vs: &[Vec3], single: bool) -> Bound<'py, PyAny> {
    match (single, vs) {
        (true, [v]) => vec3_out(py, *v).into_any(),
        _ => vec3s_out(py, vs).into_any(),
    }
}

/// `(3, 3)` float64 array, row-major as printed.
pub fn mat3_out<'py>(py: Python<'py>, m: Mat3) -> Bound<'py, PyArray2<f64>> {
    Array2::from_shape_fn((3, 3), |(i, j)| f64::from(m.col(j)[i])).into_pyarray(py)
}

/// An AABB as the tuple `(min (3,), max (3,))`.
pub fn aabb_out<'py>(py: Python<'py>, aabb: &Aabb) -> PyResult<Bound<'py, PyTuple>> {
    PyTuple::new(py, [vec3_out(py, aabb.min), vec3_out(py, aabb.max)])
}

/// `(N,)` int64 array.
pub fn indices_out<'py>(py: Python<'py>, idx: &[u32]) -> Bound<'py, PyArray1<i64>> {
    Array1::from_iter(idx.iter().map(|&i| i64::from(i))).into_pyarray(py)
}

/// `(M, 3)` int64 array.
pub fn triples_out<'py>(py: Python<'py>, tris: &[[u32; 3]]) -> Bound<'py, PyArray2<i64>> {
    Array2::from_shape_fn((tris.len(), 3), |(i, j)| i64::from(tris[i][j])).into_pyarray(py)
}

/// An integer argument of type `T` (handles, filter bits, counts). pyo3 raises
/// `OverflowError` for an int outside `T`'s range, which is neither a `ValueError` nor a
/// `TypeError`; this raises `CaromError` (a `ValueError`) naming the value and the range,
/// and refuses `bool` (a `TypeError`: `True` is not body 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Int<T>(pub T);

/// The range of an [`Int`] argument, for its error message.
pub trait IntRange {
    /// `[min, max]` as text.
    const RANGE: &'static str;
}

impl IntRange for u32 {
    const RANGE: &'static str = "[0, 2**32 - 1]";
}

impl IntRange for u64 {
    const RANGE: &'static str = "[0, 2**64 - 1]";
}

impl IntRange for i64 {
    const RANGE: &'static str = "[-2**63, 2**63 - 1]";
}

impl<'a, 'py, T> FromPyObject<'a, 'py> for Int<T>
where
    T: FromPyObject<'a, 'py, Error = PyErr> + IntRange,
{
    type Error = PyErr;

    fn extract(ob: pyo3::Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        let shown = ob.to_owned();
        if ob.is_instance_of::<pyo3::types::PyBool>() {
            return Err(PyTypeError::new_err(format!(
                "expected an int, got bool ({shown})"
            )));
        }
        match ob.extract::<T>() {
            Ok(v) => Ok(Int(v)),
            Err(e) if e.is_instance_of::<pyo3::exceptions::PyOverflowError>(ob.py()) => Err(
                invalid(format!("invalid integer {shown}: must be in {}", T::RANGE)),
            ),
            Err(e) => Err(e),
        }
    }
}

/// [`Int`] for a parameter with a default (`#[pyo3(from_py_with = int_arg::<u32>)]`), whose
/// type must stay the plain integer.
pub fn int_arg<T>(ob: &Bound<'_, PyAny>) -> PyResult<T>
where
    T: for<'a, 'py> FromPyObject<'a, 'py, Error = PyErr> + IntRange,
{
    ob.extract::<Int<T>>().map(|i| i.0)
}

/// A sequence of `u64` (handles) with [`Int`]'s errors.
pub fn u64s_arg(ob: &Bound<'_, PyAny>) -> PyResult<Vec<u64>> {
    Ok(ob
        .extract::<Vec<Int<u64>>>()?
        .into_iter()
        .map(|i| i.0)
        .collect())
}

/// [`u64s_arg`] or `None`.
pub fn opt_u64s_arg(ob: &Bound<'_, PyAny>) -> PyResult<Option<Vec<u64>>> {
    if ob.is_none() {
        return Ok(None);
    }
    u64s_arg(ob).map(Some)
}
