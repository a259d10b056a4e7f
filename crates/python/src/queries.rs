//! Module-level proximity queries: `carom.distance`, `contact`, `intersects`, `raycast`,
//! `project_point`, `shape_cast` and `time_of_impact`, thin wrappers of
//! `carom_collision::query`.
//!
//! Conventions (ARCHITECTURE.md, "Python conventions", identical to the core's
//! `query::result`): `distance` is signed (negative = minus the penetration depth) and
//! `normal` is the unit vector from A towards B, so `point_b = point_a + normal * distance`;
//! no sign conversion is needed. Given `(N, 7)` poses (or `(N, 3)` origins / points), the
//! same functions return one result object whose fields are numpy arrays of length N,
//! computed by the core's batch functions with the GIL released; rows without a result hold
//! NaN (and `False` in boolean fields).

use crate::convert::{scalar, vec3, vec3_out, vec3s, vec3s_out};
use crate::errors::core;
use crate::pose::{extract_poses, Pose64};
use crate::shape::PyShape;
use carom_collision::math::{Isometry, Real, Vec3};
use carom_collision::query::{self, Contact, Motion, PointProjection, RayHit, ShapeCastHit};
use carom_collision::shape::Shape;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyFloat};
use std::sync::Arc;

type Obj = Py<PyAny>;

fn f(py: Python<'_>, x: Real) -> Obj {
    PyFloat::new(py, f64::from(x)).into_any().unbind()
}
fn b(py: Python<'_>, x: bool) -> Obj {
    PyBool::new(py, x).to_owned().into_any().unbind()
}
fn v(py: Python<'_>, x: Vec3) -> Obj {
    vec3_out(py, x).into_any().unbind()
}
fn fs(py: Python<'_>, xs: impl Iterator<Item = Real>) -> Obj {
    PyArray1::from_vec(py, xs.map(f64::from).collect())
        .into_any()
        .unbind()
}
fn bs(py: Python<'_>, xs: impl Iterator<Item = bool>) -> Obj {
    PyArray1::from_vec(py, xs.collect()).into_any().unbind()
}
fn vs(py: Python<'_>, xs: impl Iterator<Item = Vec3>) -> Obj {
    let all: Vec<Vec3> = xs.collect();
    vec3s_out(py, &all).into_any().unbind()
}

const NAN3: Vec3 = Vec3::splat(Real::NAN);

/// Closest points or penetration between two shapes: `distance` (signed: negative when the
/// shapes overlap, minus the penetration depth), `point_a`, `point_b` (world witness points)
/// and `normal` (unit, from A towards B), with `point_b = point_a + normal * distance`.
/// For batches, `distance` is `(N,)` and the vectors `(N, 3)`.
#[pyclass(name = "Contact", module = "carom", frozen, get_all)]
pub struct PyContact {
    /// Signed distance (negative = minus the penetration depth).
    distance: Obj,
    /// Witness point on A (world).
    point_a: Obj,
    /// Witness point on B (world).
    point_b: Obj,
    /// Unit normal from A towards B (world).
    normal: Obj,
}

impl PyContact {
    fn one(py: Python<'_>, c: &Contact) -> Self {
        PyContact {
            distance: f(py, c.distance),
            point_a: v(py, c.point_a),
            point_b: v(py, c.point_b),
            normal: v(py, c.normal),
        }
    }

    fn many(py: Python<'_>, cs: &[Option<Contact>]) -> Self {
        let get = |g: fn(&Contact) -> Vec3| cs.iter().map(move |c| c.as_ref().map_or(NAN3, g));
        PyContact {
            distance: fs(py, cs.iter().map(|c| c.map_or(Real::NAN, |c| c.distance))),
            point_a: vs(py, get(|c| c.point_a)),
            point_b: vs(py, get(|c| c.point_b)),
            normal: vs(py, get(|c| c.normal)),
        }
    }
}

#[pymethods]
impl PyContact {
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!(
            "Contact(distance={}, normal={})",
            self.distance.bind(py).repr()?,
            self.normal.bind(py).repr()?
        ))
    }
}

/// A ray hit: `distance` along the unit direction, `point`, `normal` (outward, or `-direction`
/// when the ray starts inside a solid shape), `inside` (the origin was inside) and `feature`
/// (triangle index for meshes, child index for compounds, else -1). For batches, `hit` `(N,)`
/// bool marks the hits; misses hold NaN and `feature` -1.
#[pyclass(name = "RayHit", module = "carom", frozen, get_all)]
pub struct PyRayHit {
    /// True for a hit (`(N,)` in batches; always True for a single hit).
    hit: Obj,
    /// Distance along the unit direction.
    distance: Obj,
    /// The hit point (world).
    point: Obj,
    /// Unit surface normal at the hit point (world).
    normal: Obj,
    /// True when the origin was inside the (solid) shape.
    inside: Obj,
    /// Triangle (meshes) or child (compounds) index, -1 otherwise.
    feature: Obj,
}

fn feature(h: &RayHit) -> i64 {
    h.feature.map_or(-1, i64::from)
}

impl PyRayHit {
    fn one(py: Python<'_>, h: &RayHit) -> Self {
        PyRayHit {
            hit: b(py, true),
            distance: f(py, h.distance),
            point: v(py, h.point),
            normal: v(py, h.normal),
            inside: b(py, h.inside),
            feature: feature(h)
                .into_pyobject(py)
                .map_or_else(|_| py.None(), |x| x.into_any().unbind()),
        }
    }

    fn many(py: Python<'_>, hs: &[Option<RayHit>]) -> Self {
        PyRayHit {
            hit: bs(py, hs.iter().map(Option::is_some)),
            distance: fs(py, hs.iter().map(|h| h.map_or(Real::NAN, |h| h.distance))),
            point: vs(py, hs.iter().map(|h| h.map_or(NAN3, |h| h.point))),
            normal: vs(py, hs.iter().map(|h| h.map_or(NAN3, |h| h.normal))),
            inside: bs(py, hs.iter().map(|h| h.is_some_and(|h| h.inside))),
            feature: PyArray1::from_vec(
                py,
                hs.iter().map(|h| h.map_or(-1, |h| feature(&h))).collect(),
            )
            .into_any()
            .unbind(),
        }
    }
}

#[pymethods]
impl PyRayHit {
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!(
            "RayHit(distance={}, point={})",
            self.distance.bind(py).repr()?,
            self.point.bind(py).repr()?
        ))
    }
}

/// Projection of a point on a shape's boundary: `point` (closest boundary point, world),
/// `distance` (signed, negative inside) and `inside`. Arrays for batches.
#[pyclass(name = "PointProjection", module = "carom", frozen, get_all)]
pub struct PyPointProjection {
    /// Closest point on the boundary (world).
    point: Obj,
    /// Signed distance from the query point to the boundary (negative inside).
    distance: Obj,
    /// True when the query point is inside the shape or on its boundary.
    inside: Obj,
}

impl PyPointProjection {
    fn one(py: Python<'_>, p: &PointProjection) -> Self {
        PyPointProjection {
            point: v(py, p.point),
            distance: f(py, p.distance),
            inside: b(py, p.inside),
        }
    }

    fn many(py: Python<'_>, ps: &[PointProjection]) -> Self {
        PyPointProjection {
            point: vs(py, ps.iter().map(|p| p.point)),
            distance: fs(py, ps.iter().map(|p| p.distance)),
            inside: bs(py, ps.iter().map(|p| p.inside)),
        }
    }
}

/// Result of a shape cast or time of impact: `toi` (fraction of the motion), world witness
/// points `point_a`, `point_b` and `normal` (unit, A towards B) at that time, and
/// `initially_overlapping`. Arrays for batches.
#[pyclass(name = "ShapeCastHit", module = "carom", frozen, get_all)]
pub struct PyShapeCastHit {
    /// Time of impact as a fraction of the motion.
    toi: Obj,
    /// Witness point on A at the time of impact (world).
    point_a: Obj,
    /// Witness point on B at the time of impact (world).
    point_b: Obj,
    /// Unit normal from A towards B at the time of impact (world).
    normal: Obj,
    /// True when the shapes already overlapped at the start (`toi == 0`).
    initially_overlapping: Obj,
}

impl PyShapeCastHit {
    fn one(py: Python<'_>, h: &ShapeCastHit) -> Self {
        PyShapeCastHit {
            toi: f(py, h.toi),
            point_a: v(py, h.point_a),
            point_b: v(py, h.point_b),
            normal: v(py, h.normal),
            initially_overlapping: b(py, h.initially_overlapping),
        }
    }

    fn many(py: Python<'_>, hs: &[Option<ShapeCastHit>]) -> Self {
        PyShapeCastHit {
            toi: fs(py, hs.iter().map(|h| h.map_or(Real::NAN, |h| h.toi))),
            point_a: vs(py, hs.iter().map(|h| h.map_or(NAN3, |h| h.point_a))),
            point_b: vs(py, hs.iter().map(|h| h.map_or(NAN3, |h| h.point_b))),
            normal: vs(py, hs.iter().map(|h| h.map_or(NAN3, |h| h.normal))),
            initially_overlapping: bs(
                py,
                hs.iter()
                    .map(|h| h.is_some_and(|h| h.initially_overlapping)),
            ),
        }
    }
}

pub(crate) fn shape_arg(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Arc<Shape>> {
    obj.cast::<PyShape>()
        .map(|s| s.get().inner.clone())
        .map_err(|_| {
            let t = obj
                .get_type()
                .name()
                .map_or_else(|_| "object".to_string(), |n| n.to_string());
            pyo3::exceptions::PyTypeError::new_err(format!("{name} must be a carom.Shape, got {t}"))
        })
}

fn isos(poses: &[Pose64], name: &str) -> PyResult<Vec<Isometry>> {
    poses.iter().map(|p| p.to_isometry(name)).collect()
}

/// Two pose arguments: isometries and whether both were single poses.
fn pose_pair(
    pa: &Bound<'_, PyAny>,
    pb: &Bound<'_, PyAny>,
) -> PyResult<(Vec<Isometry>, Vec<Isometry>, bool)> {
    let (a, sa) = extract_poses(Some(pa), "pose_a")?;
    let (b, sb) = extract_poses(Some(pb), "pose_b")?;
    Ok((isos(&a, "pose_a")?, isos(&b, "pose_b")?, sa && sb))
}

/// The signed distance between shape `a` at `pose_a` and `b` at `pose_b` (poses: `Pose`,
/// `(7,)` or `(N, 7)`): a `Contact` (negative distance when overlapping). With `(N, 7)`
/// poses (the other may be single), a `Contact` of arrays (GIL released, parallel).
#[pyfunction]
pub fn distance(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    pose_a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    pose_b: &Bound<'_, PyAny>,
) -> PyResult<PyContact> {
    let (sa, sb) = (shape_arg(a, "a")?, shape_arg(b, "b")?);
    let (pa, pb, single) = pose_pair(pose_a, pose_b)?;
    if single {
        let c = core(|| query::distance(&sa, &pa[0], &sb, &pb[0]))?;
        return Ok(PyContact::one(py, &c));
    }
    let cs = py.detach(move || core(|| query::distance_batch(&sa, &pa, &sb, &pb)))?;
    let cs: Vec<Option<Contact>> = cs.into_iter().map(Some).collect();
    Ok(PyContact::many(py, &cs))
}

/// Like `distance`, but `None` when the shapes are further apart than `prediction` (>= 0;
/// default 0: only touching or overlapping shapes). Batches hold NaN rows for those.
#[pyfunction]
#[pyo3(signature = (a, pose_a, b, pose_b, prediction = 0.0))]
pub fn contact(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    pose_a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    pose_b: &Bound<'_, PyAny>,
    prediction: f64,
) -> PyResult<Option<PyContact>> {
    let (sa, sb) = (shape_arg(a, "a")?, shape_arg(b, "b")?);
    let (pa, pb, single) = pose_pair(pose_a, pose_b)?;
    let pred = scalar("prediction", prediction)?;
    if single {
        let c = core(|| query::contact(&sa, &pa[0], &sb, &pb[0], pred))?;
        return Ok(c.map(|c| PyContact::one(py, &c)));
    }
    let cs = py.detach(move || core(|| query::contact_batch(&sa, &pa, &sb, &pb, pred)))?;
    Ok(Some(PyContact::many(py, &cs)))
}

/// True when the shapes touch or overlap; with `(N, 7)` poses, an `(N,)` bool array.
#[pyfunction]
pub fn intersects<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    pose_a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    pose_b: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyAny>> {
    let (sa, sb) = (shape_arg(a, "a")?, shape_arg(b, "b")?);
    let (pa, pb, single) = pose_pair(pose_a, pose_b)?;
    if single {
        let hit = core(|| query::intersects(&sa, &pa[0], &sb, &pb[0]))?;
        return Ok(PyBool::new(py, hit).to_owned().into_any());
    }
    let hits = py.detach(move || core(|| query::intersects_batch(&sa, &pa, &sb, &pb)))?;
    Ok(PyArray1::from_vec(py, hits).into_any())
}

/// Casts a ray (`origin`, `direction` (3,), normalised; zero is an error) against `shape` at
/// `pose`, up to `max_distance` (>= 0, may be inf). `solid=True`: a ray starting inside hits
/// at distance 0; `solid=False`: it hits the boundary from inside. `None` on a miss. With
/// `(N, 3)` origins and directions, a `RayHit` of arrays with `.hit` (GIL released).
#[pyfunction]
#[pyo3(signature = (shape, pose, origin, direction, max_distance = f64::INFINITY, solid = true))]
pub fn raycast(
    py: Python<'_>,
    shape: &Bound<'_, PyAny>,
    pose: &Bound<'_, PyAny>,
    origin: &Bound<'_, PyAny>,
    direction: &Bound<'_, PyAny>,
    max_distance: f64,
    solid: bool,
) -> PyResult<Option<PyRayHit>> {
    let s = shape_arg(shape, "shape")?;
    let (p, sp) = extract_poses(Some(pose), "pose")?;
    if !sp {
        return Err(crate::errors::invalid(
            "pose must be a single pose for raycast (batches are over rays)",
        ));
    }
    let p = isos(&p, "pose")?[0];
    let md = scalar("max_distance", max_distance)?;
    let (o, so) = vec3s(origin, "origin", true)?;
    let (d, sd) = vec3s(direction, "direction", true)?;
    if so && sd {
        let h = core(|| query::raycast(&s, &p, o[0], d[0], md, solid))?;
        return Ok(h.map(|h| PyRayHit::one(py, &h)));
    }
    let hs = py.detach(move || core(|| query::raycast_batch(&s, &p, &o, &d, md, solid)))?;
    Ok(Some(PyRayHit::many(py, &hs)))
}

/// Projects `point` (3,) on the boundary of `shape` at `pose`: a `PointProjection` (signed
/// distance, negative inside). With `(N, 3)` points, arrays (GIL released).
#[pyfunction]
pub fn project_point(
    py: Python<'_>,
    shape: &Bound<'_, PyAny>,
    pose: &Bound<'_, PyAny>,
    point: &Bound<'_, PyAny>,
) -> PyResult<PyPointProjection> {
    let s = shape_arg(shape, "shape")?;
    let (p, sp) = extract_poses(Some(pose), "pose")?;
    if !sp {
        return Err(crate::errors::invalid(
            "pose must be a single pose for project_point (batches are over points)",
        ));
    }
    let p = isos(&p, "pose")?[0];
    let (pts, single) = vec3s(point, "point", true)?;
    if single {
        let r = core(|| query::project_point(&s, &p, pts[0]))?;
        return Ok(PyPointProjection::one(py, &r));
    }
    let rs = py.detach(move || core(|| query::project_point_batch(&s, &p, &pts)))?;
    Ok(PyPointProjection::many(py, &rs))
}

/// Linear shape cast: `a` moves by `velocity_a` and `b` by `velocity_b` per unit time, from
/// the given poses; the first time in `[0, max_time]` they touch, or `None`. With `(N, 7)`
/// poses and/or `(N, 3)` velocities (the others broadcast), a `ShapeCastHit` of arrays (NaN
/// `toi` for misses), GIL released.
#[pyfunction]
#[pyo3(signature = (a, pose_a, velocity_a, b, pose_b, velocity_b, max_time = 1.0))]
#[allow(clippy::too_many_arguments)]
pub fn shape_cast(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    pose_a: &Bound<'_, PyAny>,
    velocity_a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    pose_b: &Bound<'_, PyAny>,
    velocity_b: &Bound<'_, PyAny>,
    max_time: f64,
) -> PyResult<Option<PyShapeCastHit>> {
    let (sa, sb) = (shape_arg(a, "a")?, shape_arg(b, "b")?);
    let (pa, pb, single_poses) = pose_pair(pose_a, pose_b)?;
    let (va, sva) = vec3s(velocity_a, "velocity_a", true)?;
    let (vb, svb) = vec3s(velocity_b, "velocity_b", true)?;
    let t = scalar("max_time", max_time)?;
    if single_poses && sva && svb {
        let h = core(|| query::shape_cast(&sa, &pa[0], va[0], &sb, &pb[0], vb[0], t))?;
        return Ok(h.map(|h| PyShapeCastHit::one(py, &h)));
    }
    let hs =
        py.detach(move || core(|| query::shape_cast_batch(&sa, &pa, &va, &sb, &pb, &vb, t)))?;
    Ok(Some(PyShapeCastHit::many(py, &hs)))
}

/// Time of impact with rotation: each shape moves from its pose with a linear and an angular
/// velocity (rad per unit time, world axes, about the pose's origin); the first time in
/// `[0, max_time]` (finite) they come within `tolerance` (> 0), or `None`. Single poses.
#[pyfunction]
#[pyo3(signature = (a, pose_a, velocity_a, angular_velocity_a, b, pose_b, velocity_b,
                    angular_velocity_b, max_time = 1.0, tolerance = 1e-4))]
#[allow(clippy::too_many_arguments)]
pub fn time_of_impact(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    pose_a: &Bound<'_, PyAny>,
    velocity_a: &Bound<'_, PyAny>,
    angular_velocity_a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    pose_b: &Bound<'_, PyAny>,
    velocity_b: &Bound<'_, PyAny>,
    angular_velocity_b: &Bound<'_, PyAny>,
    max_time: f64,
    tolerance: f64,
) -> PyResult<Option<PyShapeCastHit>> {
    let (sa, sb) = (shape_arg(a, "a")?, shape_arg(b, "b")?);
    let pa = crate::pose::extract_isometry(Some(pose_a), "pose_a")?;
    let pb = crate::pose::extract_isometry(Some(pose_b), "pose_b")?;
    let (va, wa) = (
        vec3(velocity_a, "velocity_a")?,
        vec3(angular_velocity_a, "angular_velocity_a")?,
    );
    let (vb, wb) = (
        vec3(velocity_b, "velocity_b")?,
        vec3(angular_velocity_b, "angular_velocity_b")?,
    );
    let t = scalar("max_time", max_time)?;
    let tol = scalar("tolerance", tolerance)?;
    let ma = core(|| Motion::new(pa, va, wa))?;
    let mb = core(|| Motion::new(pb, vb, wb))?;
    let h = core(|| query::time_of_impact(&sa, &ma, &sb, &mb, t, tol))?;
    Ok(h.map(|h| PyShapeCastHit::one(py, &h)))
}

/// Registers the query functions and result classes.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyContact>()?;
    m.add_class::<PyRayHit>()?;
    m.add_class::<PyPointProjection>()?;
    m.add_class::<PyShapeCastHit>()?;
    m.add_function(wrap_pyfunction!(distance, m)?)?;
    m.add_function(wrap_pyfunction!(contact, m)?)?;
    m.add_function(wrap_pyfunction!(intersects, m)?)?;
    m.add_function(wrap_pyfunction!(raycast, m)?)?;
    m.add_function(wrap_pyfunction!(project_point, m)?)?;
    m.add_function(wrap_pyfunction!(shape_cast, m)?)?;
    m.add_function(wrap_pyfunction!(time_of_impact, m)?)?;
    Ok(())
}
