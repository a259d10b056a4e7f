//! `carom.DynamicTree`: the core's dynamic AABB tree (`carom_collision::broadphase::
//! DynamicTree`) with box, ray and frustum queries.
//!
//! The tree stores fat (enlarged) boxes; the binding keeps each object's exact box beside it
//! and filters every query against the exact boxes, so results are exact and independent of
//! the margin. Handles are the leaves' generational ids packed into one int (generation in
//! the high 32 bits), so a removed handle is rejected.

use crate::broadphase::{boxes_arg, handles_arg, handles_out, moves_arg};
use crate::convert::{aabb_out, array_values, float_array, scalar, shape_str, vec3};
use crate::errors::{core, invalid};
use carom_collision::broadphase::{DynamicTree, HalfSpace, InsertStrategy, TreeProxy};
use carom_collision::math::{real, Aabb, Real, Vec3};
use numpy::ndarray::Array1;
use numpy::{IntoPyArray, PyArray1};
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::PyTuple;

fn to_bits(p: TreeProxy) -> i64 {
    (((p.generation as u64) << 32) | p.index as u64) as i64
}

fn from_bits(b: u64) -> TreeProxy {
    TreeProxy {
        index: b as u32,
        generation: (b >> 32) as u32,
    }
}

/// A dynamic AABB tree (Box2D v3's `b2DynamicTree`, Bullet's `btDbvt`): boxes are inserted,
/// moved and removed by integer handle, and queried by box overlap, ray and frustum. Queries
/// return exact results (touching counts as overlap) as int64 arrays of handles, sorted.
/// `margin` (>= 0) enlarges the stored boxes so small moves need no re-insertion;
/// `strategy` is "sah" (surface-area heuristic with rotations, default) or "manhattan".
#[pyclass(name = "DynamicTree", module = "carom")]
pub struct PyDynamicTree {
    tree: DynamicTree,
    /// Exact boxes by leaf node index.
    exact: Vec<Aabb>,
}

impl PyDynamicTree {
    fn proxies(&self, obj: &Bound<'_, PyAny>, name: &str) -> PyResult<(Vec<TreeProxy>, bool)> {
        let (bits, single) = handles_arg(obj, name)?;
        let mut out = Vec::with_capacity(bits.len());
        for b in bits {
            let p = from_bits(b);
            if self.tree.user_data(p).is_err() {
                return Err(invalid(format!("unknown handle {name} = {}", b as i64)));
            }
            out.push(p);
        }
        Ok((out, single))
    }

    fn set_exact(&mut self, p: TreeProxy, aabb: Aabb) {
        let i = p.index as usize;
        if i >= self.exact.len() {
            self.exact.resize(i + 1, Aabb::EMPTY);
        }
        self.exact[i] = aabb;
    }

    fn sorted_out<'py>(py: Python<'py>, mut hs: Vec<i64>) -> Bound<'py, PyArray1<i64>> {
        hs.sort_unstable();
        handles_out(py, hs)
    }
}

/// Planes `(P, 4)` rows `(nx, ny, nz, d)`, inside where `n·x + d >= 0`.
fn planes_arg(obj: &Bound<'_, PyAny>) -> PyResult<Vec<(Vec3, Real)>> {
    let (shape, values) = array_values(&float_array(obj, "planes")?)?;
    if !(shape.len() == 2 && shape[1] == 4) {
        return Err(invalid(format!(
            "planes must have shape (P, 4), got {}",
            shape_str(&shape)
        )));
    }
    let mut out = Vec::with_capacity(shape[0]);
    for (i, c) in values.chunks_exact(4).enumerate() {
        if !c.iter().all(|x| x.is_finite()) {
            return Err(invalid(format!(
                "invalid planes[{i}] = {c:?}: components must be finite"
            )));
        }
        out.push((Vec3::new(real(c[0]), real(c[1]), real(c[2])), real(c[3])));
    }
    Ok(out)
}

/// True when the box meets every half-space `n·x + d >= 0`.
fn box_in_planes(b: &Aabb, planes: &[(Vec3, Real)]) -> bool {
    planes.iter().all(|(n, d)| {
        let p = Vec3::select(n.cmpge(Vec3::ZERO), b.max, b.min);
        n.dot(p) + d >= 0.0
    })
}

#[pymethods]
impl PyDynamicTree {
    #[new]
    #[pyo3(signature = (margin = 0.1, strategy = "sah"))]
    fn new(margin: f64, strategy: &str) -> PyResult<Self> {
        let m = scalar("margin", margin)?;
        if !(m >= 0.0 && m.is_finite()) {
            return Err(invalid(format!(
                "invalid margin = {margin:?}: must be finite and >= 0"
            )));
        }
        let strategy = match strategy {
            "sah" => InsertStrategy::SurfaceArea,
            "manhattan" => InsertStrategy::Manhattan,
            _ => {
                return Err(invalid(format!(
                    "invalid strategy = {strategy:?}: expected 'sah' or 'manhattan'"
                )))
            }
        };
        Ok(PyDynamicTree {
            tree: DynamicTree::new(strategy, m),
            exact: Vec::new(),
        })
    }

    /// Inserts boxes: `(3,)` min/max insert one and return its handle (int); `(N, 3)` arrays
    /// insert N and return an `(N,)` int64 array of handles.
    fn insert<'py>(
        &mut self,
        py: Python<'py>,
        aabb_min: &Bound<'py, PyAny>,
        aabb_max: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (boxes, single) = boxes_arg(aabb_min, aabb_max, true)?;
        let tree = &mut self.tree;
        let proxies = py.detach(move || {
            core(|| {
                boxes
                    .iter()
                    .map(|b| tree.create_proxy(*b, 0).map(|p| (p, *b)))
                    .collect::<Result<Vec<_>, _>>()
            })
        })?;
        let mut hs = Vec::with_capacity(proxies.len());
        for (p, b) in proxies {
            self.set_exact(p, b);
            hs.push(to_bits(p));
        }
        Ok(if single {
            hs[0].into_pyobject(py)?.into_any()
        } else {
            Array1::from_vec(hs).into_pyarray(py).into_any()
        })
    }

    /// Removes boxes (an int or an `(N,)` array of handles). Unknown, stale or repeated
    /// handles raise `CaromError` and nothing is removed.
    fn remove(&mut self, handles: &Bound<'_, PyAny>) -> PyResult<()> {
        let (ps, _) = self.proxies(handles, "handles")?;
        let mut sorted = ps.clone();
        sorted.sort_unstable();
        if let Some(w) = sorted.windows(2).find(|w| w[0] == w[1]) {
            return Err(invalid(format!("handle {} is given twice", to_bits(w[0]))));
        }
        core(|| ps.iter().try_for_each(|p| self.tree.destroy_proxy(*p)))
    }

    /// Moves boxes: `handles` an int with `(3,)` min/max, or an `(N,)` array with `(N, 3)`
    /// arrays; `displacement` (same shape) is the predicted motion, which enlarges the stored
    /// box along it. A box still inside its stored box is not re-inserted.
    #[pyo3(signature = (handles, aabb_min, aabb_max, displacement = None))]
    fn update(
        &mut self,
        handles: &Bound<'_, PyAny>,
        aabb_min: &Bound<'_, PyAny>,
        aabb_max: &Bound<'_, PyAny>,
        displacement: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let (ps, single) = self.proxies(handles, "handles")?;
        let (boxes, disp) = moves_arg(ps.len(), single, aabb_min, aabb_max, displacement)?;
        for ((p, b), d) in ps.iter().zip(&boxes).zip(&disp) {
            core(|| self.tree.move_proxy(*p, *b, *d))?;
            self.set_exact(*p, *b);
        }
        Ok(())
    }

    /// Handles of the boxes overlapping the box `[aabb_min, aabb_max]` (touching included),
    /// a sorted int64 array.
    fn query_aabb<'py>(
        &self,
        py: Python<'py>,
        aabb_min: &Bound<'py, PyAny>,
        aabb_max: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let (boxes, single) = boxes_arg(aabb_min, aabb_max, true)?;
        if !single {
            return Err(invalid(
                "query_aabb takes one box: aabb_min and aabb_max of shape (3,)",
            ));
        }
        let q = boxes[0];
        let mut hs = Vec::new();
        self.tree.query_aabb(&q, |p, _| {
            if self.exact[p.index as usize].intersects(&q) {
                hs.push(to_bits(p));
            }
            true
        });
        Ok(Self::sorted_out(py, hs))
    }

    /// Casts the ray `origin + t * direction`, `t` in `[0, max_fraction]` (`direction` need
    /// not be unit: `t` is in units of it). Returns `(handles, fractions)`: int64 and
    /// float64 arrays of every box the ray hits and the `t` where it enters each (0 when the
    /// origin is inside), sorted by fraction then handle. With `closest=True`, only the
    /// nearest hit (arrays of length 0 or 1); the ray is clipped as hits are found.
    #[pyo3(signature = (origin, direction, max_fraction = 1.0, closest = false))]
    fn raycast<'py>(
        &self,
        py: Python<'py>,
        origin: &Bound<'py, PyAny>,
        direction: &Bound<'py, PyAny>,
        max_fraction: f64,
        closest: bool,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let o = vec3(origin, "origin")?;
        let d = vec3(direction, "direction")?;
        crate::convert::require_finite("origin", &[o])?;
        crate::convert::require_finite("direction", &[d])?;
        let mf = scalar("max_fraction", max_fraction)?;
        if mf.is_nan() || mf < 0.0 {
            return Err(invalid(format!(
                "invalid max_fraction = {max_fraction:?}: must be >= 0"
            )));
        }
        let mut hits: Vec<(Real, i64)> = Vec::new();
        self.tree.ray_cast(o, d, mf, |p, _, _| {
            let bound = if closest {
                hits.first().map_or(mf, |h| h.0)
            } else {
                mf
            };
            if let Some(t) = self.exact[p.index as usize].ray_intersection(o, d, bound) {
                if closest {
                    hits.clear();
                    hits.push((t, to_bits(p)));
                    return t;
                }
                hits.push((t, to_bits(p)));
            }
            // Keep the current maximum (the tree takes the minimum with it).
            Real::INFINITY
        });
        hits.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let hs: Vec<i64> = hits.iter().map(|h| h.1).collect();
        let ts: Vec<f64> = hits.iter().map(|h| f64::from(h.0)).collect();
        PyTuple::new(
            py,
            [
                handles_out(py, hs).into_any(),
                Array1::from_vec(ts).into_pyarray(py).into_any(),
            ],
        )
    }

    /// Handles of the boxes that meet every half-space `nx*x + ny*y + nz*z + d >= 0` of
    /// `planes`, a `(P, 4)` array of rows `(nx, ny, nz, d)` (inward normals, need not be
    /// unit): frustum culling, conservative as usual (a box outside the frustum only near
    /// a corner, yet inside every plane, is reported). Sorted int64 array.
    fn query_frustum<'py>(
        &self,
        py: Python<'py>,
        planes: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let planes = planes_arg(planes)?;
        // The core's half-spaces are `normal · x <= offset` with outward normals.
        let spaces: Vec<HalfSpace> = planes
            .iter()
            .map(|(n, d)| HalfSpace {
                normal: -*n,
                offset: *d,
            })
            .collect();
        let mut hs = Vec::new();
        self.tree.query_planes(&spaces, |p, _| {
            if box_in_planes(&self.exact[p.index as usize], &planes) {
                hs.push(to_bits(p));
            }
        });
        Ok(Self::sorted_out(py, hs))
    }

    /// The exact box of a handle as `(min (3,), max (3,))`.
    fn aabb<'py>(
        &self,
        py: Python<'py>,
        handle: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let (ps, single) = self.proxies(handle, "handle")?;
        if !single {
            return Err(invalid("aabb takes one handle"));
        }
        aabb_out(py, &self.exact[ps[0].index as usize])
    }

    /// Checks the tree's invariants (every parent box contains its children's, heights and
    /// parent links consistent, leaf count) and that every stored box contains its exact
    /// box; raises `RuntimeError` describing the first violation.
    fn validate(&self) -> PyResult<()> {
        self.tree.validate().map_err(PyRuntimeError::new_err)?;
        let mut bad = None;
        self.tree.query_planes(&[], |p, _| {
            let fat = self.tree.fat_aabb_of(p).unwrap_or(Aabb::EMPTY);
            if bad.is_none() && !fat.contains(&self.exact[p.index as usize]) {
                bad = Some(to_bits(p));
            }
        });
        match bad {
            Some(h) => Err(PyRuntimeError::new_err(format!(
                "stored box of handle {h} does not contain its exact box"
            ))),
            None => Ok(()),
        }
    }

    /// Height of the tree (0 for zero or one box).
    #[getter]
    fn height(&self) -> i32 {
        self.tree.height()
    }

    /// The number of boxes.
    fn __len__(&self) -> usize {
        self.tree.len()
    }

    fn __repr__(&self) -> String {
        format!(
            "DynamicTree(boxes={}, height={})",
            self.tree.len(),
            self.tree.height()
        )
    }
}
