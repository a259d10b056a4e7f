//! [`DynamicsWorld`]: bodies, joints and the step pipeline, fed with contacts from outside.
//!
//! `step(dt, contacts)` runs: validate → islands (wake) → gravity and forces → prepare
//! constraints → warm start → solve velocities → integrate → relax / split impulses →
//! restitution → write back impulses → joint breaking → sleeping, with per-stage timings.

use crate::body::{BodyDesc, BodyType};
use crate::body_set::{BodyHandle, BodySet};
use crate::contact::ContactManifold;
use crate::integrate;
use crate::island::{self, SleepParams};
use crate::joint::{JointDesc, JointHandle, JointSet};
use crate::solver::joints::JointScratch;
use crate::solver::{
    self, SolverBody, SolverKind, SolverParams, SolverScratch, StepContext, StepTimings,
};
use carom_collision::math::{check_finite_vec, Real, Vec3};
use carom_collision::{CaromError, Result};
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// World settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WorldParams {
    /// Gravity, m/s².
    pub gravity: Vec3,
    /// Solver choice and settings.
    pub solver: SolverParams,
    /// Sleeping settings.
    pub sleep: SleepParams,
    /// Include the gyroscopic term, solved implicitly in body space with one Newton step
    /// (Bullet's `computeGyroscopicImpulseImplicit_Body`), which keeps fast, thin spinning
    /// bodies stable.
    pub gyroscopic: bool,
    /// Use the current rayon pool's threads in the solver (with the `parallel` feature): the
    /// soft step's stages and the building of its constraints, or the large colours of
    /// sequential impulses. Results are bit-identical either way.
    pub parallel: bool,
}

impl Default for WorldParams {
    fn default() -> Self {
        WorldParams {
            gravity: Vec3::new(0.0, -9.81, 0.0),
            solver: SolverParams::default(),
            sleep: SleepParams::default(),
            gyroscopic: true,
            parallel: true,
        }
    }
}

/// A step between [`DynamicsWorld::begin_step`] and [`DynamicsWorld::finish_step`]: when it
/// began, whether islands were built, and the report so far (the woken bodies).
#[derive(Debug)]
pub(crate) struct BegunStep {
    start: Instant,
    islands: bool,
    /// Every live body static or asleep ([`island::Stillness::Frozen`]).
    frozen: bool,
    report: StepReport,
}

impl BegunStep {
    /// Bodies woken so far (by contacts, joints or user calls).
    pub(crate) fn woken(&self) -> &[BodyHandle] {
        &self.report.woken
    }
}

/// What changed during a step.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StepReport {
    /// Bodies woken since the last step, by contacts, joints or user calls (the broadphase
    /// moves them to its active tree).
    pub woken: Vec<BodyHandle>,
    /// Bodies that fell asleep this step (to the broadphase's resting tree).
    pub slept: Vec<BodyHandle>,
    /// Joints that broke this step.
    pub broken_joints: Vec<JointHandle>,
    /// Per-stage timings.
    pub timings: StepTimings,
}

/// Rigid bodies and joints, stepped with externally generated contacts.
#[derive(Debug, Clone)]
pub struct DynamicsWorld {
    bodies: BodySet,
    joints: JointSet,
    params: WorldParams,
    solver_bodies: Vec<SolverBody>,
    /// The solver's constraint and colouring buffers, reused from step to step.
    solver_scratch: SolverScratch,
    /// The solver's joint rows, reused from step to step.
    joint_scratch: JointScratch,
    /// The islands' union-find and sleep buffers, reused from step to step.
    islands: island::IslandScratch,
}

impl DynamicsWorld {
    /// An empty world.
    pub fn new(params: WorldParams) -> Result<Self> {
        Self::check_params(&params)?;
        Ok(DynamicsWorld {
            bodies: BodySet::new(),
            joints: JointSet::default(),
            params,
            solver_bodies: Vec::new(),
            solver_scratch: SolverScratch::default(),
            joint_scratch: JointScratch::default(),
            islands: island::IslandScratch::default(),
        })
    }

    /// A world made of restored parts (a snapshot): the structure of both sets is checked.
    pub(crate) fn from_parts(
        params: WorldParams,
        bodies: BodySet,
        joints: JointSet,
    ) -> Result<Self> {
        Self::check_params(&params)?;
        bodies.check_structure()?;
        joints.check_structure()?;
        Ok(DynamicsWorld {
            bodies,
            joints,
            params,
            solver_bodies: Vec::new(),
            // Per-step buffers only (rebuilt every step): a restored world starts empty.
            solver_scratch: SolverScratch::default(),
            joint_scratch: JointScratch::default(),
            islands: island::IslandScratch::default(),
        })
    }

    fn check_params(p: &WorldParams) -> Result<()> {
        check_finite_vec("gravity", p.gravity)?;
        p.solver.validate()?;
        p.sleep.validate()
    }

    /// The settings.
    pub fn params(&self) -> &WorldParams {
        &self.params
    }

    /// Replaces the settings (validated).
    pub fn set_params(&mut self, params: WorldParams) -> Result<()> {
        Self::check_params(&params)?;
        self.params = params;
        Ok(())
    }

    /// Selects the solver.
    pub fn set_solver(&mut self, kind: SolverKind) {
        self.params.solver.kind = kind;
    }

    /// The bodies.
    pub fn bodies(&self) -> &BodySet {
        &self.bodies
    }

    /// The bodies, mutable (forces, impulses, velocities, poses).
    pub fn bodies_mut(&mut self) -> &mut BodySet {
        &mut self.bodies
    }

    /// The joints.
    pub fn joints(&self) -> &JointSet {
        &self.joints
    }

    /// Creates a body.
    pub fn create_body(&mut self, desc: &BodyDesc) -> Result<BodyHandle> {
        self.bodies.insert(desc)
    }

    /// Removes a body and every joint attached to it; returns the removed joints.
    pub fn remove_body(&mut self, h: BodyHandle) -> Result<Vec<JointHandle>> {
        self.bodies.slot(h)?;
        let attached: Vec<JointHandle> = self
            .joints
            .iter()
            .filter(|(_, j)| j.desc.body_a == h || j.desc.body_b == h)
            .map(|(jh, _)| jh)
            .collect();
        for &jh in &attached {
            self.joints.remove(jh)?;
        }
        self.bodies.remove(h)?;
        Ok(attached)
    }

    /// Creates a joint between two live bodies.
    pub fn create_joint(&mut self, desc: &JointDesc) -> Result<JointHandle> {
        desc.validate()?;
        let a = self.bodies.slot(desc.body_a)?;
        let b = self.bodies.slot(desc.body_b)?;
        let info = |i: usize| self.bodies.info[i].body_type;
        if info(a) != BodyType::Dynamic && info(b) != BodyType::Dynamic {
            return Err(CaromError::invalid(
                "joint.body_b",
                desc.body_b,
                "a joint needs at least one dynamic body",
            ));
        }
        self.bodies.wake_slot(a);
        self.bodies.wake_slot(b);
        Ok(self.joints.insert(desc.clone()))
    }

    /// Removes a joint (wakes its bodies).
    pub fn remove_joint(&mut self, h: JointHandle) -> Result<()> {
        let j = self.joints.remove(h)?;
        for body in [j.desc.body_a, j.desc.body_b] {
            if let Ok(i) = self.bodies.slot(body) {
                self.bodies.wake_slot(i);
            }
        }
        Ok(())
    }

    /// Whether contacts between `a` and `b` should be generated: both live, at least one
    /// dynamic, and no joint between them disables collisions. The collision side filters its
    /// pairs with this.
    pub fn should_collide(&self, a: BodyHandle, b: BodyHandle) -> bool {
        let (Ok(ia), Ok(ib)) = (self.bodies.slot(a), self.bodies.slot(b)) else {
            return false;
        };
        let dynamic = |i: usize| self.bodies.info[i].body_type == BodyType::Dynamic;
        a != b && (dynamic(ia) || dynamic(ib)) && !self.joints.collision_disabled(a, b)
    }

    /// Advances the world by `dt` with the given contacts. Reads the accumulated impulses of
    /// each manifold (warm start) and writes this step's back. All input is validated before
    /// anything changes.
    pub fn step(&mut self, dt: Real, contacts: &mut [ContactManifold]) -> Result<StepReport> {
        self.step_gathered(dt, contacts, false)
    }

    /// [`DynamicsWorld::step`] for contacts that are known to pass its per-manifold checks
    /// when `checked` (the pipeline's adapter tests the same conditions while it copies the
    /// manifolds, see `pipeline/contacts.rs`); with `checked` false, exactly `step`.
    pub(crate) fn step_gathered(
        &mut self,
        dt: Real,
        contacts: &mut [ContactManifold],
        checked: bool,
    ) -> Result<StepReport> {
        let stillness = island::stillness(&self.bodies);
        let begun = self.begin_step(dt, contacts, checked, &[], stillness)?;
        self.finish_step(dt, contacts, begun, None)
    }

    /// The first part of a step: checks everything (nothing changes on an error), then
    /// builds the islands from the contacts with points, the `resting` pairs (body slots
    /// touching without a manifold handed on) and the joints, and wakes the sleeping islands
    /// that hold an awake body. [`DynamicsWorld::finish_step`] solves with the contacts; the
    /// pipeline gathers them again between the two when this woke a body, since it hands
    /// only the manifolds of awake bodies to the solver. `stillness` is the bodies'
    /// [`island::stillness`] as the step begins (the pipeline has it from its gather).
    pub(crate) fn begin_step(
        &mut self,
        dt: Real,
        contacts: &[ContactManifold],
        checked: bool,
        resting: &[(usize, usize)],
        stillness: island::Stillness,
    ) -> Result<BegunStep> {
        let start = Instant::now();
        if !(dt.is_finite() && dt > 0.0) {
            return Err(CaromError::invalid("dt", dt, "must be finite and > 0"));
        }
        self.check_contacts(contacts, checked)?;
        for (jh, j) in self.joints.iter() {
            if !self.bodies.contains(j.desc.body_a) || !self.bodies.contains(j.desc.body_b) {
                return Err(CaromError::UnknownHandle(format!("a body of joint {jh:?}")));
            }
        }
        let mut report = StepReport::default();
        let frozen = stillness == island::Stillness::Frozen;
        let islands = !stillness.idle() && self.islands_needed(dt);
        if islands {
            let touching = (contacts, resting);
            island::build(&self.bodies, touching, &self.joints, &mut self.islands);
            report.woken = island::wake_islands(&mut self.bodies, &mut self.islands, touching);
        } else {
            report.woken = island::user_woken(&mut self.bodies);
        }
        report.timings.islands = start.elapsed();
        Ok(BegunStep {
            start,
            islands,
            frozen,
            report,
        })
    }

    /// Whether a step of `dt` needs the islands ([`island::needed`]).
    pub(crate) fn islands_needed(&mut self, dt: Real) -> bool {
        island::needed(&mut self.bodies, &self.params.sleep, dt)
    }

    /// Every manifold's checks (see [`DynamicsWorld::step_gathered`] for `checked`).
    fn check_contacts(&self, contacts: &[ContactManifold], checked: bool) -> Result<()> {
        for (k, m) in contacts.iter().enumerate() {
            // The full check (which names the bad value) only for a manifold that fails the
            // cheap one; both accept the same manifolds, the cheap one possibly fewer.
            if checked {
                debug_assert!(plausible(m, &self.bodies), "contacts[{k}]: {m:?}");
            } else if !plausible(m, &self.bodies) {
                m.validate(k, &self.bodies)?;
            }
        }
        Ok(())
    }

    /// The rest of a step begun by [`DynamicsWorld::begin_step`] with the same `dt`:
    /// integration, the solver and sleeping, with `contacts`: those of `begin_step`
    /// (`regathered` `None`), or gathered again after it woke bodies (`Some(checked)`,
    /// checked as `begin_step` checks; an error then leaves the woken bodies awake and
    /// changes nothing else).
    pub(crate) fn finish_step(
        &mut self,
        dt: Real,
        contacts: &mut [ContactManifold],
        begun: BegunStep,
        regathered: Option<bool>,
    ) -> Result<StepReport> {
        let BegunStep {
            start,
            islands,
            frozen,
            mut report,
        } = begun;
        if let Some(checked) = regathered {
            self.check_contacts(contacts, checked)?;
        }
        // Nothing can move when every body is static or asleep (a force on a sleeping
        // body would have woken it) and no contact is handed on: the solver skips the
        // joints of sleeping bodies and would only clear the forces, and no timer
        // advances. So such a step skips the solver and the sleep update ("1000 stack"
        // asleep: 0.055 -> 0.021 ms a step with the narrowphase's settled events).
        let still = frozen && contacts.is_empty() && report.woken.is_empty();
        if still {
            integrate::clear_forces(&mut self.bodies, usize::MAX);
        } else {
            self.solve(dt, contacts, &mut report);
        }

        let t = Instant::now();
        for (jh, j) in self.joints.iter_mut() {
            // The peak of the step's impulse, summed over its substeps (`joints::store`;
            // a joint the solver skipped keeps the peak it had).
            if !j.broken && j.step_peak > j.desc.break_impulse {
                j.broken = true;
                report.broken_joints.push(jh);
            }
        }
        if !still {
            report.slept = island::update_sleep(
                &mut self.bodies,
                &mut self.islands,
                dt,
                &self.params.sleep,
                islands,
            );
        }
        report.timings.store += t.elapsed();
        report.timings.total = start.elapsed();
        Ok(report)
    }

    /// Integration and the constraint solver over the awake bodies (the solvers store the
    /// velocities and world inertias and clear the forces).
    fn solve(&mut self, dt: Real, contacts: &mut [ContactManifold], report: &mut StepReport) {
        integrate::load(&self.bodies, &mut self.solver_bodies);
        let mut ctx = StepContext {
            set: &mut self.bodies,
            bodies: &mut self.solver_bodies,
            manifolds: contacts,
            joints: &mut self.joints,
            gravity: self.params.gravity,
            dt,
            params: &self.params.solver,
            gyroscopic: self.params.gyroscopic,
            parallel: self.params.parallel,
            timings: &mut report.timings,
            scratch: &mut self.solver_scratch,
            joint_scratch: &mut self.joint_scratch,
        };
        match self.params.solver.kind {
            SolverKind::SequentialImpulse => solver::sequential::step(&mut ctx),
            SolverKind::SoftStep => solver::soft_step::step(&mut ctx),
        }
    }

    /// A hash of every body's position, rotation and velocities (bit patterns), for
    /// determinism checks.
    pub fn state_hash(&self) -> u64 {
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        let mut eat = |x: Real| {
            for byte in x.to_le_bytes() {
                h ^= byte as u64;
                h = h.wrapping_mul(0x0000_0100_0000_01b3);
            }
        };
        let b = &self.bodies;
        for i in 0..b.capacity() {
            let q = b.rotation[i];
            for v in [b.position[i], b.linear_velocity[i], b.angular_velocity[i]] {
                v.to_array().into_iter().for_each(&mut eat);
            }
            q.to_array().into_iter().for_each(&mut eat);
        }
        h
    }
}

/// A cheap sufficient test for [`ContactManifold::validate`]: live distinct bodies, a unit
/// normal (within a tighter tolerance than `validate`'s), a finite tangent, friction and
/// restitution in range, and every point value finite. The finiteness of the twenty-odd
/// values is one sum of `0 · x` terms (zero exactly when all are finite, NaN otherwise),
/// without a branch per value: `validate` on every manifold of every step was 2.5 % of the
/// instructions of "1000 stack".
fn plausible(m: &ContactManifold, bodies: &BodySet) -> bool {
    let zero = |v: Vec3| (v * 0.0).element_sum();
    let mut finite = zero(m.normal) + zero(m.tangent) + m.friction * 0.0;
    for p in m.points() {
        finite += zero(p.local_a)
            + zero(p.local_b)
            + (p.separation + p.normal_impulse + p.tangent_impulse[0] + p.tangent_impulse[1]) * 0.0;
    }
    // The sum of the four scalars may overflow to infinity (0 · ∞ is NaN): then the full
    // check decides.
    finite == 0.0
        && (m.normal.length_squared() - 1.0).abs() <= 1.0e-3
        && m.friction >= 0.0
        && (0.0..=1.0).contains(&m.restitution)
        && m.body_a != m.body_b
        && bodies.contains(m.body_a)
        && bodies.contains(m.body_b)
}

#[cfg(test)]
mod plausible_tests {
    use super::*;
    use crate::contact::ContactPoint;
    use carom_collision::math::Isometry;
    use carom_collision::shape::{Shape, Sphere};
    use std::sync::Arc;

    /// Every single-value corruption of a valid manifold: the cheap test must never accept
    /// what `validate` rejects, and must accept the valid manifold itself.
    #[test]
    fn the_cheap_check_accepts_only_what_validate_accepts() {
        let mut w = DynamicsWorld::new(WorldParams::default()).unwrap();
        let shape = Arc::new(Shape::from(Sphere::new(0.5).unwrap()));
        let a = w
            .create_body(&BodyDesc::dynamic(shape.clone(), Isometry::IDENTITY, 1.0))
            .unwrap();
        let b = w
            .create_body(&BodyDesc::dynamic(shape, Isometry::IDENTITY, 1.0))
            .unwrap();
        let mut good = ContactManifold::new(a, b, Vec3::new(0.0, 0.6, 0.8));
        for k in 0..4 {
            let mut p = ContactPoint::new(Vec3::splat(k as Real), -Vec3::X, -0.01, k);
            p.normal_impulse = 2.0;
            p.tangent_impulse = [0.5, -0.5];
            good.push(p).unwrap();
        }
        assert!(plausible(&good, w.bodies()));
        assert!(good.validate(0, w.bodies()).is_ok());
        let bad_values = [
            Real::NAN,
            Real::INFINITY,
            Real::NEG_INFINITY,
            Real::MAX,
            -Real::MAX,
            -1.0,
            2.0,
            0.0,
        ];
        let mut checked = 0;
        for &x in &bad_values {
            // Each scalar slot of the manifold in turn.
            for slot in 0..(3 + 3 + 2 + 4 * 10) {
                let mut m = good.clone();
                match slot {
                    0..=2 => m.normal[slot] = x,
                    3..=5 => m.tangent[slot - 3] = x,
                    6 => m.friction = x,
                    7 => m.restitution = x,
                    _ => {
                        let (k, f) = ((slot - 8) / 10, (slot - 8) % 10);
                        let p = &mut m.points_mut()[k];
                        match f {
                            0..=2 => p.local_a[f] = x,
                            3..=5 => p.local_b[f - 3] = x,
                            6 => p.separation = x,
                            7 => p.normal_impulse = x,
                            _ => p.tangent_impulse[f - 8] = x,
                        }
                    }
                }
                if plausible(&m, w.bodies()) {
                    assert!(
                        m.validate(0, w.bodies()).is_ok(),
                        "slot {slot} = {x}: the cheap check accepted an invalid manifold"
                    );
                } else if !x.is_finite() {
                    assert!(m.validate(0, w.bodies()).is_err(), "slot {slot} = {x}");
                }
                checked += 1;
            }
        }
        assert!(checked > 300);
        // Huge finite impulses whose sum overflows: not cheap, yet valid.
        let mut m = good.clone();
        m.points_mut()[0].normal_impulse = Real::MAX;
        m.points_mut()[0].separation = Real::MAX;
        assert!(!plausible(&m, w.bodies()));
        assert!(m.validate(0, w.bodies()).is_ok());
        // Handles: the same body twice, a removed body.
        let mut m = good.clone();
        m.body_b = a;
        assert!(!plausible(&m, w.bodies()));
        assert!(m.validate(0, w.bodies()).is_err());
        w.bodies_mut().remove(b).unwrap();
        assert!(!plausible(&good, w.bodies()));
        assert!(good.validate(0, w.bodies()).is_err());
    }
}
