//! Contact generation from Python: `carom.contact_manifold` (one pair, one manifold) and
//! `carom.CollisionWorld` (objects, broadphase, persistent manifolds, contact events),
//! thin wrappers of `carom_collision::narrowphase` and `carom_collision::world`.
//!
//! Conventions are those of `carom.contact` (ARCHITECTURE.md, "Python conventions"): the
//! normal is the unit vector **from A towards B** and `distance` is signed (negative =
//! penetration), so `point_b = point_a + normal * distance`; `depth = -distance`. (The
//! core's `ContactPoint` stores the talk's convention, normal on B pointing towards A: the
//! sign is flipped here, once.) Object handles are Python ints (slot and generation packed
//! as in `ProxyHandle::to_bits`).

use crate::convert::scalar;
use crate::convert::Int;
use crate::errors::{core, invalid};
use crate::pose::{extract_isometry, extract_poses};
use crate::queries::shape_arg;
use carom_collision::broadphase::{BroadPhase, Filter, Method, ProxyHandle};
use carom_collision::math::{Isometry, Real, Vec3};
use carom_collision::narrowphase::{
    ContactEventKind, ContactManifold, ContactPoint, Dispatcher, ManifoldConfig,
};
use carom_collision::world::{CollisionWorld, ObjectHandle};
use numpy::ndarray::{Array1, Array2};
use numpy::IntoPyArray;
use pyo3::prelude::*;

type Obj = Py<PyAny>;

fn bits(h: ObjectHandle) -> u64 {
    ProxyHandle {
        index: h.index,
        generation: h.generation,
    }
    .to_bits()
}

fn handle(b: u64) -> ObjectHandle {
    ProxyHandle::from_bits(b).into()
}

fn reals(py: Python<'_>, xs: impl Iterator<Item = Real>) -> Obj {
    Array1::from_iter(xs.map(f64::from))
        .into_pyarray(py)
        .into_any()
        .unbind()
}

fn vecs(py: Python<'_>, xs: &[Vec3]) -> Obj {
    crate::convert::vec3s_out(py, xs).into_any().unbind()
}

pub(crate) fn pairs_out(py: Python<'_>, ps: &[(u64, u64)]) -> Obj {
    Array2::from_shape_fn((ps.len(), 2), |(i, j)| {
        let p = ps[i];
        (if j == 0 { p.0 } else { p.1 }) as i64
    })
    .into_pyarray(py)
    .into_any()
    .unbind()
}

/// Contact points as numpy arrays (K rows): `point_a`, `point_b` (world, `(K, 3)`),
/// `normal` (`(K, 3)`, unit, **from A towards B**, as `carom.contact`), `distance` (`(K,)`,
/// signed, negative = penetration; `point_b = point_a + normal * distance`), `depth`
/// (`(K,)` = `-distance`), `feature` (`(K,)` int64 feature ids, stable across steps while
/// the same features touch; -1 when unknown) and, from `CollisionWorld.step`, `pairs`
/// (`(K, 2)` int64 object handles A and B of each point).
#[pyclass(name = "Contacts", module = "carom", frozen, get_all)]
pub struct PyContacts {
    /// `(K, 2)` handles of objects A and B of each point (empty for `contact_manifold`).
    pairs: Obj,
    /// `(K, 3)` world points on A.
    point_a: Obj,
    /// `(K, 3)` world points on B.
    point_b: Obj,
    /// `(K, 3)` unit normals from A towards B.
    normal: Obj,
    /// `(K,)` signed distances (negative = penetration).
    distance: Obj,
    /// `(K,)` penetration depths (`-distance`).
    depth: Obj,
    /// `(K,)` feature ids (-1 when unknown).
    feature: Obj,
}

impl PyContacts {
    fn new(py: Python<'_>, pts: &[((u64, u64), ContactPoint)]) -> Self {
        // Core convention (normal on B towards A, a = b + n d) to A → B.
        let pa: Vec<Vec3> = pts.iter().map(|(_, p)| p.point_a()).collect();
        let pb: Vec<Vec3> = pts.iter().map(|(_, p)| p.point_b).collect();
        let n: Vec<Vec3> = pts.iter().map(|(_, p)| -p.normal).collect();
        let ids: Vec<(u64, u64)> = pts.iter().map(|(h, _)| *h).collect();
        let feature = Array1::from_iter(pts.iter().map(|(_, p)| {
            if p.feature == carom_collision::narrowphase::NO_FEATURE {
                -1
            } else {
                i64::from(p.feature)
            }
        }));
        PyContacts {
            pairs: pairs_out(py, &ids),
            point_a: vecs(py, &pa),
            point_b: vecs(py, &pb),
            normal: vecs(py, &n),
            distance: reals(py, pts.iter().map(|(_, p)| p.distance)),
            depth: reals(py, pts.iter().map(|(_, p)| -p.distance)),
            feature: feature.into_pyarray(py).into_any().unbind(),
        }
    }
}

impl PyContactEvents {
    /// Events grouped as `[begin, persist, end]` lists of handle pairs (also used by
    /// `carom.World`, whose pairs are body handles).
    pub(crate) fn from_groups(py: Python<'_>, by: &[Vec<(u64, u64)>; 3]) -> Self {
        PyContactEvents {
            begin: pairs_out(py, &by[0]),
            persist: pairs_out(py, &by[1]),
            end: pairs_out(py, &by[2]),
        }
    }
}

#[pymethods]
impl PyContacts {
    fn __len__(&self, py: Python<'_>) -> PyResult<usize> {
        self.distance.bind(py).len()
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!(
            "Contacts({} points, distance={})",
            self.distance.bind(py).len()?,
            self.distance.bind(py).repr()?
        ))
    }
}

/// Contact events of the last `CollisionWorld.step`: `begin`, `persist` and `end`, each a
/// `(E, 2)` int64 array of object-handle pairs (A, B), in pair order. Sensor pairs are
/// included (they report overlap but carry no contact points).
#[pyclass(name = "ContactEvents", module = "carom", frozen, get_all)]
pub struct PyContactEvents {
    /// Pairs that started touching.
    begin: Obj,
    /// Pairs that still touch.
    persist: Obj,
    /// Pairs that stopped touching (or whose object was removed).
    end: Obj,
}

#[pymethods]
impl PyContactEvents {
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let n = |o: &Obj| o.bind(py).len();
        Ok(format!(
            "ContactEvents(begin={}, persist={}, end={})",
            n(&self.begin)?,
            n(&self.persist)?,
            n(&self.end)?
        ))
    }
}

/// The contact manifold of shape `a` at `pose_a` and `b` at `pose_b` (poses: `Pose` or
/// `(7,)`): up to 4 points, from the one-shot manifold (box and hull clipping, capsule
/// segments, plane and mesh contacts with internal-edge correction) or, for round shapes
/// without one, GJK/EPA plus perturbation. Points further apart than `prediction` (>= 0)
/// are dropped. Returns a `Contacts` whose normal points **from A towards B** (as
/// `carom.contact`); empty when the shapes are apart. An unsupported pair (mesh–mesh,
/// plane–plane, heightfield–mesh) raises `CaromError`.
#[pyfunction]
#[pyo3(signature = (a, pose_a, b, pose_b, prediction = 0.0))]
pub fn contact_manifold(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    pose_a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    pose_b: &Bound<'_, PyAny>,
    prediction: f64,
) -> PyResult<PyContacts> {
    let (sa, sb) = (shape_arg(a, "a")?, shape_arg(b, "b")?);
    let pa = extract_isometry(Some(pose_a), "pose_a")?;
    let pb = extract_isometry(Some(pose_b), "pose_b")?;
    let pred = scalar("prediction", prediction)?;
    if !(pred >= 0.0 && pred.is_finite()) {
        return Err(invalid(format!(
            "prediction must be finite and >= 0, got {prediction}"
        )));
    }
    let d = Dispatcher::new(ManifoldConfig {
        prediction: pred,
        breaking_threshold: pred,
        ..ManifoldConfig::default()
    });
    let mut m = ContactManifold::new();
    core(|| {
        d.check_pair(&sa, &sb)?;
        d.update_manifold(&sa, &pa, &sb, &pb, &mut m)
    })?;
    let pts: Vec<_> = m.points.iter().map(|p| ((0, 0), *p)).collect();
    Ok(PyContacts::new(py, &pts))
}

/// A collision world: shapes at poses with collision filters, a broadphase (`method`: one
/// of "tree", the default, "tree_manhattan", "sap", "sort_sweep", "grid", "hgrid",
/// "brute_force") and persistent contact manifolds per overlapping pair. `add` returns an
/// int handle; move objects with `set_pose`/`set_poses`, then `step()` runs broadphase,
/// midphase and narrowphase and returns every manifold point as `Contacts` (normal from A
/// towards B, `pairs` the handles). `events()` gives begin/persist/end pairs of the last step.
#[pyclass(name = "CollisionWorld", module = "carom")]
pub struct PyCollisionWorld {
    world: CollisionWorld,
}

impl PyCollisionWorld {
    fn contacts_now(&self) -> Vec<((u64, u64), ContactPoint)> {
        self.world
            .narrowphase()
            .manifolds()
            .flat_map(|p| {
                let h = (bits(p.a), bits(p.b));
                p.manifold.points.iter().map(move |q| (h, *q))
            })
            .collect()
    }
}

#[pymethods]
impl PyCollisionWorld {
    #[new]
    #[pyo3(signature = (method = "tree"))]
    fn new(method: &str) -> PyResult<Self> {
        let m: Method = core(|| method.parse())?;
        Ok(PyCollisionWorld {
            world: CollisionWorld::new(m),
        })
    }

    /// Adds `shape` at `pose`; returns its handle. `group`/`mask` are 32-bit collision
    /// filter bits (two objects pair when each one's group meets the other's mask);
    /// `is_static` objects never pair with each other; `sensor` objects report events
    /// but no contact points. A shape pair without a contact algorithm (e.g. two meshes)
    /// raises `CaromError` here.
    #[pyo3(signature = (shape, pose = None, group = 1, mask = 0xFFFF_FFFF, is_static = false, sensor = false))]
    fn add(
        &mut self,
        shape: &Bound<'_, PyAny>,
        pose: Option<&Bound<'_, PyAny>>,
        #[pyo3(from_py_with = crate::convert::int_arg::<u32>)] group: u32,
        #[pyo3(from_py_with = crate::convert::int_arg::<u32>)] mask: u32,
        is_static: bool,
        sensor: bool,
    ) -> PyResult<u64> {
        let s = shape_arg(shape, "shape")?;
        let p = extract_isometry(pose, "pose")?;
        let filter = Filter {
            group,
            mask,
            is_static,
        };
        let h = core(|| self.world.add(s, p, filter))?;
        self.world.narrowphase_mut().set_sensor(h, sensor);
        Ok(bits(h))
    }

    /// Moves object `handle` to `pose` (taken into account by the next `step`).
    fn set_pose(&mut self, handle: Int<u64>, pose: &Bound<'_, PyAny>) -> PyResult<()> {
        let handle = handle.0;
        let p = extract_isometry(Some(pose), "pose")?;
        core(|| self.world.set_pose(self::handle(handle), p))
    }

    /// Moves many objects: `handles` (N ints) to `poses` (`(N, 7)`). Checked before any
    /// object moves: on an error nothing changes.
    fn set_poses(
        &mut self,
        #[pyo3(from_py_with = crate::convert::u64s_arg)] handles: Vec<u64>,
        poses: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        let (ps, single) = extract_poses(Some(poses), "poses")?;
        if single && handles.len() != 1 || ps.len() != handles.len() {
            return Err(invalid(format!(
                "poses must have shape ({}, 7) to match handles, got {} pose(s)",
                handles.len(),
                ps.len()
            )));
        }
        let isos: Vec<Isometry> = ps
            .iter()
            .enumerate()
            .map(|(i, p)| p.to_isometry(&format!("poses[{i}]")))
            .collect::<PyResult<_>>()?;
        for &h in &handles {
            core(|| self.world.get(handle(h)).map(|_| ()))?;
        }
        for (&h, p) in handles.iter().zip(isos) {
            core(|| self.world.set_pose(handle(h), p))?;
        }
        Ok(())
    }

    /// Removes object `handle`; its pairs end at the next `step` (with `end` events).
    fn remove(&mut self, handle: Int<u64>) -> PyResult<()> {
        let handle = handle.0;
        core(|| self.world.remove(self::handle(handle)).map(|_| ()))
    }

    /// The current pose of object `handle` as a `(7,)` array.
    fn pose<'py>(&self, py: Python<'py>, handle: Int<u64>) -> PyResult<Bound<'py, PyAny>> {
        let handle = handle.0;
        let o = core(|| self.world.get(self::handle(handle)))?;
        let p = crate::pose::Pose64::from_isometry(&o.pose).to_array();
        Ok(Array1::from_vec(p.to_vec()).into_pyarray(py).into_any())
    }

    /// Runs broadphase → midphase → narrowphase (GIL released) and returns every manifold
    /// point of every touching or nearly touching pair.
    fn step(&mut self, py: Python<'_>) -> PyResult<PyContacts> {
        let w = &mut self.world;
        py.detach(|| core(|| w.update().map(|_| ())))?;
        Ok(PyContacts::new(py, &self.contacts_now()))
    }

    /// The contact points of the last `step`.
    fn contacts(&self, py: Python<'_>) -> PyContacts {
        PyContacts::new(py, &self.contacts_now())
    }

    /// Begin, persist and end events of the last `step`.
    fn events(&self, py: Python<'_>) -> PyContactEvents {
        let mut by = [Vec::new(), Vec::new(), Vec::new()];
        for e in self.world.narrowphase().events() {
            let k = match e.kind {
                ContactEventKind::Begin => 0,
                ContactEventKind::Persist => 1,
                ContactEventKind::End => 2,
            };
            by[k].push((bits(e.a), bits(e.b)));
        }
        PyContactEvents::from_groups(py, &by)
    }

    /// The broadphase pairs (overlapping boxes, filters passed) as of the last `step`,
    /// `(P, 2)` int64 handles, sorted.
    fn pairs(&self, py: Python<'_>) -> Obj {
        let ps: Vec<(u64, u64)> = self
            .world
            .pairs()
            .into_iter()
            .map(|(a, b)| (bits(a), bits(b)))
            .collect();
        pairs_out(py, &ps)
    }

    /// The handles of the live objects, in slot order.
    fn handles(&self) -> Vec<u64> {
        self.world.iter().map(|(h, _)| bits(h)).collect()
    }

    /// The broadphase method's name.
    #[getter]
    fn method(&self) -> &'static str {
        self.world.broadphase().name()
    }

    fn __len__(&self) -> usize {
        self.world.len()
    }

    fn __repr__(&self) -> String {
        format!(
            "CollisionWorld(method={:?}, objects={})",
            self.method(),
            self.world.len()
        )
    }
}

/// Registers `contact_manifold`, `CollisionWorld` and their result classes.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyContacts>()?;
    m.add_class::<PyContactEvents>()?;
    m.add_class::<PyCollisionWorld>()?;
    m.add_function(wrap_pyfunction!(contact_manifold, m)?)?;
    Ok(())
}
