//! Broadphase bindings: `carom.overlapping_pairs` (one call, any method) and
//! `carom.BroadPhase` (an incremental broadphase reporting added/removed pairs), thin wrappers
//! of `carom_collision::broadphase`. Batches are validated in full before anything changes,
//! and the heavy work runs with the GIL released.
//!
//! Handles are the core's generational `ProxyHandle`s packed into one integer
//! (`ProxyHandle::to_bits`: generation in the high 32 bits, slot index in the low 32): Python
//! sees plain ints, and a removed (stale) handle is rejected, never confused with the object
//! that reuses its slot.

use crate::convert::{aabb_out, integer_array, require_finite, shape_str, vec3s};
use crate::errors::{carom_err, core, guard, invalid};
use carom_collision::broadphase::{
    overlapping_pairs as core_pairs, AnyBroadPhase, BroadPhase, Filter, Method, ProxyHandle,
};
use carom_collision::math::{vec3_to_f64, Aabb, Vec3};
use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyInt, PyTuple};

/// Boxes from `(N, 3)` min/max arrays (or `(3,)` each for one box, flagged by the bool),
/// rejecting NaN/infinite bounds and inverted boxes with the index of the first bad box.
pub fn boxes_arg(
    aabb_min: &Bound<'_, PyAny>,
    aabb_max: &Bound<'_, PyAny>,
    allow_single: bool,
) -> PyResult<(Vec<Aabb>, bool)> {
    let (lo, single_lo) = vec3s(aabb_min, "aabb_min", allow_single)?;
    let (hi, single_hi) = vec3s(aabb_max, "aabb_max", allow_single)?;
    if lo.len() != hi.len() || single_lo != single_hi {
        return Err(invalid(format!(
            "aabb_min and aabb_max must have the same shape, got {} and {} boxes",
            lo.len(),
            hi.len()
        )));
    }
    let mut out = Vec::with_capacity(lo.len());
    for (i, (a, b)) in lo.into_iter().zip(hi).enumerate() {
        if !a.is_finite() || !b.is_finite() {
            return Err(invalid(format!(
                "invalid box {i}: aabb_min = {:?}, aabb_max = {:?}: bounds must be finite",
                vec3_to_f64(a),
                vec3_to_f64(b)
            )));
        }
        if !a.cmple(b).all() {
            return Err(invalid(format!(
                "invalid box {i}: aabb_min = {:?} > aabb_max = {:?} on some axis (inverted box)",
                vec3_to_f64(a),
                vec3_to_f64(b)
            )));
        }
        out.push(Aabb::new(a, b));
    }
    Ok((out, single_lo))
}

/// Integer handles: a Python int (single, flagged by the bool) or a 1-D integer array.
pub fn handles_arg(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<(Vec<u64>, bool)> {
    if obj.is_instance_of::<PyBool>() {
        return Err(PyTypeError::new_err(format!(
            "{name} must be an int or a 1-D integer array, got bool"
        )));
    }
    if obj.is_instance_of::<PyInt>() {
        let h: i64 = obj
            .extract()
            .map_err(|_| invalid(format!("unknown handle {name} = {obj}")))?;
        return Ok((vec![h as u64], true));
    }
    let arr = integer_array(obj, name, "an int or a 1-D integer array")?;
    let shape: Vec<usize> = arr.getattr("shape")?.extract()?;
    if shape.is_empty() {
        let h: i64 = arr.call_method1("astype", ("int64",))?.extract()?;
        return Ok((vec![h as u64], true));
    }
    if shape.len() != 1 {
        return Err(invalid(format!(
            "{name} must have shape (N,), got {}",
            shape_str(&shape)
        )));
    }
    let v: Vec<i64> = arr
        .call_method1("astype", ("int64",))?
        .call_method0("tolist")?
        .extract()?;
    Ok((v.into_iter().map(|h| h as u64).collect(), false))
}

/// The boxes and predicted displacements of an `update` of `count` handles (`single` when
/// given as one int): `(3,)` or `(N, 3)` arrays matching the handles; no displacement = 0.
pub fn moves_arg(
    count: usize,
    single: bool,
    aabb_min: &Bound<'_, PyAny>,
    aabb_max: &Bound<'_, PyAny>,
    displacement: Option<&Bound<'_, PyAny>>,
) -> PyResult<(Vec<Aabb>, Vec<Vec3>)> {
    let (boxes, single_box) = boxes_arg(aabb_min, aabb_max, true)?;
    if count != boxes.len() || single != single_box {
        return Err(invalid(format!(
            "handles and boxes must match, got {count} handles and {} boxes",
            boxes.len()
        )));
    }
    let disp = match displacement {
        None => vec![Vec3::ZERO; count],
        Some(d) => {
            let (d, _) = vec3s(d, "displacement", true)?;
            require_finite("displacement", &d)?;
            if d.len() != count {
                return Err(invalid(format!(
                    "displacement must have one row per handle, got {} for {count}",
                    d.len()
                )));
            }
            d
        }
    };
    Ok((boxes, disp))
}

/// A `u32` filter argument given as a Python int.
fn bits_arg(name: &str, x: i64) -> PyResult<u32> {
    u32::try_from(x)
        .map_err(|_| invalid(format!("invalid {name} = {x}: must be in [0, 0xFFFFFFFF]")))
}

/// Pairs of integers as a `(M, 2)` int64 array.
pub fn pairs_out<'py>(py: Python<'py>, pairs: &[[i64; 2]]) -> Bound<'py, PyArray2<i64>> {
    Array2::from_shape_fn((pairs.len(), 2), |(i, j)| pairs[i][j]).into_pyarray(py)
}

/// Handle pairs as rows `(a, b)`, `a < b` as ints, sorted lexicographically.
fn handle_rows(pairs: &[(ProxyHandle, ProxyHandle)]) -> Vec<[i64; 2]> {
    let mut rows: Vec<[i64; 2]> = pairs
        .iter()
        .map(|(a, b)| {
            let (a, b) = (a.to_bits() as i64, b.to_bits() as i64);
            [a.min(b), a.max(b)]
        })
        .collect();
    rows.sort_unstable();
    rows
}

/// All pairs `(i, j)`, `i < j`, of the boxes `[aabb_min[i], aabb_max[i]]` (`(N, 3)` arrays)
/// that overlap, touching included, as a `(M, 2)` int64 array sorted lexicographically.
/// `method` is one of "tree", "tree_manhattan", "sap", "sort_sweep", "grid", "hgrid"
/// (default) or "brute_force"; all give the same pairs. NaN or inverted boxes raise
/// `CaromError` naming the box. The GIL is released while the pairs are found.
#[pyfunction]
#[pyo3(signature = (aabb_min, aabb_max, method = "hgrid"))]
pub fn overlapping_pairs<'py>(
    py: Python<'py>,
    aabb_min: &Bound<'py, PyAny>,
    aabb_max: &Bound<'py, PyAny>,
    method: &str,
) -> PyResult<Bound<'py, PyArray2<i64>>> {
    let method: Method = method.parse().map_err(carom_err)?;
    let (boxes, _) = boxes_arg(aabb_min, aabb_max, false)?;
    let lo: Vec<[_; 3]> = boxes.iter().map(|b| b.min.to_array()).collect();
    let hi: Vec<[_; 3]> = boxes.iter().map(|b| b.max.to_array()).collect();
    let pairs = py.detach(move || core(|| core_pairs(&lo, &hi, method)))?;
    let rows: Vec<[i64; 2]> = pairs
        .into_iter()
        .map(|(a, b)| [i64::from(a), i64::from(b)])
        .collect();
    Ok(pairs_out(py, &rows))
}

/// An incremental broadphase: boxes are added, moved and removed by integer handle, and
/// `update_pairs()` returns the pairs of overlapping boxes (touching included) added and
/// removed since the previous call. Pairs are `(M, 2)` int64 arrays of handles, each row
/// `(a, b)` with `a < b`, rows sorted. `method` as for `overlapping_pairs` (default
/// "hgrid"). Two boxes may pair when `group_a & mask_b` and `group_b & mask_a` are non-zero
/// and they are not both static. Removing a box reports its pairs as removed at the next
/// update; its handle is then stale and rejected.
#[pyclass(name = "BroadPhase", module = "carom")]
pub struct PyBroadPhase {
    bp: AnyBroadPhase,
    method: Method,
}

impl PyBroadPhase {
    fn handles(&self, obj: &Bound<'_, PyAny>, name: &str) -> PyResult<(Vec<ProxyHandle>, bool)> {
        let (bits, single) = handles_arg(obj, name)?;
        let mut out = Vec::with_capacity(bits.len());
        for b in bits {
            let h = ProxyHandle::from_bits(b);
            if self.bp.aabb(h).is_err() {
                return Err(invalid(format!("unknown handle {name} = {}", b as i64)));
            }
            out.push(h);
        }
        Ok((out, single))
    }
}

#[pymethods]
impl PyBroadPhase {
    #[new]
    #[pyo3(signature = (method = "hgrid"))]
    fn new(method: &str) -> PyResult<Self> {
        let method: Method = method.parse().map_err(carom_err)?;
        Ok(PyBroadPhase {
            bp: AnyBroadPhase::new(method),
            method,
        })
    }

    /// The method name.
    #[getter]
    fn method(&self) -> &'static str {
        self.method.name()
    }

    /// Adds boxes: `(3,)` min/max give one box and return its handle (int); `(N, 3)` arrays
    /// give N boxes and return an `(N,)` int64 array of handles. `group` and `mask` are
    /// 32-bit masks; `is_static` boxes never pair with each other.
    #[pyo3(signature = (aabb_min, aabb_max, group = 1, mask = 0xFFFF_FFFF, is_static = false))]
    fn add<'py>(
        &mut self,
        py: Python<'py>,
        aabb_min: &Bound<'py, PyAny>,
        aabb_max: &Bound<'py, PyAny>,
        #[pyo3(from_py_with = crate::convert::int_arg::<i64>)] group: i64,
        #[pyo3(from_py_with = crate::convert::int_arg::<i64>)] mask: i64,
        is_static: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let filter = Filter {
            group: bits_arg("group", group)?,
            mask: bits_arg("mask", mask)?,
            is_static,
        };
        let (boxes, single) = boxes_arg(aabb_min, aabb_max, true)?;
        let bp = &mut self.bp;
        let handles = py.detach(move || {
            core(|| {
                boxes
                    .iter()
                    .map(|b| bp.create_proxy(*b, filter).map(|h| h.to_bits() as i64))
                    .collect::<Result<Vec<i64>, _>>()
            })
        })?;
        Ok(if single {
            handles[0].into_pyobject(py)?.into_any()
        } else {
            Array1::from_vec(handles).into_pyarray(py).into_any()
        })
    }

    /// Moves boxes: `handles` an int with `(3,)` min/max, or an `(N,)` array with `(N, 3)`
    /// arrays. `displacement` (same shape) is the predicted motion over the next step, used
    /// by the tree methods to enlarge their boxes. Nothing changes if any input is invalid.
    #[pyo3(signature = (handles, aabb_min, aabb_max, displacement = None))]
    fn update(
        &mut self,
        py: Python<'_>,
        handles: &Bound<'_, PyAny>,
        aabb_min: &Bound<'_, PyAny>,
        aabb_max: &Bound<'_, PyAny>,
        displacement: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let (hs, single) = self.handles(handles, "handles")?;
        let (boxes, disp) = moves_arg(hs.len(), single, aabb_min, aabb_max, displacement)?;
        let bp = &mut self.bp;
        py.detach(move || {
            core(|| {
                for ((h, b), d) in hs.iter().zip(&boxes).zip(&disp) {
                    bp.update_proxy(*h, *b, *d)?;
                }
                Ok(())
            })
        })
    }

    /// Removes boxes (an int or an `(N,)` array of handles); their pairs are reported as
    /// removed by the next `update_pairs()`. Unknown, stale or repeated handles raise
    /// `CaromError` and nothing is removed.
    fn remove(&mut self, handles: &Bound<'_, PyAny>) -> PyResult<()> {
        let (hs, _) = self.handles(handles, "handles")?;
        let mut sorted = hs.clone();
        sorted.sort_unstable();
        if let Some(w) = sorted.windows(2).find(|w| w[0] == w[1]) {
            return Err(invalid(format!(
                "handle {} is given twice",
                w[0].to_bits() as i64
            )));
        }
        core(|| hs.iter().try_for_each(|h| self.bp.remove_proxy(*h)))
    }

    /// Marks a box as resting (asleep, `True`) or moving (`False`). The tree methods move it
    /// between their moving and resting trees; the other methods only check the handle.
    fn set_resting(&mut self, handle: &Bound<'_, PyAny>, resting: bool) -> PyResult<()> {
        let (hs, _) = self.handles(handle, "handle")?;
        core(|| hs.iter().try_for_each(|h| self.bp.set_resting(*h, resting)))
    }

    /// Changes the collision filter of a box (takes effect at the next update).
    #[pyo3(signature = (handle, group = 1, mask = 0xFFFF_FFFF, is_static = false))]
    fn set_filter(
        &mut self,
        handle: &Bound<'_, PyAny>,
        #[pyo3(from_py_with = crate::convert::int_arg::<i64>)] group: i64,
        #[pyo3(from_py_with = crate::convert::int_arg::<i64>)] mask: i64,
        is_static: bool,
    ) -> PyResult<()> {
        let filter = Filter {
            group: bits_arg("group", group)?,
            mask: bits_arg("mask", mask)?,
            is_static,
        };
        let (hs, _) = self.handles(handle, "handle")?;
        core(|| hs.iter().try_for_each(|h| self.bp.set_filter(*h, filter)))
    }

    /// Finds the overlapping pairs and returns `(added, removed)`: `(K, 2)` and `(L, 2)`
    /// int64 arrays of the handle pairs that appeared and disappeared since the previous
    /// call (GIL released).
    fn update_pairs<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let bp = &mut self.bp;
        let (added, removed) = py.detach(move || {
            guard(|| {
                let ch = bp.update_pairs();
                Ok((handle_rows(&ch.added), handle_rows(&ch.removed)))
            })
        })?;
        PyTuple::new(py, [pairs_out(py, &added), pairs_out(py, &removed)])
    }

    /// The current pairs (as of the last `update_pairs()`), a `(M, 2)` int64 array.
    fn pairs<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        let rows = guard(|| Ok(handle_rows(&self.bp.pairs())))?;
        Ok(pairs_out(py, &rows))
    }

    /// The exact box of a handle as `(min (3,), max (3,))`.
    fn aabb<'py>(
        &self,
        py: Python<'py>,
        handle: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let (hs, single) = self.handles(handle, "handle")?;
        if !single {
            return Err(invalid("aabb takes one handle"));
        }
        aabb_out(py, &core(|| self.bp.aabb(hs[0]))?)
    }

    /// True when `handle` names a box of this broadphase.
    fn __contains__(&self, handle: &Bound<'_, PyAny>) -> bool {
        matches!(handles_arg(handle, "handle"), Ok((h, true))
            if self.bp.aabb(ProxyHandle::from_bits(h[0])).is_ok())
    }

    /// The number of boxes.
    fn __len__(&self) -> usize {
        self.bp.len()
    }

    fn __repr__(&self) -> String {
        format!(
            "BroadPhase(method='{}', boxes={}, pairs={})",
            self.method.name(),
            self.bp.len(),
            self.bp.pair_count()
        )
    }
}

/// `(N,)` int64 array of handles.
pub fn handles_out<'py>(py: Python<'py>, hs: Vec<i64>) -> Bound<'py, PyArray1<i64>> {
    Array1::from_vec(hs).into_pyarray(py)
}
