//! Rigid-body simulation from Python: `carom.World`, a thin wrapper of
//! `carom_dynamics::World` (broadphase → narrowphase → warm-started solver → integration,
//! islands and sleeping, speculative contacts against tunnelling).
//!
//! Bodies are Python ints (slot and generation packed like object handles: stale handles
//! are rejected). Poses are `(N, 7)` arrays `[x, y, z, qx, qy, qz, qw]` as everywhere in
//! `carom`; bulk getters and setters take and return numpy arrays in one call, in the order
//! of the given handles (or of `handles()`).
//!
//! Joints (`add_joint`, argument parsing in `world_joints`), contact events and points, ray
//! and shape casts (`world_queries`), and snapshots: `to_bytes()` is a short header holding
//! the `dt` of `step()` followed by `carom_dynamics::World::to_bytes`; pickling goes through
//! it (`__reduce__` → `World()` + `__setstate__(bytes)`), so a restored world continues
//! bit for bit.

use crate::convert::Int;
use crate::convert::{scalar, vec3, vec3s, vec3s_out};
use crate::errors::{core, guard, invalid};
use crate::pose::{extract_isometry, extract_poses, Pose64};
use crate::queries::shape_arg;
use crate::world_joints::{joint_bits, joint_desc, joint_handle, JointOptions};
use crate::world_queries::{bits, PyWorldContacts, PyWorldRayHit, PyWorldShapeCastHit};
use crate::world_snapshot::{decode, encode};
use carom_collision::broadphase::{Filter, Method};
use carom_collision::math::{Isometry, Real};
use carom_dynamics::{BodyDesc, BodyHandle, BodyType, MassSpec, PipelineParams, SolverKind, World};
use numpy::ndarray::Array2;
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyTuple};

fn handle(b: u64) -> BodyHandle {
    BodyHandle {
        index: b as u32,
        generation: (b >> 32) as u32,
    }
}

/// A rigid-body world. `gravity` (3,) in m/s², `dt` the step of `step()` in seconds,
/// `method` the broadphase ("tree", the default, "tree_manhattan", "hgrid", "grid",
/// "sap", "sort_sweep", "brute_force"), `sleeping` whether resting islands fall asleep,
/// `sleep_linear` (m/s) and `sleep_angular` (rad/s) the speeds under which a body rests,
/// `sleep_drift` (m) how far a body may move from where its rest began and still rest
/// whatever its speed (0 turns that rule off), `sleep_time` (s) how long a whole island must
/// rest before it sleeps, `solver` "soft_step" (Box2D v3's substepping soft step, the default) or "sequential_impulse"
/// (Bullet's, with split impulses). `substeps` (soft step) and `iterations` (sequential
/// impulses: velocity and split-impulse iterations) set the solver's effort, each in 1..=1000;
/// `simd` solves contacts four at a time in SIMD lanes (the same physics as the scalar path);
/// `parallel` lets a step use rayon's threads (results are bit-identical either way), and
/// `spin_workers` keeps those threads awake for the length of each step (they take its
/// parallel work at once instead of being woken for each loop; the other cores spin meanwhile).
///
/// `add_body(shape, pose, ...)` returns an int handle; `step(n)` advances `n` steps of
/// `dt`; `poses()` / `velocities()` read every body in one call, `set_poses` /
/// `set_velocities` write them. Bad values raise `CaromError` (a `ValueError`) naming the
/// value and change nothing.
#[pyclass(name = "World", module = "carom")]
pub struct PyWorld {
    world: World,
    dt: Real,
}

impl PyWorld {
    fn handles_arg(&self, handles: Option<Vec<u64>>) -> PyResult<Vec<BodyHandle>> {
        match handles {
            None => Ok(self.world.handles()),
            Some(hs) => {
                let hs: Vec<BodyHandle> = hs.into_iter().map(handle).collect();
                for &h in &hs {
                    core(|| self.world.bodies().slot(h).map(|_| ()))?;
                }
                Ok(hs)
            }
        }
    }
}

#[pymethods]
impl PyWorld {
    #[new]
    #[pyo3(signature = (
        gravity = None, dt = 1.0 / 60.0, method = "tree", sleeping = true, solver = "soft_step",
        substeps = 4, iterations = 10, simd = true, parallel = true, sleep_linear = 0.05,
        sleep_angular = 0.05, sleep_drift = 0.015, sleep_time = 0.5, spin_workers = true
    ))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        gravity: Option<&Bound<'_, PyAny>>,
        dt: f64,
        method: &str,
        sleeping: bool,
        solver: &str,
        #[pyo3(from_py_with = crate::convert::int_arg::<i64>)] substeps: i64,
        #[pyo3(from_py_with = crate::convert::int_arg::<i64>)] iterations: i64,
        simd: bool,
        parallel: bool,
        sleep_linear: f64,
        sleep_angular: f64,
        sleep_drift: f64,
        sleep_time: f64,
        spin_workers: bool,
    ) -> PyResult<Self> {
        let mut params = PipelineParams::default();
        if let Some(g) = gravity {
            params.dynamics.gravity = vec3(g, "gravity")?;
        }
        let non_negative = |name: &str, x: f64| {
            let r = scalar(name, x)?;
            if r >= 0.0 && r.is_finite() {
                Ok(r)
            } else {
                Err(invalid(format!("{name} = {x} must be finite and >= 0")))
            }
        };
        let sleep = &mut params.dynamics.sleep;
        sleep.enabled = sleeping;
        sleep.linear_threshold = non_negative("sleep_linear", sleep_linear)?;
        sleep.angular_threshold = non_negative("sleep_angular", sleep_angular)?;
        sleep.drift = non_negative("sleep_drift", sleep_drift)?;
        sleep.time_to_sleep = non_negative("sleep_time", sleep_time)?;
        params.broadphase = core(|| method.parse::<Method>())?;
        params.dynamics.solver.kind = match solver {
            "soft_step" => SolverKind::SoftStep,
            "sequential_impulse" => SolverKind::SequentialImpulse,
            other => {
                return Err(invalid(format!(
                    "invalid solver = {other:?}: expected \"soft_step\" or \"sequential_impulse\""
                )))
            }
        };
        let count = |name: &str, n: i64| {
            u32::try_from(n)
                .ok()
                .filter(|n| (1..=1000).contains(n))
                .ok_or_else(|| invalid(format!("{name} = {n} must be in 1..=1000")))
        };
        let s = &mut params.dynamics.solver;
        s.substeps = count("substeps", substeps)?;
        s.velocity_iterations = count("iterations", iterations)?;
        s.position_iterations = s.velocity_iterations;
        s.simd = simd;
        params.dynamics.parallel = parallel;
        params.spin_workers = spin_workers;
        let dt_r = scalar("dt", dt)?;
        if !(dt_r > 0.0 && dt_r.is_finite()) {
            return Err(invalid(format!("dt must be finite and > 0, got {dt}")));
        }
        let world = core(|| World::new(params))?;
        Ok(PyWorld { world, dt: dt_r })
    }

    /// Adds a body with `shape` at `pose`; returns its handle. Dynamic bodies get their
    /// mass from `mass` (kg, > 0) if given, else from `density` (kg/m³) and the shape's
    /// volume; `is_static` bodies never move; `kinematic` bodies move only by their
    /// velocity. `friction` (>= 0) and `restitution` (in [0, 1]) combine by product and max.
    /// `group`/`mask` are 32-bit collision filter bits. `gravity_scale` multiplies the
    /// world gravity for this body; `max_linear_speed` (m/s) and `max_angular_speed` (rad/s)
    /// clamp its speeds after the solve; `user_data` is any 64-bit integer, read back with
    /// `user_data(handle)`.
    #[pyo3(signature = (
        shape, pose = None, mass = None, density = 1000.0, friction = 0.5, restitution = 0.0,
        is_static = false, kinematic = false, linear_velocity = None, angular_velocity = None,
        linear_damping = 0.0, angular_damping = 0.0, group = 1, mask = 0xFFFF_FFFF,
        gravity_scale = 1.0, max_linear_speed = 400.0, max_angular_speed = 100.0, user_data = 0
    ))]
    #[allow(clippy::too_many_arguments)]
    fn add_body(
        &mut self,
        shape: &Bound<'_, PyAny>,
        pose: Option<&Bound<'_, PyAny>>,
        mass: Option<f64>,
        density: f64,
        friction: f64,
        restitution: f64,
        is_static: bool,
        kinematic: bool,
        linear_velocity: Option<&Bound<'_, PyAny>>,
        angular_velocity: Option<&Bound<'_, PyAny>>,
        linear_damping: f64,
        angular_damping: f64,
        #[pyo3(from_py_with = crate::convert::int_arg::<u32>)] group: u32,
        #[pyo3(from_py_with = crate::convert::int_arg::<u32>)] mask: u32,
        gravity_scale: f64,
        max_linear_speed: f64,
        max_angular_speed: f64,
        #[pyo3(from_py_with = crate::convert::int_arg::<u64>)] user_data: u64,
    ) -> PyResult<u64> {
        if is_static && kinematic {
            return Err(invalid(
                "a body cannot be both is_static and kinematic".to_string(),
            ));
        }
        let s = shape_arg(shape, "shape")?;
        let mut desc = BodyDesc {
            shape: Some(s),
            pose: extract_isometry(pose, "pose")?,
            body_type: if is_static {
                BodyType::Static
            } else if kinematic {
                BodyType::Kinematic
            } else {
                BodyType::Dynamic
            },
            mass: match mass {
                Some(m) => MassSpec::Mass(scalar("mass", m)?),
                None => MassSpec::Density(scalar("density", density)?),
            },
            friction: scalar("friction", friction)?,
            restitution: scalar("restitution", restitution)?,
            linear_damping: scalar("linear_damping", linear_damping)?,
            angular_damping: scalar("angular_damping", angular_damping)?,
            gravity_scale: scalar("gravity_scale", gravity_scale)?,
            max_linear_speed: scalar("max_linear_speed", max_linear_speed)?,
            max_angular_speed: scalar("max_angular_speed", max_angular_speed)?,
            user_data,
            filter: Filter {
                group,
                mask,
                is_static,
            },
            ..Default::default()
        };
        if let Some(v) = linear_velocity {
            desc.linear_velocity = vec3(v, "linear_velocity")?;
        }
        if let Some(w) = angular_velocity {
            desc.angular_velocity = vec3(w, "angular_velocity")?;
        }
        let h = core(|| self.world.add_body(&desc))?;
        Ok(bits(h))
    }

    /// Removes body `handle` (and every joint attached to it).
    fn remove_body(&mut self, handle: Int<u64>) -> PyResult<()> {
        let handle = handle.0;
        core(|| self.world.remove_body(self::handle(handle)).map(|_| ()))
    }

    /// Advances the world by `n` steps of `dt` (GIL released).
    #[pyo3(signature = (n = 1))]
    fn step(
        &mut self,
        py: Python<'_>,
        #[pyo3(from_py_with = crate::convert::int_arg::<u32>)] n: u32,
    ) -> PyResult<()> {
        let (w, dt) = (&mut self.world, self.dt);
        py.detach(|| {
            core(|| {
                for _ in 0..n {
                    w.step(dt)?;
                }
                Ok(())
            })
        })
    }

    /// Bullet's `stepSimulation`: adds `elapsed` seconds to the accumulator and runs as many
    /// fixed steps of `fixed_step` (default `dt`) as fit, at most `max_sub_steps` (leftover
    /// time is dropped beyond that); returns the number of steps taken.
    #[pyo3(signature = (elapsed, max_sub_steps = 1, fixed_step = None))]
    fn step_simulation(
        &mut self,
        py: Python<'_>,
        elapsed: f64,
        #[pyo3(from_py_with = crate::convert::int_arg::<u32>)] max_sub_steps: u32,
        fixed_step: Option<f64>,
    ) -> PyResult<u32> {
        let e = scalar("elapsed", elapsed)?;
        if !(e.is_finite() && e >= 0.0) {
            return Err(invalid(format!(
                "invalid elapsed = {elapsed:?}: must be finite and >= 0"
            )));
        }
        let f = match fixed_step {
            Some(f) => scalar("fixed_step", f)?,
            None => self.dt,
        };
        let w = &mut self.world;
        py.detach(|| core(|| w.step_simulation(e, max_sub_steps, f)))
    }

    /// The live bodies' handles, in slot order (the order of `poses()` and `velocities()`).
    fn handles(&self) -> Vec<u64> {
        self.world.handles().into_iter().map(bits).collect()
    }

    /// Poses as an `(N, 7)` array `[x, y, z, qx, qy, qz, qw]`, of `handles` or of every
    /// body (in `handles()` order).
    #[pyo3(signature = (handles = None))]
    fn poses<'py>(
        &self,
        py: Python<'py>,
        #[pyo3(from_py_with = crate::convert::opt_u64s_arg)] handles: Option<Vec<u64>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let hs = self.handles_arg(handles)?;
        let mut rows = Vec::with_capacity(hs.len());
        for h in hs {
            let p = core(|| self.world.bodies().pose(h))?;
            rows.push(Pose64::from_isometry(&p).to_array());
        }
        Ok(Array2::from_shape_fn((rows.len(), 7), |(i, j)| rows[i][j])
            .into_pyarray(py)
            .into_any())
    }

    /// `(linear, angular)` velocities, two `(N, 3)` arrays (m/s, rad/s, world frame).
    #[pyo3(signature = (handles = None))]
    fn velocities<'py>(
        &self,
        py: Python<'py>,
        #[pyo3(from_py_with = crate::convert::opt_u64s_arg)] handles: Option<Vec<u64>>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let hs = self.handles_arg(handles)?;
        let mut lin = Vec::with_capacity(hs.len());
        let mut ang = Vec::with_capacity(hs.len());
        for h in hs {
            lin.push(core(|| self.world.bodies().linear_velocity(h))?);
            ang.push(core(|| self.world.bodies().angular_velocity(h))?);
        }
        Ok((
            vec3s_out(py, &lin).into_any(),
            vec3s_out(py, &ang).into_any(),
        ))
    }

    /// Teleports bodies `handles` to `poses` (`(N, 7)`), waking them. Everything is
    /// checked before any body moves.
    fn set_poses(
        &mut self,
        #[pyo3(from_py_with = crate::convert::u64s_arg)] handles: Vec<u64>,
        poses: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        let (ps, _) = extract_poses(Some(poses), "poses")?;
        if ps.len() != handles.len() {
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
        let hs = self.handles_arg(Some(handles))?;
        for (h, p) in hs.into_iter().zip(isos) {
            core(|| self.world.set_pose(h, p))?;
        }
        Ok(())
    }

    /// Sets the linear and angular velocities (`(N, 3)` each) of bodies `handles`.
    /// Everything is checked before any body changes.
    fn set_velocities(
        &mut self,
        #[pyo3(from_py_with = crate::convert::u64s_arg)] handles: Vec<u64>,
        linear: &Bound<'_, PyAny>,
        angular: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        let (lin, _) = vec3s(linear, "linear", true)?;
        let (ang, _) = vec3s(angular, "angular", true)?;
        if lin.len() != handles.len() || ang.len() != handles.len() {
            return Err(invalid(format!(
                "linear and angular must have shape ({}, 3) to match handles, got {} and {}",
                handles.len(),
                lin.len(),
                ang.len()
            )));
        }
        let hs = self.handles_arg(Some(handles))?;
        let items: Vec<_> = hs
            .into_iter()
            .zip(lin)
            .zip(ang)
            .map(|((h, v), w)| (h, v, w))
            .collect();
        core(|| self.world.bodies_mut().set_velocities(&items))
    }

    /// Applies an impulse (N·s, world frame) at a world `point` of body `handle`.
    fn apply_impulse(
        &mut self,
        handle: Int<u64>,
        impulse: &Bound<'_, PyAny>,
        point: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        let handle = handle.0;
        let (j, p) = (vec3(impulse, "impulse")?, vec3(point, "point")?);
        core(|| {
            self.world
                .bodies_mut()
                .apply_impulse(self::handle(handle), j, p)
        })
    }

    /// Adds a force (N, world frame) for the next step, at the centre of mass or at a world
    /// `point` (adding its torque); wakes the body.
    #[pyo3(signature = (handle, force, point = None))]
    fn add_force(
        &mut self,
        handle: Int<u64>,
        force: &Bound<'_, PyAny>,
        point: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let handle = handle.0;
        let f = vec3(force, "force")?;
        let p = point.map(|p| vec3(p, "point")).transpose()?;
        let bodies = self.world.bodies_mut();
        let h = self::handle(handle);
        core(|| match p {
            Some(p) => bodies.add_force_at_point(h, f, p),
            None => bodies.add_force(h, f),
        })
    }

    /// Adds a torque (N·m, world frame) for the next step; wakes the body.
    fn add_torque(&mut self, handle: Int<u64>, torque: &Bound<'_, PyAny>) -> PyResult<()> {
        let handle = handle.0;
        let t = vec3(torque, "torque")?;
        core(|| self.world.bodies_mut().add_torque(self::handle(handle), t))
    }

    /// The `user_data` integer body `handle` was created with.
    fn user_data(&self, handle: Int<u64>) -> PyResult<u64> {
        let handle = handle.0;
        core(|| {
            self.world
                .bodies()
                .info(self::handle(handle))
                .map(|i| i.user_data)
        })
    }

    /// Whether body `handle` is asleep.
    fn is_sleeping(&self, handle: Int<u64>) -> PyResult<bool> {
        let handle = handle.0;
        core(|| self.world.bodies().is_sleeping(self::handle(handle)))
    }

    /// Per-stage wall times of the last step in milliseconds (`sync`, `broadphase`,
    /// `narrowphase`, `contacts`, `solver`, `integrate`, `islands`, `query_tree`, `total`), plus the
    /// counts of `pairs`, `manifolds` and `points`.
    fn last_step<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let r = self.world.last_report();
        let t = &r.timings;
        let d = PyDict::new(py);
        for (k, v) in [
            ("sync", t.sync),
            ("broadphase", t.broadphase),
            ("narrowphase", t.narrowphase),
            ("contacts", t.contacts),
            ("solver", t.solver),
            ("integrate", t.integrate),
            ("islands", t.islands),
            ("query_tree", t.query_tree),
            ("total", t.total),
        ] {
            d.set_item(k, v.as_secs_f64() * 1e3)?;
        }
        d.set_item("pairs", r.pairs)?;
        d.set_item("manifolds", r.manifolds)?;
        d.set_item("points", r.contact_points)?;
        Ok(d)
    }

    /// Adds a joint between bodies `body_a` and `body_b` (at least one dynamic); returns its
    /// handle. `kind`: "ball" (point to point), "hinge" (rotation about the frames' Z axis;
    /// `limits=(low, high)` rad, `motor=(speed, max_torque)`), "cone_twist" (`swing1` about
    /// frame Z, `swing2` about frame Y, `twist` about frame X, rad, all required), "slider"
    /// (translation along frame A's X; `limits` m, `motor=(speed, max_force)`), "fixed", or
    /// "6dof" (`linear` and `angular`: three axes each, x, y, z of frame A, each "locked",
    /// "free", `(low, high)` or a dict with `limits`, `motor=(speed, max_force)`,
    /// `spring=(hertz, damping_ratio, rest)`). `frame_a`/`frame_b` are the joint frames in
    /// each body's frame (poses, default identity). The joint breaks once one of its
    /// impulses in a step exceeds `break_impulse` (N·s); `disable_collisions` turns off
    /// contacts between the two bodies. Options that do not apply to `kind` raise.
    #[pyo3(signature = (
        kind, body_a, body_b, frame_a = None, frame_b = None, limits = None, motor = None,
        swing1 = None, swing2 = None, twist = None, linear = None, angular = None,
        break_impulse = f64::INFINITY, disable_collisions = true
    ))]
    #[allow(clippy::too_many_arguments)]
    fn add_joint(
        &mut self,
        kind: &str,
        body_a: Int<u64>,
        body_b: Int<u64>,
        frame_a: Option<&Bound<'_, PyAny>>,
        frame_b: Option<&Bound<'_, PyAny>>,
        limits: Option<(f64, f64)>,
        motor: Option<(f64, f64)>,
        swing1: Option<f64>,
        swing2: Option<f64>,
        twist: Option<f64>,
        linear: Option<&Bound<'_, PyAny>>,
        angular: Option<&Bound<'_, PyAny>>,
        break_impulse: f64,
        disable_collisions: bool,
    ) -> PyResult<u64> {
        let body_a = body_a.0;
        let body_b = body_b.0;
        let opts = JointOptions {
            frame_a,
            frame_b,
            limits,
            motor,
            swing1,
            swing2,
            twist,
            linear,
            angular,
            break_impulse,
            disable_collisions,
        };
        let desc = joint_desc(kind, handle(body_a), handle(body_b), &opts)?;
        let h = core(|| self.world.create_joint(&desc))?;
        Ok(joint_bits(h))
    }

    /// Removes joint `joint` (wakes its bodies).
    fn remove_joint(&mut self, joint: Int<u64>) -> PyResult<()> {
        let joint = joint.0;
        core(|| self.world.remove_joint(joint_handle(joint)))
    }

    /// The live joints' handles, in slot order (joints attached to a removed body are
    /// removed with it).
    fn joints(&self) -> Vec<u64> {
        self.world
            .joints()
            .iter()
            .map(|(h, _)| joint_bits(h))
            .collect()
    }

    /// Whether `joint` is a live joint.
    fn has_joint(&self, joint: Int<u64>) -> bool {
        let joint = joint.0;
        self.world.joints().get(joint_handle(joint)).is_ok()
    }

    /// Whether `joint` has broken (its impulse exceeded `break_impulse`); a broken joint no
    /// longer acts.
    fn is_joint_broken(&self, joint: Int<u64>) -> PyResult<bool> {
        let joint = joint.0;
        core(|| {
            self.world
                .joints()
                .get(joint_handle(joint))
                .map(|j| j.broken)
        })
    }

    /// The two bodies `(body_a, body_b)` of `joint`.
    fn joint_bodies(&self, joint: Int<u64>) -> PyResult<(u64, u64)> {
        let joint = joint.0;
        let j = core(|| self.world.joints().get(joint_handle(joint)))?;
        Ok((bits(j.desc.body_a), bits(j.desc.body_b)))
    }

    /// Contact events of the last step with body handles: `begin`, `persist` and `end`, each
    /// an `(E, 2)` int64 array of `(body_a, body_b)` pairs, in pair order.
    fn contact_events(&self, py: Python<'_>) -> crate::collision_world::PyContactEvents {
        crate::world_queries::contact_events(py, &self.world)
    }

    /// The contact points of the last step with the solver's impulses (see `WorldContacts`).
    fn contacts(&self, py: Python<'_>) -> PyWorldContacts {
        crate::world_queries::contacts(py, &self.world)
    }

    /// Casts rays against every body (closest hit, current poses). One `(3,)` origin and
    /// direction: a `WorldRayHit` or `None` on a miss. `(N, 3)` origins and directions (or
    /// one direction for all): a `WorldRayHit` of arrays (GIL released). Only bodies whose
    /// `group` meets `mask` are hit; a ray starting inside a body hits it at distance 0.
    #[pyo3(signature = (origins, directions, max_distance = f64::INFINITY, mask = 0xFFFF_FFFF))]
    fn raycast(
        &self,
        py: Python<'_>,
        origins: &Bound<'_, PyAny>,
        directions: &Bound<'_, PyAny>,
        max_distance: f64,
        #[pyo3(from_py_with = crate::convert::int_arg::<u32>)] mask: u32,
    ) -> PyResult<Option<PyWorldRayHit>> {
        let md = scalar("max_distance", max_distance)?;
        let (o, so) = vec3s(origins, "origins", true)?;
        let (d, sd) = vec3s(directions, "directions", true)?;
        if so && sd {
            let h = core(|| self.world.raycast(o[0], d[0], md, mask))?;
            return Ok(h.map(|h| PyWorldRayHit::one(py, &h)));
        }
        let w = &self.world;
        let hs = py.detach(|| core(|| w.raycast_batch(&o, &d, md, mask)))?;
        Ok(Some(PyWorldRayHit::many(py, &hs)))
    }

    /// Sweeps `shape` from `pose` with `velocity` (per unit time, no rotation) over times
    /// `[0, max_time]` against every body whose `group` meets `mask`: the first hit as a
    /// `WorldShapeCastHit`, or `None`. A body overlapping at the start is hit at time 0.
    #[pyo3(signature = (shape, pose, velocity, max_time = 1.0, mask = 0xFFFF_FFFF))]
    fn shape_cast(
        &self,
        py: Python<'_>,
        shape: &Bound<'_, PyAny>,
        pose: &Bound<'_, PyAny>,
        velocity: &Bound<'_, PyAny>,
        max_time: f64,
        #[pyo3(from_py_with = crate::convert::int_arg::<u32>)] mask: u32,
    ) -> PyResult<Option<PyWorldShapeCastHit>> {
        let s = shape_arg(shape, "shape")?;
        let p = extract_isometry(Some(pose), "pose")?;
        let v = vec3(velocity, "velocity")?;
        let t = scalar("max_time", max_time)?;
        let w = &self.world;
        let h = py.detach(|| core(|| w.shape_cast(&s, &p, v, t, mask)))?;
        Ok(h.map(|h| PyWorldShapeCastHit::new(py, &h)))
    }

    /// The whole world as bytes (bodies, joints, contacts with their warm-starting
    /// impulses, sleep state, the accumulator of `step_simulation`, `dt`):
    /// `World.from_bytes(data)` continues bit for bit as if never stopped.
    fn to_bytes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let out = encode(&self.world, self.dt)?;
        Ok(PyBytes::new(py, &out))
    }

    /// Restores a world from `to_bytes()`; corrupt or truncated bytes raise `CaromError`.
    #[staticmethod]
    fn from_bytes(data: &[u8]) -> PyResult<PyWorld> {
        let (world, dt) = guard(|| decode(data))?;
        Ok(PyWorld { world, dt })
    }

    /// Pickle support: the state is `to_bytes()`.
    fn __getstate__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        self.to_bytes(py)
    }

    /// Pickle support: replaces this world with the one in `state` (bytes of `to_bytes()`).
    fn __setstate__(&mut self, state: &[u8]) -> PyResult<()> {
        let (world, dt) = guard(|| decode(state))?;
        self.world = world;
        self.dt = dt;
        Ok(())
    }

    /// Pickle support: `(World, (), state)`.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let state = slf.borrow().to_bytes(py)?;
        let cls = slf.get_type();
        PyTuple::new(
            py,
            [
                cls.into_any(),
                PyTuple::empty(py).into_any(),
                state.into_any(),
            ],
        )
    }

    /// The step of `step()`, seconds.
    #[getter]
    fn dt(&self) -> f64 {
        f64::from(self.dt)
    }

    /// Number of bodies.
    fn __len__(&self) -> usize {
        self.world.bodies().len()
    }

    /// Whether `handle` is a live body.
    fn __contains__(&self, handle: &Bound<'_, PyAny>) -> bool {
        // Anything but a handle (a bool, a negative or too large int, another type) is not
        // in the world.
        !handle.is_instance_of::<pyo3::types::PyBool>()
            && matches!(handle.extract::<u64>(), Ok(h) if self.world.bodies().contains(self::handle(h)))
    }

    fn __repr__(&self) -> String {
        format!(
            "World({} bodies, dt={}, {} asleep)",
            self.world.bodies().len(),
            self.dt,
            self.world.sleeping_count()
        )
    }
}
