//! [`World`]: rigid bodies, joints and collision detection in one step pipeline.
//!
//! The bundled world of the architecture: a [`DynamicsWorld`] (bodies, joints, solver,
//! islands) and a [`CollisionWorld`] (one collision object per body with a shape, a
//! broadphase, a narrowphase with persistent manifolds). [`World::step`] runs the talks'
//! pipeline, in the order of Box2D v3's `b2World_Step` (collide, then solve) and Bullet's
//! `btDiscreteDynamicsWorld::internalSingleStepSimulation`:
//!
//! 1. **sync** (module `step`): the pose of every awake body goes to its collision object,
//!    with a speculative margin covering its motion over the step (`|v|·dt + |ω|·dt·r`) and
//!    its linear displacement (`v·dt`), and
//!    sleeping bodies are hinted resting (the broadphase moves them to its resting tree, the
//!    narrowphase stops updating pairs of two resting objects);
//! 2. **broadphase and narrowphase** ([`CollisionWorld::update`]): boxes expanded by the
//!    margins, pairs, persistent manifolds with points up to the two margins apart, with
//!    the pair's *relative* linear motion `|v_a − v_b|·dt` in place of `(|v_a| + |v_b|)·dt`
//!    (speculative contacts; bodies moving together get none, unless one of them has just
//!    landed and may stop: its pairs count that case too), updated in parallel over pairs;
//! 3. **contacts** (module `contacts`): the persistent manifolds become the solver's
//!    [`ContactManifold`]s in a reused buffer, skipping sensors, pairs without a dynamic body
//!    and pairs whose joint disables collisions; their accumulated impulses warm-start;
//! 4. **solve and integrate** ([`DynamicsWorld::step`]): gravity, constraints, integration,
//!    islands and sleeping;
//! 5. **write back**: the new impulses go into the persistent manifold points, so the next
//!    step warm-starts from them.
//!
//! ## Contact convention at the dynamics boundary
//!
//! The narrowphase keeps the talk's point (normal on B, from B towards A). The dynamics side
//! has one convention: [`ContactManifold::normal`] points **from A to B**, like
//! `query::Contact`, and positive impulses push B along it. The adapter flips the normal of
//! the deepest point once per manifold, and maps the friction impulses between the
//! narrowphase's fixed tangent basis `orthonormal_basis(n_B)` and the solver's
//! `(t₁, n × t₁)` (the second component changes sign with the normal). An adapter was chosen
//! over making the solver read narrowphase manifolds directly: the solver stays testable with
//! hand-made contacts, and the copy costs far less than contact generation.
//!
//! ## Continuous collision
//!
//! Speculative contacts (Catto, "Continuous Collision", GDC 2013; Box2D v3 and Rapier's
//! "soft CCD"): a pair's contact points are generated up to the distance both bodies can
//! travel towards each other in the step, and the solver lets the gap close but not more, so
//! a fast body stops at the surface it would have crossed. No body is flagged: every body
//! gets a margin from its own speed; a pair counts the relative linear displacement
//! `|v_a − v_b|·dt` (plus each body's rotational sweep), not the sum of both speeds.

mod contacts;
#[cfg(test)]
mod contacts_tests;
pub mod queries;
mod query_cache;
mod scene;
pub mod snapshot;
mod step;

pub use queries::{BodyRayHit, BodyShapeCastHit, WorldQuery};
pub use snapshot::{SNAPSHOT_MAGIC, SNAPSHOT_VERSION};
pub use step::{PipelineReport, PipelineTimings};

use crate::body::{BodyDesc, BodyType};
use crate::body_set::{BodyHandle, BodySet};
use crate::contact::ContactManifold;
use crate::joint::{JointDesc, JointHandle, JointSet};
use crate::world::{DynamicsWorld, WorldParams};
use carom_collision::broadphase::Method;
use carom_collision::math::{Isometry, Real};
use carom_collision::narrowphase::ManifoldConfig;
use carom_collision::world::{CollisionWorld, ObjectHandle};
use carom_collision::{CaromError, Result};

/// Settings of a [`World`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PipelineParams {
    /// Gravity, solver, sleeping.
    pub dynamics: WorldParams,
    /// Broadphase method.
    pub broadphase: Method,
    /// Contact generation: `prediction` is the base speculative distance (Box2D's
    /// `B2_SPECULATIVE_DISTANCE`, 4 × linear slop = 2 cm).
    pub manifold: ManifoldConfig,
    /// Speculative contacts over each body's motion (continuous collision). Off, contacts
    /// are generated only within `manifold.prediction`, and fast bodies may tunnel.
    pub speculative: bool,
    /// With `dynamics.parallel` and more than one thread in the current rayon pool, keep the
    /// pool's other threads awake for the length of each step: they take the step's
    /// parallel work as soon as it appears, and spin in between (as a game engine's job
    /// system does). Off, they sleep between the step's parallel loops and each loop waits
    /// for them to wake (16–50 µs each on the bench's two-vCPU host). The results are the
    /// same either way; on, the other cores are busy for the whole step.
    pub spin_workers: bool,
}

impl Default for PipelineParams {
    fn default() -> Self {
        PipelineParams {
            dynamics: WorldParams::default(),
            broadphase: Method::default(),
            manifold: ManifoldConfig::default(),
            speculative: true,
            spin_workers: true,
        }
    }
}

/// Bodies, joints and collision detection, stepped together (see the module docs).
///
/// All state is plain data in vectors indexed by body or object slot (no `Rc`, no stored
/// closures apart from the collision world's optional user filter).
#[derive(Debug, Clone)]
pub struct World {
    dynamics: DynamicsWorld,
    collision: CollisionWorld,
    params: PipelineParams,
    /// Collision object of each body slot.
    object_of: Vec<Option<ObjectHandle>>,
    /// Body of each collision object slot.
    body_of: Vec<Option<BodyHandle>>,
    /// Distance from the centre of mass to the farthest point of the shape's local box.
    radius: Vec<Real>,
    /// Whether the body's object is hinted resting in the collision world.
    resting: Vec<bool>,
    /// Per body slot, whether the body landed on another in the last step (see
    /// `step::mark_landed`); empty when no contact was solved. Read by the next sync.
    landed: Vec<bool>,
    /// Solver contacts of the current step (reused buffer).
    contacts: Vec<ContactManifold>,
    /// For each entry of `contacts`, the index of its narrowphase pair (see `contacts.rs`).
    sources: Vec<u32>,
    /// Per chunk of pairs, its first manifold and first resting edge (reused buffer of the
    /// parallel gather).
    chunk_counts: Vec<(u32, u32)>,
    /// Body slots of the touching pairs not handed to the solver because neither body is
    /// awake, for the islands (reused buffer, filled by the gather; see
    /// `contacts::push_resting`).
    resting_pairs: Vec<(usize, usize)>,
    /// Time not yet simulated by [`World::step_simulation`].
    accumulator: Real,
    report: PipelineReport,
    /// The scene-query tree kept between [`World::query`] calls.
    query_cache: query_cache::QueryCache,
}

impl World {
    /// An empty world.
    pub fn new(params: PipelineParams) -> Result<Self> {
        carom_collision::math::check_non_negative(
            "manifold.prediction",
            params.manifold.prediction,
        )?;
        let mut collision = CollisionWorld::new(params.broadphase);
        collision.narrowphase_mut().dispatcher.config = params.manifold;
        Ok(World {
            dynamics: DynamicsWorld::new(params.dynamics)?,
            collision,
            params,
            object_of: Vec::new(),
            body_of: Vec::new(),
            radius: Vec::new(),
            resting: Vec::new(),
            landed: Vec::new(),
            contacts: Vec::new(),
            sources: Vec::new(),
            chunk_counts: Vec::new(),
            resting_pairs: Vec::new(),
            accumulator: 0.0,
            report: PipelineReport::default(),
            query_cache: Default::default(),
        })
    }

    /// The settings.
    pub fn params(&self) -> &PipelineParams {
        &self.params
    }

    /// Replaces the dynamics settings (gravity, solver, sleeping), validated.
    pub fn set_dynamics_params(&mut self, p: WorldParams) -> Result<()> {
        self.dynamics.set_params(p)?;
        self.params.dynamics = p;
        Ok(())
    }

    /// Turns speculative contacts (continuous collision) on or off.
    pub fn set_speculative(&mut self, on: bool) {
        self.params.speculative = on;
    }

    /// The dynamics side (bodies, joints, solver settings).
    pub fn dynamics(&self) -> &DynamicsWorld {
        &self.dynamics
    }

    /// The collision side (objects, pairs, manifolds, contact events of the last step).
    pub fn collision(&self) -> &CollisionWorld {
        &self.collision
    }

    /// The bodies.
    pub fn bodies(&self) -> &BodySet {
        self.dynamics.bodies()
    }

    /// The bodies, to set velocities, apply forces and impulses, teleport or wake them.
    pub fn bodies_mut(&mut self) -> &mut BodySet {
        self.query_cache.moved();
        self.dynamics.bodies_mut()
    }

    /// The joints.
    pub fn joints(&self) -> &JointSet {
        self.dynamics.joints()
    }

    /// Handles of the live bodies in slot order (creation order while nothing was removed).
    pub fn handles(&self) -> Vec<BodyHandle> {
        self.bodies().handles().collect()
    }

    /// The collision object of a body (`None` for a body without shape).
    pub fn object(&self, h: BodyHandle) -> Result<Option<ObjectHandle>> {
        let i = self.bodies().slot(h)?;
        Ok(self.object_of.get(i).copied().flatten())
    }

    /// The body of a collision object.
    pub fn body_of_object(&self, o: ObjectHandle) -> Option<BodyHandle> {
        let b = self.body_of.get(o.index as usize).copied().flatten()?;
        (self.object_of.get(b.index as usize).copied().flatten() == Some(o)).then_some(b)
    }

    /// Creates a body and, if it has a shape, its collision object (with `desc.filter`;
    /// static bodies never pair with each other). Invalid values are rejected before anything
    /// changes.
    pub fn add_body(&mut self, desc: &BodyDesc) -> Result<BodyHandle> {
        let h = self.dynamics.create_body(desc)?;
        self.query_cache.moved();
        let i = h.index as usize;
        let cap = self.bodies().capacity();
        if self.object_of.len() < cap {
            self.object_of.resize(cap, None);
            self.radius.resize(cap, 0.0);
            self.resting.resize(cap, false);
        }
        self.object_of[i] = None;
        let Some(shape) = desc.shape.clone() else {
            return Ok(h);
        };
        let is_static = desc.body_type == BodyType::Static;
        let mut filter = desc.filter;
        filter.is_static = is_static;
        let pose = self.bodies().pose(h)?;
        let com = self.bodies().info(h)?.local_com;
        let local = shape.local_aabb();
        let obj = match self.collision.add(shape, pose, filter) {
            Ok(o) => o,
            Err(e) => {
                self.dynamics.remove_body(h)?;
                return Err(e);
            }
        };
        let base = 0.5 * self.params.manifold.prediction;
        self.collision.set_pose_with_margin(obj, pose, base)?;
        let k = obj.index as usize;
        if self.body_of.len() <= k {
            self.body_of.resize(k + 1, None);
        }
        self.body_of[k] = Some(h);
        self.object_of[i] = Some(obj);
        let r = local.half_extents().length() + (local.center() - com).length();
        self.radius[i] = if r.is_finite() { r } else { 0.0 };
        self.resting[i] = is_static;
        Ok(h)
    }

    /// Removes a body, its collision object and every joint attached to it (returned). Its
    /// contacts disappear at the next step; its handle becomes stale.
    pub fn remove_body(&mut self, h: BodyHandle) -> Result<Vec<JointHandle>> {
        let i = self.bodies().slot(h)?;
        let joints = self.dynamics.remove_body(h)?;
        self.query_cache.moved();
        if let Some(obj) = self.object_of[i].take() {
            self.collision.remove(obj)?;
            self.body_of[obj.index as usize] = None;
        }
        self.resting[i] = false;
        if let Some(p) = self.landed.get_mut(i) {
            *p = false;
        }
        Ok(joints)
    }

    /// Sets the pose of a body and of its collision object (teleport); wakes the body.
    pub fn set_pose(&mut self, h: BodyHandle, pose: Isometry) -> Result<()> {
        self.dynamics.bodies_mut().set_pose(h, pose)?;
        self.query_cache.moved();
        if let Some(obj) = self.object(h)? {
            let pose = self.bodies().pose(h)?;
            self.collision.set_pose(obj, pose)?;
        }
        Ok(())
    }

    /// Creates a joint between two live bodies (see [`DynamicsWorld::create_joint`]). With
    /// `disable_collisions`, the pair of the two bodies' collision objects is excluded from
    /// contact generation until the joint is removed or breaks
    /// ([`CollisionWorld::set_pair_excluded`]).
    pub fn create_joint(&mut self, desc: &JointDesc) -> Result<JointHandle> {
        let h = self.dynamics.create_joint(desc)?;
        if desc.disable_collisions {
            self.update_exclusion(desc.body_a, desc.body_b)?;
        }
        Ok(h)
    }

    /// Removes a joint (wakes its bodies); their collisions come back unless another joint
    /// still disables them.
    pub fn remove_joint(&mut self, h: JointHandle) -> Result<()> {
        let desc = &self.dynamics.joints().get(h)?.desc;
        let (a, b, disables) = (desc.body_a, desc.body_b, desc.disable_collisions);
        self.dynamics.remove_joint(h)?;
        if disables {
            self.update_exclusion(a, b)?;
        }
        Ok(())
    }

    /// Excludes the pair of collision objects of bodies `a` and `b` from contact generation
    /// while an unbroken joint between them disables their collisions, and lets it back in
    /// otherwise (nothing when a body has no object). Jointed pairs thus never reach the
    /// narrowphase: in "136 ragdolls" about 1,070 of the 3,524 broadphase pairs per step
    /// are such pairs, which were generated in full and then dropped by the adapter.
    fn update_exclusion(&mut self, a: BodyHandle, b: BodyHandle) -> Result<()> {
        let (Some(oa), Some(ob)) = (self.object(a)?, self.object(b)?) else {
            return Ok(());
        };
        let disabled = self.dynamics.joints().collision_disabled(a, b);
        self.collision.set_pair_excluded(oa, ob, disabled)
    }

    /// Excludes the object pairs of every unbroken joint that disables collisions (a world
    /// restored from a snapshot).
    fn exclude_jointed_pairs(&mut self) -> Result<()> {
        let pairs: Vec<(BodyHandle, BodyHandle)> = self
            .dynamics
            .joints()
            .iter()
            .filter(|(_, j)| j.desc.disable_collisions && !j.broken)
            .map(|(_, j)| (j.desc.body_a, j.desc.body_b))
            .collect();
        for (a, b) in pairs {
            if let (Some(oa), Some(ob)) = (self.object(a)?, self.object(b)?) {
                self.collision.set_pair_excluded(oa, ob, true)?;
            }
        }
        Ok(())
    }

    /// The report of the last [`World::step`].
    pub fn last_report(&self) -> &PipelineReport {
        &self.report
    }

    /// Time left over by [`World::step_simulation`] (less than one fixed step).
    pub fn accumulator(&self) -> Real {
        self.accumulator
    }

    /// A hash of every body's position, rotation and velocities (bit patterns).
    pub fn state_hash(&self) -> u64 {
        self.dynamics.state_hash()
    }

    /// Number of dynamic bodies currently asleep.
    pub fn sleeping_count(&self) -> usize {
        let b = self.bodies();
        b.handles()
            .filter(|&h| b.info(h).is_ok_and(|i| i.sleeping))
            .count()
    }

    fn check_dt(name: &str, dt: Real) -> Result<Real> {
        if dt.is_finite() && dt > 0.0 {
            Ok(dt)
        } else {
            Err(CaromError::invalid(name, dt, "must be finite and > 0"))
        }
    }
}
