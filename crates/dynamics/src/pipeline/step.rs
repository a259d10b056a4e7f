//! [`World::step`] (one pipeline step) and [`World::step_simulation`] (fixed steps from a
//! variable frame time), with per-stage timings.

use super::World;
use crate::body::BodyType;
use crate::world::StepReport;
use carom_collision::math::{Real, Vec3};
use carom_collision::{CaromError, Result};
use std::time::{Duration, Instant};

/// Wall-clock time of each stage of the last [`World::step`] (like Bullet's
/// `CProfileManager` sections or Box2D's `b2Profile`).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PipelineTimings {
    /// Body poses and speculative margins to the collision objects, sleep hints.
    pub sync: Duration,
    /// Box updates and broadphase pairs.
    pub broadphase: Duration,
    /// Contact generation (persistent manifolds, parallel over pairs).
    pub narrowphase: Duration,
    /// Manifolds to solver contacts and impulses back (the adapter).
    pub contacts: Duration,
    /// Gravity and forces, constraint preparation, warm start, velocity iterations, relax
    /// and restitution.
    pub solver: Duration,
    /// Position integration.
    pub integrate: Duration,
    /// Islands, waking, sleeping, storing velocities, joint breaking.
    pub islands: Duration,
    /// Keeping the scene-query tree current: zero unless a query used it since the last
    /// step (see `pipeline::query_cache`).
    pub query_tree: Duration,
    /// The whole step.
    pub total: Duration,
}

/// What happened during the last [`World::step`].
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PipelineReport {
    /// Stage timings.
    pub timings: PipelineTimings,
    /// Broadphase pairs (manifolds kept by the narrowphase).
    pub pairs: usize,
    /// Manifolds handed to the solver.
    pub manifolds: usize,
    /// Contact points handed to the solver.
    pub contact_points: usize,
    /// The dynamics report: woken and slept bodies, broken joints, detailed solver timings.
    pub dynamics: StepReport,
}

impl World {
    /// Advances the world by `dt` through the whole pipeline (see the module docs of
    /// [`crate::pipeline`]). A non-finite or non-positive `dt` is rejected before anything
    /// changes.
    ///
    /// With [`crate::WorldParams::parallel`], [`super::PipelineParams::spin_workers`] and
    /// more than one thread in the current rayon pool, the pool's other threads are kept
    /// awake for the length of the step (`with_workers_awake`).
    pub fn step(&mut self, dt: Real) -> Result<&PipelineReport> {
        let dt = Self::check_dt("dt", dt)?;
        let spin = self.params.dynamics.parallel && self.params.spin_workers;
        with_workers_awake(spin, || self.run_step(dt))?;
        Ok(&self.report)
    }

    /// The body of [`World::step`] for a checked `dt`.
    fn run_step(&mut self, dt: Real) -> Result<()> {
        let start = Instant::now();
        // Bodies move from here on; the end of the step refreshes the query tree (an error
        // in between leaves it stale, never wrong).
        self.query_cache.moved();
        self.sync(dt)?;
        let t_sync = start.elapsed();

        self.collision.update()?;
        let ct = self.collision.timings();

        // Only the manifolds of awake bodies go to the solver; the islands also see the
        // touching pairs of sleeping ones, and when they wake bodies, the manifolds are
        // gathered again before the solver runs. A world whose dynamic bodies all sleep (no
        // kinematic body moving) hands nothing on and wakes nothing: no gather, no islands
        // (`island::Stillness::Idle`).
        let t = Instant::now();
        let bodies = self.dynamics.bodies();
        let stillness = crate::island::stillness(bodies);
        let checked = if stillness.idle() {
            self.contacts.clear();
            self.sources.clear();
            self.resting_pairs.clear();
            true
        } else {
            let islands = self.dynamics.islands_needed(dt);
            self.gather(islands)
        };
        let mut gather = t.elapsed();
        let begun = self.dynamics.begin_step(
            dt,
            &self.contacts,
            checked,
            &self.resting_pairs,
            stillness,
        )?;
        let regathered = (!begun.woken().is_empty()).then(|| {
            let t = Instant::now();
            let checked = self.gather(false);
            gather += t.elapsed();
            checked
        });
        let dyn_report = self
            .dynamics
            .finish_step(dt, &mut self.contacts, begun, regathered)?;

        let t = Instant::now();
        self.write_back();
        self.mark_landed();
        let contacts = gather + t.elapsed();
        // A broken joint lets its bodies collide again from the next step on.
        for &jh in &dyn_report.broken_joints {
            let desc = &self.dynamics.joints().get(jh)?.desc;
            if desc.disable_collisions {
                self.update_exclusion(desc.body_a, desc.body_b)?;
            }
        }

        let t = Instant::now();
        let query_tree = if self.refresh_query_tree() {
            t.elapsed()
        } else {
            Duration::ZERO
        };

        let d = &dyn_report.timings;
        self.report = PipelineReport {
            timings: PipelineTimings {
                sync: t_sync,
                broadphase: ct.broadphase,
                narrowphase: ct.narrowphase,
                contacts,
                solver: d.forces + d.prepare + d.warm_start + d.solve + d.relax + d.restitution,
                integrate: d.integrate,
                islands: d.islands + d.store,
                query_tree,
                total: start.elapsed(),
            },
            pairs: self.collision.narrowphase().len(),
            manifolds: self.contacts.len(),
            contact_points: self.contact_point_count(),
            dynamics: dyn_report,
        };
        Ok(())
    }

    /// Bullet's `btDiscreteDynamicsWorld::stepSimulation(timeStep, maxSubSteps,
    /// fixedTimeStep)`: adds `dt` to an accumulator and runs as many whole steps of
    /// `fixed_step` as it holds, at most `max_sub_steps` (time beyond that is dropped, so a
    /// slow frame does not snowball); the remainder waits for the next call
    /// ([`World::accumulator`]). Returns the number of steps taken. With `max_sub_steps == 0`
    /// it runs one step of `dt` instead (variable time step), as Bullet does.
    ///
    /// Interpolation-free: the body poses are those of the last completed fixed step, never
    /// extrapolated by the leftover time (Bullet interpolates motion states; a renderer that
    /// wants that can blend the last two poses by `accumulator() / fixed_step`).
    pub fn step_simulation(
        &mut self,
        dt: Real,
        max_sub_steps: u32,
        fixed_step: Real,
    ) -> Result<u32> {
        if !(dt.is_finite() && dt >= 0.0) {
            return Err(CaromError::invalid("dt", dt, "must be finite and >= 0"));
        }
        if max_sub_steps == 0 {
            if dt > 0.0 {
                self.step(dt)?;
                return Ok(1);
            }
            return Ok(0);
        }
        let fixed = Self::check_dt("fixed_step", fixed_step)?;
        self.accumulator += dt;
        let whole = (self.accumulator / fixed).floor();
        self.accumulator -= whole * fixed;
        let n = (whole as u64).min(max_sub_steps as u64) as u32;
        for _ in 0..n {
            self.step(fixed)?;
        }
        Ok(n)
    }

    /// Marks in `landed` the bodies that landed in this step: a solver contact with a
    /// speculative point (separation above half the base prediction) that took a positive
    /// normal impulse. The solver let that gap close in this step, no more, so the bodies
    /// meet at its end with the approach speed of about `separation / dt`, which the next
    /// step takes away. Bodies resting or sliding on one another (points at about zero
    /// separation) are not marked. Leaves `landed` empty when there are no contacts (an
    /// idle world pays nothing).
    fn mark_landed(&mut self) {
        self.landed.clear();
        if self.contacts.is_empty() {
            return;
        }
        let gap = 0.5 * self.params.manifold.prediction;
        self.landed.resize(self.object_of.len(), false);
        for m in &self.contacts {
            let landed = m
                .points()
                .iter()
                .any(|p| p.separation > gap && p.normal_impulse > 0.0);
            if landed {
                for h in [m.body_a, m.body_b] {
                    if let Some(p) = self.landed.get_mut(h.index as usize) {
                        *p = true;
                    }
                }
            }
        }
    }

    /// Copies the poses of moving bodies to their collision objects with speculative margins,
    /// and the sleep state to the broadphase's resting hints.
    #[inline(never)] // its own entry in profiles
    pub(super) fn sync(&mut self, dt: Real) -> Result<()> {
        let base = 0.5 * self.params.manifold.prediction;
        let speculative = self.params.speculative;
        for i in 0..self.object_of.len() {
            let Some(obj) = self.object_of[i] else {
                continue;
            };
            let set = self.dynamics.bodies();
            let info = &set.info[i];
            let moving = match info.body_type {
                BodyType::Dynamic => !info.sleeping,
                BodyType::Kinematic => true,
                BodyType::Static => false,
            };
            // The resting hint first: the two-tree broadphase migrates the leaf with its
            // current fat box, and the box update below then refits it in its new tree.
            let resting = !moving;
            let was_resting = self.resting[i];
            if resting != was_resting {
                self.collision.set_resting(obj, resting)?;
                self.resting[i] = resting;
            } else if was_resting && info.body_type == BodyType::Dynamic {
                // Asleep since the last sync, which zeroed its motion; its pose cannot have
                // changed since (`set_pose` wakes a body). (A world asleep: 1077 bodies of
                // "1000 stack" in 0.003 ms instead of 0.009.)
                continue;
            }
            let pose = set.pose_of(i);
            if moving {
                // The rotation's sweep goes into the margin, the linear displacement into
                // the motion: a pair's speculative distance counts the two bodies' relative
                // displacement (a falling column's boxes get none from their common speed).
                // The margin (the box's expansion, kept by snapshots) covers both; the motion
                // lets a pair take the linear part relative to the other body.
                let (spin, motion) = if speculative {
                    let (v, w) = (set.linear_velocity[i], set.angular_velocity[i]);
                    (w.length() * self.radius[i] * dt, v * dt)
                } else {
                    (0.0, Vec3::ZERO)
                };
                // A body that landed on another in the last step may be stopped in this one
                // while a body moving with it is not (the layers of a pyramid landing one
                // on another): its pairs count both cases (`may_stop`).
                let may_stop = self.landed.get(i) == Some(&true);
                // Pose, margin, motion, box and broadphase proxy in one call.
                self.collision.sync_object(
                    obj,
                    pose,
                    base + spin + motion.length(),
                    motion,
                    may_stop,
                )?;
            } else {
                let o = self.collision.get(obj)?;
                let (teleported, has_motion) = (o.pose != pose, o.motion != Vec3::ZERO);
                if teleported {
                    // A static body teleported through `bodies_mut().set_pose`, or a body
                    // that fell asleep in the last step: the object still has the pose of
                    // the sync before that step's integration (within v·dt of the body's,
                    // below the sleep thresholds), and keeps the body's final one while it
                    // sleeps.
                    self.collision.set_pose(obj, pose)?;
                }
                // Asleep or static: no motion (what a restored snapshot starts from too).
                if has_motion {
                    self.collision.set_motion(obj, Vec3::ZERO)?;
                }
            }
        }
        Ok(())
    }
}

/// Runs `f` while the other threads of the current rayon pool stay awake: with `on`, the
/// `parallel` feature and more than one thread, `f` runs beside keepers, one per other
/// thread, that take the pool's pending jobs (`rayon::yield_now`) and otherwise spin until
/// `f` returns. Without them, a pool thread that finds no work goes to sleep within
/// microseconds, and the next parallel loop of the step (the narrowphase, the gather's two
/// passes, the solver's region, the write-back: several a step, between serial stages)
/// waits for it to be woken: 16–50 µs on the bench's two-vCPU host (a `rayon::join` whose
/// second half a sleeping thread steals), so short loops ran on one thread. This is what a
/// game engine's job system does during its step (Box2D v3's and Jolt's workers spin
/// between tasks). The results do not depend on it (the keepers only run jobs the step
/// would have run anyway); the cost is the other cores spinning for the length of the step.
pub(crate) fn with_workers_awake<R: Send>(on: bool, f: impl FnOnce() -> R + Send) -> R {
    #[cfg(feature = "parallel")]
    if on && rayon::current_num_threads() > 1 {
        use std::sync::atomic::{AtomicBool, Ordering};
        let done = AtomicBool::new(false);
        let keepers = rayon::current_num_threads() - 1;
        /// Releases the keepers when `f` returns or unwinds (a panic must not leave them
        /// spinning, and `join` waits for them before it rethrows).
        struct Release<'a>(&'a AtomicBool);
        impl Drop for Release<'_> {
            fn drop(&mut self) {
                self.0.store(true, Ordering::Release);
            }
        }
        let (r, ()) = rayon::join(
            || {
                let _release = Release(&done);
                f()
            },
            || keep_awake(keepers, &done),
        );
        return r;
    }
    let _ = on;
    f()
}

/// `n` keepers (see [`with_workers_awake`]): this thread and, forked with `rayon::join`,
/// `n - 1` more, each taking pending jobs or spinning until `done`. A keeper that no thread
/// took before `done` is run by the thread that forked it and returns at once.
#[cfg(feature = "parallel")]
fn keep_awake(n: usize, done: &std::sync::atomic::AtomicBool) {
    use std::sync::atomic::Ordering;
    let spin = || {
        while !done.load(Ordering::Acquire) {
            if rayon::yield_now() != Some(rayon::Yield::Executed) {
                std::hint::spin_loop();
            }
        }
    };
    if n <= 1 {
        spin();
    } else {
        rayon::join(spin, || keep_awake(n - 1, done));
    }
}

#[cfg(all(test, feature = "parallel"))]
mod tests {
    use super::with_workers_awake;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// On 1 to 4 threads: the value comes back, the parallel work inside runs (every item
    /// once), and a panic inside reaches the caller instead of leaving the keepers spinning
    /// (the test would hang).
    #[test]
    fn the_work_runs_once_and_a_panic_comes_back() {
        use rayon::prelude::*;
        for threads in 1..=4 {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            for on in [false, true] {
                let hits: Vec<AtomicUsize> = (0..1000).map(|_| AtomicUsize::new(0)).collect();
                let sum = pool.install(|| {
                    with_workers_awake(on, || {
                        (0..1000usize)
                            .into_par_iter()
                            .map(|i| {
                                hits[i].fetch_add(1, Ordering::Relaxed);
                                i
                            })
                            .sum::<usize>()
                    })
                });
                assert_eq!(sum, 999 * 1000 / 2);
                assert!(hits.iter().all(|h| h.load(Ordering::Relaxed) == 1));
                let caught = pool.install(|| {
                    std::panic::catch_unwind(|| {
                        with_workers_awake(on, || -> usize { panic!("a step failed") })
                    })
                });
                assert!(caught.is_err(), "{threads} threads, on {on}");
            }
        }
    }
}
