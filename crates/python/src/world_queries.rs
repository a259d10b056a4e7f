//! Queries and contact reports of `carom.World`: ray casts (one ray or a batch, GIL
//! released), shape casts, contact events with body handles, and the touching contact points
//! with their solver impulses, as numpy arrays.
//!
//! Rays and shape casts run `carom_dynamics::World::query` (a BVH over the bodies' current
//! boxes, closest hit first); the brute force over `carom.raycast` on every body is the
//! oracle of `python/tests/test_world_queries.py`.

use crate::collision_world::{pairs_out, PyContactEvents};
use crate::convert::{vec3_out, vec3s_out};
use carom_collision::math::{Real, Vec3};
use carom_collision::narrowphase::ContactEventKind;
use carom_dynamics::{BodyHandle, BodyRayHit, BodyShapeCastHit, World};
use numpy::ndarray::Array1;
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyFloat, PyInt};

type Obj = Py<PyAny>;

/// A body handle as a Python int (generation in the high 32 bits).
pub(crate) fn bits(h: BodyHandle) -> u64 {
    (u64::from(h.generation) << 32) | u64::from(h.index)
}

fn reals(py: Python<'_>, xs: impl Iterator<Item = Real>) -> Obj {
    Array1::from_iter(xs.map(f64::from))
        .into_pyarray(py)
        .into_any()
        .unbind()
}

fn vecs(py: Python<'_>, xs: &[Vec3]) -> Obj {
    vec3s_out(py, xs).into_any().unbind()
}

const NAN3: Vec3 = Vec3::splat(Real::NAN);

/// The closest body hit by a ray through a `carom.World`: `hit`, `distance` (along the unit
/// direction), `point`, `normal` (outward) and `body` (the handle). For one ray the fields
/// are scalars and `(3,)` arrays; for `(N, 3)` rays, arrays of length N where misses hold
/// `hit = False`, NaN and `body = -1`.
#[pyclass(name = "WorldRayHit", module = "carom", frozen, get_all)]
pub struct PyWorldRayHit {
    /// Whether the ray hit (bool or `(N,)` bool).
    hit: Obj,
    /// Distance along the unit direction.
    distance: Obj,
    /// World hit point.
    point: Obj,
    /// Outward unit normal at the hit point.
    normal: Obj,
    /// Handle of the body hit (`-1` for a miss in a batch).
    body: Obj,
}

impl PyWorldRayHit {
    pub(crate) fn one(py: Python<'_>, h: &BodyRayHit) -> Self {
        PyWorldRayHit {
            hit: PyBool::new(py, true).to_owned().into_any().unbind(),
            distance: PyFloat::new(py, f64::from(h.hit.distance))
                .into_any()
                .unbind(),
            point: vec3_out(py, h.hit.point).into_any().unbind(),
            normal: vec3_out(py, h.hit.normal).into_any().unbind(),
            body: PyInt::new(py, bits(h.body)).into_any().unbind(),
        }
    }

    pub(crate) fn many(py: Python<'_>, hs: &[Option<BodyRayHit>]) -> Self {
        let pts: Vec<Vec3> = hs.iter().map(|h| h.map_or(NAN3, |h| h.hit.point)).collect();
        let ns: Vec<Vec3> = hs
            .iter()
            .map(|h| h.map_or(NAN3, |h| h.hit.normal))
            .collect();
        let body = Array1::from_iter(hs.iter().map(|h| h.map_or(-1, |h| bits(h.body) as i64)));
        let hit = Array1::from_iter(hs.iter().map(|h| h.is_some()));
        PyWorldRayHit {
            hit: hit.into_pyarray(py).into_any().unbind(),
            distance: reals(
                py,
                hs.iter().map(|h| h.map_or(Real::NAN, |h| h.hit.distance)),
            ),
            point: vecs(py, &pts),
            normal: vecs(py, &ns),
            body: body.into_pyarray(py).into_any().unbind(),
        }
    }
}

#[pymethods]
impl PyWorldRayHit {
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!(
            "WorldRayHit(body={}, distance={})",
            self.body.bind(py).repr()?,
            self.distance.bind(py).repr()?
        ))
    }
}

/// The first body hit by a shape cast through a `carom.World`: `toi` (time of impact, a
/// fraction of the velocity), `point_a` (on the cast shape), `point_b` (on the body),
/// `normal` (unit, from the cast shape towards the body) and `body` (the handle).
#[pyclass(name = "WorldShapeCastHit", module = "carom", frozen, get_all)]
pub struct PyWorldShapeCastHit {
    /// Time of impact.
    toi: f64,
    /// Witness point on the cast shape at the time of impact (world).
    point_a: Obj,
    /// Witness point on the body (world).
    point_b: Obj,
    /// Unit normal from the cast shape towards the body.
    normal: Obj,
    /// Handle of the body hit.
    body: u64,
}

impl PyWorldShapeCastHit {
    pub(crate) fn new(py: Python<'_>, h: &BodyShapeCastHit) -> Self {
        PyWorldShapeCastHit {
            toi: f64::from(h.hit.toi),
            point_a: vec3_out(py, h.hit.point_a).into_any().unbind(),
            point_b: vec3_out(py, h.hit.point_b).into_any().unbind(),
            normal: vec3_out(py, h.hit.normal).into_any().unbind(),
            body: bits(h.body),
        }
    }
}

#[pymethods]
impl PyWorldShapeCastHit {
    fn __repr__(&self) -> String {
        format!("WorldShapeCastHit(body={}, toi={})", self.body, self.toi)
    }
}

/// The contact events of the last step with body handles. Pairs whose body was removed
/// since, pairs of two non-dynamic bodies and pairs whose joint disables collisions are
/// left out (the solver never sees them).
pub(crate) fn contact_events(py: Python<'_>, w: &World) -> PyContactEvents {
    let mut by = [Vec::new(), Vec::new(), Vec::new()];
    for e in w.collision().narrowphase().events() {
        let (Some(a), Some(b)) = (w.body_of_object(e.a), w.body_of_object(e.b)) else {
            continue;
        };
        if !w.dynamics().should_collide(a, b) {
            continue;
        }
        let k = match e.kind {
            ContactEventKind::Begin => 0,
            ContactEventKind::Persist => 1,
            ContactEventKind::End => 2,
        };
        by[k].push((bits(a), bits(b)));
    }
    PyContactEvents::from_groups(py, &by)
}

/// The contact points of the last step (K rows) between bodies: `bodies` `(K, 2)` int64
/// handles (A, B), `point_a`, `point_b` `(K, 3)` world points, `normal` `(K, 3)` unit from A
/// towards B, `distance` `(K,)` signed (negative = penetration, `point_b = point_a + normal
/// * distance`) and `normal_impulse` `(K,)` the solver's accumulated impulse along the normal
/// (N·s, pushing B away from A).
/// Speculative points (not yet touching, `distance > 0`) are included with their impulse
/// (usually 0).
#[pyclass(name = "WorldContacts", module = "carom", frozen, get_all)]
pub struct PyWorldContacts {
    /// `(K, 2)` body handles A and B of each point.
    bodies: Obj,
    /// `(K, 3)` world points on A.
    point_a: Obj,
    /// `(K, 3)` world points on B.
    point_b: Obj,
    /// `(K, 3)` unit normals from A towards B.
    normal: Obj,
    /// `(K,)` signed distances.
    distance: Obj,
    /// `(K,)` accumulated normal impulses, N·s.
    normal_impulse: Obj,
}

#[pymethods]
impl PyWorldContacts {
    fn __len__(&self, py: Python<'_>) -> PyResult<usize> {
        self.distance.bind(py).len()
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!(
            "WorldContacts({} points)",
            self.distance.bind(py).len()?
        ))
    }
}

/// The contact points the solver used at the last step (non-sensor manifolds between live
/// bodies that should collide), in pair order.
pub(crate) fn contacts(py: Python<'_>, w: &World) -> PyWorldContacts {
    let (mut ids, mut pa, mut pb, mut n) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let (mut d, mut jn) = (Vec::new(), Vec::new());
    for pc in w.collision().narrowphase().manifolds() {
        let (Some(a), Some(b)) = (w.body_of_object(pc.a), w.body_of_object(pc.b)) else {
            continue;
        };
        if pc.sensor || !w.dynamics().should_collide(a, b) {
            continue;
        }
        for p in &pc.manifold.points {
            ids.push((bits(a), bits(b)));
            pa.push(p.point_a());
            pb.push(p.point_b);
            n.push(-p.normal);
            d.push(p.distance);
            jn.push(p.normal_impulse);
        }
    }
    PyWorldContacts {
        bodies: pairs_out(py, &ids),
        point_a: vecs(py, &pa),
        point_b: vecs(py, &pb),
        normal: vecs(py, &n),
        distance: reals(py, d.into_iter()),
        normal_impulse: reals(py, jn.into_iter()),
    }
}
