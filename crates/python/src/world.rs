//! Rigid-body simulation from Python: `carom.World`, a thin wrapper of
//! `carom_dynamics::World` (broadphase → narrowphase → warm-started solver → integration,
//! islands and sleeping, speculative contacts against tunnelling).
//!
//! Bodies are Python ints (slot and generation packed like object handles: stale handles
//! are rejected). Poses are `(N, 7)` arrays `[x, y, z, qx, qy, qz, qw]` as everywhere in
//! `carom`; bulk getters and setters take and return numpy arrays in one call, in the order
//! of the given handles (or of `handles()`).

use crate::convert::{scalar, vec3, vec3s, vec3s_out};
use crate::errors::{core, invalid};
use crate::pose::{extract_isometry, extract_poses, Pose64};
use crate::queries::shape_arg;
use carom_collision::broadphase::{Filter, Method};
use carom_collision::math::{check_finite_vec, Isometry, Real};
use carom_dynamics::{BodyDesc, BodyHandle, BodyType, MassSpec, PipelineParams, World};
use numpy::ndarray::Array2;
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;

fn bits(h: BodyHandle) -> u64 {
    (u64::from(h.generation) << 32) | u64::from(h.index)
}

fn handle(b: u64) -> BodyHandle {
    BodyHandle {
        index: b as u32,
        generation: (b >> 32) as u32,
    }
}

/// A rigid-body world. `gravity` (3,) in m/s², `dt` the step of `step()` in seconds,
/// `method` the broadphase ("hgrid", "grid", "tree", "tree_manhattan", "sap",
/// "sort_sweep", "brute_force"), `sleeping` whether resting islands fall asleep.
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
    #[pyo3(signature = (gravity = None, dt = 1.0 / 60.0, method = "hgrid", sleeping = true))]
    fn new(
        gravity: Option<&Bound<'_, PyAny>>,
        dt: f64,
        method: &str,
        sleeping: bool,
    ) -> PyResult<Self> {
        let mut params = PipelineParams::default();
        if let Some(g) = gravity {
            params.dynamics.gravity = vec3(g, "gravity")?;
        }
        params.dynamics.sleep.enabled = sleeping;
        params.broadphase = core(|| method.parse::<Method>())?;
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
    /// `group`/`mask` are 32-bit collision filter bits.
    #[pyo3(signature = (
        shape, pose = None, mass = None, density = 1000.0, friction = 0.5, restitution = 0.0,
        is_static = false, kinematic = false, linear_velocity = None, angular_velocity = None,
        linear_damping = 0.0, angular_damping = 0.0, group = 1, mask = 0xFFFF_FFFF
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
        group: u32,
        mask: u32,
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
    fn remove_body(&mut self, handle: u64) -> PyResult<()> {
        core(|| self.world.remove_body(self::handle(handle)).map(|_| ()))
    }

    /// Advances the world by `n` steps of `dt` (GIL released).
    #[pyo3(signature = (n = 1))]
    fn step(&mut self, py: Python<'_>, n: u32) -> PyResult<()> {
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
        max_sub_steps: u32,
        fixed_step: Option<f64>,
    ) -> PyResult<u32> {
        let e = scalar("elapsed", elapsed)?;
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
        handles: Option<Vec<u64>>,
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
        handles: Option<Vec<u64>>,
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
    fn set_poses(&mut self, handles: Vec<u64>, poses: &Bound<'_, PyAny>) -> PyResult<()> {
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
        handles: Vec<u64>,
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
        for (i, (v, w)) in lin.iter().zip(&ang).enumerate() {
            core(|| check_finite_vec(&format!("linear[{i}]"), *v).map(|_| ()))?;
            core(|| check_finite_vec(&format!("angular[{i}]"), *w).map(|_| ()))?;
        }
        let hs = self.handles_arg(Some(handles))?;
        let bodies = self.world.bodies_mut();
        for ((h, v), w) in hs.into_iter().zip(lin).zip(ang) {
            core(|| bodies.set_linear_velocity(h, v))?;
            core(|| bodies.set_angular_velocity(h, w))?;
        }
        Ok(())
    }

    /// Applies an impulse (N·s, world frame) at a world `point` of body `handle`.
    fn apply_impulse(
        &mut self,
        handle: u64,
        impulse: &Bound<'_, PyAny>,
        point: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        let (j, p) = (vec3(impulse, "impulse")?, vec3(point, "point")?);
        core(|| {
            self.world
                .bodies_mut()
                .apply_impulse(self::handle(handle), j, p)
        })
    }

    /// Whether body `handle` is asleep.
    fn is_sleeping(&self, handle: u64) -> PyResult<bool> {
        core(|| self.world.bodies().is_sleeping(self::handle(handle)))
    }

    /// Per-stage wall times of the last step in milliseconds (`sync`, `broadphase`,
    /// `narrowphase`, `contacts`, `solver`, `integrate`, `islands`, `total`), plus the
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
            ("total", t.total),
        ] {
            d.set_item(k, v.as_secs_f64() * 1e3)?;
        }
        d.set_item("pairs", r.pairs)?;
        d.set_item("manifolds", r.manifolds)?;
        d.set_item("points", r.contact_points)?;
        Ok(d)
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
    fn __contains__(&self, handle: u64) -> bool {
        self.world.bodies().contains(self::handle(handle))
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
