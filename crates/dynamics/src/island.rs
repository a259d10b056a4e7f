//! Islands and sleeping.
//!
//! Each step, union-find over the awake-or-sleeping dynamic bodies joined by contacts and
//! joints (static and kinematic bodies do not join islands, as in Bullet's
//! `btSimulationIslandManager` and Box2D). An island containing an awake body wakes whole
//! (a new contact with an awake body, or a user call, wakes a sleeping island); an island
//! whose bodies all rested for `time_to_sleep` goes to sleep: velocities are zeroed and the
//! solver and integrator skip it. A body rests while it is slow (Box2D's velocity
//! thresholds) or while it stays where its rest began (the drift rule of
//! [`SleepParams::drift`], after Jolt's sleep test spheres).

use crate::body::BodyType;
use crate::body_set::{BodyHandle, BodySet};
use crate::contact::ContactManifold;
use crate::joint::JointSet;
use carom_collision::math::{check_non_negative, motion_bound, Real, Vec3};
use carom_collision::Result;
use serde::{Deserialize, Serialize};

/// When bodies fall asleep.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SleepParams {
    /// Allow sleeping at all.
    pub enabled: bool,
    /// Linear speed below which a body counts as resting, m/s.
    pub linear_threshold: Real,
    /// Angular speed below which a body counts as resting, rad/s.
    pub angular_threshold: Real,
    /// Time a whole island must rest before it sleeps, s.
    pub time_to_sleep: Real,
    /// The drift rule, m: a body with a shape also rests while no point of it has moved
    /// farther than this from where it was when its rest began, whatever its velocity. A
    /// body that jitters in place, as contacts settle under a load, then counts as resting;
    /// one that goes anywhere does not. (The idea of Jolt's sleep test spheres, which keep
    /// three points of the body within balls of 1.5 cm radius.) 0 leaves only the velocity
    /// thresholds.
    pub drift: Real,
}

impl Default for SleepParams {
    /// Box2D's thresholds (5 cm/s, 0.5 s) with an angular threshold of ~3°/s, and a drift of
    /// 1.5 cm (Jolt's sphere radius: `PhysicsSettings::mPointVelocitySleepThreshold`, 3 cm/s,
    /// times `mTimeBeforeSleep`, 0.5 s).
    fn default() -> Self {
        SleepParams {
            enabled: true,
            linear_threshold: 0.05,
            angular_threshold: 0.05,
            time_to_sleep: 0.5,
            drift: 0.015,
        }
    }
}

impl SleepParams {
    /// Checks every value.
    pub fn validate(&self) -> Result<()> {
        check_non_negative("sleep.linear_threshold", self.linear_threshold)?;
        check_non_negative("sleep.angular_threshold", self.angular_threshold)?;
        check_non_negative("sleep.time_to_sleep", self.time_to_sleep)?;
        check_non_negative("sleep.drift", self.drift)?;
        Ok(())
    }
}

fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

fn union(parent: &mut [usize], a: usize, b: usize) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    // Deterministic: the smaller root wins.
    if ra < rb {
        parent[rb] = ra;
    } else if rb < ra {
        parent[ra] = rb;
    }
}

fn is_dynamic(set: &BodySet, i: usize) -> bool {
    set.is_alive(i) && set.info[i].body_type == BodyType::Dynamic
}

/// The islands' working arrays, owned by the world and reused from step to step (no
/// allocation once they have grown to the body count).
#[derive(Debug, Clone, Default)]
pub(crate) struct IslandScratch {
    /// Union-find parents, then the island root of every body slot.
    pub roots: Vec<usize>,
    /// Per root: the island holds an awake body.
    awake: Vec<bool>,
    /// Per root: the smallest rest time of its bodies.
    min_time: Vec<Real>,
}

/// True when this step needs the islands: a dynamic body sleeps (its island may have to
/// wake), or sleeping is enabled and an awake dynamic body may reach `time_to_sleep` during
/// the step (its rest timer, which grows by at most `dt` per step, is within `dt` of it; the
/// test is the very sum [`update_sleep`] compares). Otherwise building them is wasted: no
/// island can wake or fall asleep, so [`wake_islands`] would wake nothing and
/// [`update_sleep`] put nothing to sleep (Box2D v3 likewise keeps its islands only for
/// sleeping). With sleeping off, as in the benchmarks, this skips the union-find over every
/// contact and joint.
///
/// Both questions are answered without a pass over the bodies when the answer is known:
/// [`BodySet::none_asleep`] (set here by a pass that found no sleeping body, cleared when
/// [`update_sleep`] puts one to sleep), and [`BodySet::max_rest`], the largest rest timer of
/// an awake body after the last [`update_sleep`] (`None` when unknown: a new or restored set).
/// Between steps the timers only go down (a wake or a new body starts at zero), so
/// `max_rest + dt` bounds them all (the same sum, so the same answer as the pass). The pass
/// read every body's record each step (3,000 in "3000 fall": 0.1 ms of serial work).
#[inline(never)] // its own entry in profiles
pub(crate) fn needed(set: &mut BodySet, params: &SleepParams, dt: Real) -> bool {
    #[cfg(test)]
    if tests::FORCE.with(|f| f.get()) {
        return true;
    }
    if !set.none_asleep {
        let asleep = (0..set.capacity()).any(|i| {
            set.is_alive(i) && set.info[i].body_type == BodyType::Dynamic && set.info[i].sleeping
        });
        if asleep {
            return true;
        }
        set.none_asleep = true;
    }
    if !params.enabled {
        return false;
    }
    if let Some(t) = set.max_rest {
        return t + dt >= params.time_to_sleep;
    }
    (0..set.capacity()).any(|i| {
        let info = &set.info[i];
        set.is_alive(i)
            && info.body_type == BodyType::Dynamic
            && info.can_sleep
            && info.sleep_time + dt >= params.time_to_sleep
    })
}

/// Touching body pairs (slots) of the step: the manifolds with points, then `resting`,
/// the touching pairs the pipeline did not hand to the solver because neither body is awake
/// (see `pipeline::contacts::push_resting`).
fn touching<'a>(
    manifolds: &'a [ContactManifold],
    resting: &'a [(usize, usize)],
) -> impl Iterator<Item = (usize, usize)> + 'a {
    manifolds
        .iter()
        .filter(|m| !m.points().is_empty())
        .map(|m| (m.body_a.index as usize, m.body_b.index as usize))
        .chain(resting.iter().copied())
}

/// What can move in a step, from one pass over the bodies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Stillness {
    /// An awake dynamic body or a moving kinematic one.
    Moving,
    /// Nothing can move or wake anything: every live dynamic body sleeps and no kinematic
    /// body moves (a body woken by a user call is awake). Islands would then wake nothing,
    /// and no manifold would reach the solver, so the step skips both.
    Idle,
    /// [`Stillness::Idle`] without any kinematic body: every live body is static or a
    /// sleeping dynamic body. A step then changes no body at all (a parked kinematic body
    /// is still integrated, its rotation renormalised), so with no contact handed on it
    /// also skips the solver (`DynamicsWorld::finish_step`).
    Frozen,
}

impl Stillness {
    /// Idle or frozen.
    pub(crate) fn idle(self) -> bool {
        self != Stillness::Moving
    }
}

/// The [`Stillness`] of `set`: stops at the first body that moves.
pub(crate) fn stillness(set: &BodySet) -> Stillness {
    let mut kinematic = false;
    for i in 0..set.capacity() {
        if !set.is_alive(i) {
            continue;
        }
        match set.info[i].body_type {
            BodyType::Dynamic if !set.info[i].sleeping => return Stillness::Moving,
            BodyType::Kinematic => {
                if set.linear_velocity[i] != Vec3::ZERO || set.angular_velocity[i] != Vec3::ZERO {
                    return Stillness::Moving;
                }
                kinematic = true;
            }
            _ => {}
        }
    }
    if kinematic {
        Stillness::Idle
    } else {
        Stillness::Frozen
    }
}

/// Computes the island root of every body slot into `scratch.roots`, joining bodies through
/// the manifolds with points, the `resting` pairs and the unbroken joints.
#[inline(never)] // its own entry in profiles
pub(crate) fn build(
    set: &BodySet,
    (manifolds, resting): (&[ContactManifold], &[(usize, usize)]),
    joints: &JointSet,
    scratch: &mut IslandScratch,
) {
    let parent = &mut scratch.roots;
    parent.clear();
    parent.extend(0..set.capacity());
    let edges = touching(manifolds, resting).chain(
        joints
            .iter()
            .filter(|(_, j)| !j.broken)
            .map(|(_, j)| (j.desc.body_a.index as usize, j.desc.body_b.index as usize)),
    );
    for (a, b) in edges {
        if is_dynamic(set, a) && is_dynamic(set, b) {
            union(parent, a, b);
        }
    }
    // Full path compression in place: afterwards every slot holds its root.
    for i in 0..parent.len() {
        let r = find(parent, i);
        parent[i] = r;
    }
}

/// Wakes every sleeping body whose island holds an awake body or touches a moving kinematic
/// body. Returns the bodies woken since the last step (by this or by user calls), in slot
/// order.
#[inline(never)] // its own entry in profiles
pub(crate) fn wake_islands(
    set: &mut BodySet,
    scratch: &mut IslandScratch,
    (manifolds, resting): (&[ContactManifold], &[(usize, usize)]),
) -> Vec<BodyHandle> {
    let roots = &scratch.roots;
    let awake = &mut scratch.awake;
    awake.clear();
    awake.resize(roots.len(), false);
    let mut moving_kinematic = false;
    for i in 0..roots.len() {
        if set.is_awake_dynamic(i) {
            awake[roots[i]] = true;
        }
        moving_kinematic |= set.is_alive(i)
            && set.info[i].body_type == BodyType::Kinematic
            && (set.linear_velocity[i] != Vec3::ZERO || set.angular_velocity[i] != Vec3::ZERO);
    }
    // The contacts matter only when a kinematic body moves.
    let (manifolds, resting) = if moving_kinematic {
        (manifolds, resting)
    } else {
        (&[][..], &[][..])
    };
    for (a, b) in touching(manifolds, resting) {
        for (k, d) in [(a, b), (b, a)] {
            let kinematic = set.is_alive(k) && set.info[k].body_type == BodyType::Kinematic;
            let moving =
                set.linear_velocity[k] != Vec3::ZERO || set.angular_velocity[k] != Vec3::ZERO;
            if kinematic && moving && is_dynamic(set, d) {
                awake[roots[d]] = true;
            }
        }
    }
    let mut slots: Vec<usize> = std::mem::take(&mut set.woken_by_user);
    for i in 0..roots.len() {
        if is_dynamic(set, i) && set.info[i].sleeping && awake[roots[i]] {
            set.wake_slot(i);
            slots.push(i);
        }
    }
    set.woken_by_user.clear();
    woken_handles(set, slots)
}

/// The bodies woken by user calls since the last step, in slot order (what
/// [`wake_islands`] returns when no island sleeps).
pub(crate) fn user_woken(set: &mut BodySet) -> Vec<BodyHandle> {
    let slots = std::mem::take(&mut set.woken_by_user);
    woken_handles(set, slots)
}

/// The live bodies of `slots`, sorted and deduplicated, as handles.
fn woken_handles(set: &BodySet, mut slots: Vec<usize>) -> Vec<BodyHandle> {
    slots.sort_unstable();
    slots.dedup();
    slots
        .into_iter()
        .filter(|&i| set.is_alive(i))
        .map(|i| set.handle_of(i))
        .collect()
}

/// Advances the rest timer of body slot `i` (awake, dynamic) and returns it.
///
/// The body rests while its velocities are under the thresholds, or while no point of it
/// has moved farther than `drift` ([`motion_bound`], the shape's reach about the centre of
/// mass) from the rest anchor, its pose when the
/// rest began (bodies with a shape only: without one nothing bounds what a rotation moves).
/// When the drift exceeds `drift` the anchor moves to the current pose, so a slow body
/// creeping away restarts the drift rule from where it is while its velocity rule goes on
/// counting, and a moving body takes its anchor with it.
fn advance_timer(
    set: &mut BodySet,
    i: usize,
    dt: Real,
    (lin_sq, ang_sq): (Real, Real),
    drift: Real,
) -> Real {
    let (c, q) = (set.position[i], set.rotation[i]);
    let slow = set.linear_velocity[i].length_squared() <= lin_sq
        && set.angular_velocity[i].length_squared() <= ang_sq;
    let info = &mut set.info[i];
    let still = drift > 0.0
        && info.reach > 0.0
        && motion_bound(info.rest_position, info.rest_rotation, c, q, info.reach) <= drift;
    if !still {
        info.rest_position = c;
        info.rest_rotation = q;
    }
    let resting = info.can_sleep && (slow || still);
    info.sleep_time = if resting { info.sleep_time + dt } else { 0.0 };
    info.sleep_time
}

/// Advances the rest timers and puts resting islands to sleep. Returns the bodies that fell
/// asleep, in slot order. Without `islands` (not built this step, see [`needed`]) only the
/// timers advance: no island can reach `time_to_sleep` then.
#[inline(never)] // its own entry in profiles
pub(crate) fn update_sleep(
    set: &mut BodySet,
    scratch: &mut IslandScratch,
    dt: Real,
    params: &SleepParams,
    islands: bool,
) -> Vec<BodyHandle> {
    if !params.enabled {
        return Vec::new();
    }
    let thresholds = (
        params.linear_threshold * params.linear_threshold,
        params.angular_threshold * params.angular_threshold,
    );
    // The largest rest timer left on an awake body (see [`needed`]).
    let mut max_rest: Real = 0.0;
    if !islands {
        for i in 0..set.capacity() {
            if set.is_awake_dynamic(i) {
                let t = advance_timer(set, i, dt, thresholds, params.drift);
                debug_assert!(t < params.time_to_sleep, "slot {i} rested {t} s");
                max_rest = max_rest.max(t);
            }
        }
        set.max_rest = Some(max_rest);
        return Vec::new();
    }
    let roots = &scratch.roots;
    let min_time = &mut scratch.min_time;
    min_time.clear();
    min_time.resize(roots.len(), Real::INFINITY);
    for (i, &r) in roots.iter().enumerate() {
        if !set.is_awake_dynamic(i) {
            continue;
        }
        let t = advance_timer(set, i, dt, thresholds, params.drift);
        min_time[r] = min_time[r].min(t);
    }
    let mut slept = Vec::new();
    for i in 0..roots.len() {
        if !set.is_awake_dynamic(i) {
            continue;
        }
        if min_time[roots[i]] >= params.time_to_sleep {
            set.info[i].sleeping = true;
            set.none_asleep = false;
            set.linear_velocity[i] = Vec3::ZERO;
            set.angular_velocity[i] = Vec3::ZERO;
            slept.push(set.handle_of(i));
        } else {
            max_rest = max_rest.max(set.info[i].sleep_time);
        }
    }
    set.max_rest = Some(max_rest);
    slept
}

#[cfg(test)]
#[path = "island_drift_tests.rs"]
mod drift_tests;

#[cfg(test)]
mod tests {
    use crate::collision::math::{Isometry, Quat, Real, Vec3};
    use crate::collision::shape::{Cuboid, Shape};
    use crate::{BodyDesc, BodyHandle, BodyType, PipelineParams, World};
    use std::cell::Cell;
    use std::sync::Arc;

    thread_local! {
        /// Makes [`super::needed`] answer true: the oracle builds the islands every step.
        pub(super) static FORCE: Cell<bool> = const { Cell::new(false) };
    }

    fn cuboid(h: Vec3) -> Arc<Shape> {
        Arc::new(Cuboid::new(h).unwrap().into())
    }

    /// `stillness` against the definitions: static only, a sleeping dynamic body, a
    /// parked kinematic one, a kinematic one moving, an awake dynamic one, a dead slot.
    #[test]
    fn stillness_is_moving_idle_or_frozen() {
        use super::{stillness, Stillness};
        use crate::BodySet;
        let mut set = BodySet::new();
        let shape = cuboid(Vec3::splat(0.5));
        set.insert(&BodyDesc::fixed(shape.clone(), Isometry::IDENTITY))
            .unwrap();
        assert_eq!(stillness(&set), Stillness::Frozen);
        let box_ = BodyDesc::dynamic(shape.clone(), Isometry::IDENTITY, 1.0);
        let d = set.insert(&box_).unwrap();
        assert_eq!(stillness(&set), Stillness::Moving);
        let slot = set.slot(d).unwrap();
        set.info[slot].sleeping = true;
        assert_eq!(stillness(&set), Stillness::Frozen);
        let mut kin = box_.clone();
        kin.body_type = BodyType::Kinematic;
        let k = set.insert(&kin).unwrap();
        assert_eq!(stillness(&set), Stillness::Idle);
        assert!(Stillness::Idle.idle() && Stillness::Frozen.idle() && !Stillness::Moving.idle());
        set.set_angular_velocity(k, Vec3::Y).unwrap();
        assert_eq!(stillness(&set), Stillness::Moving);
        set.remove(k).unwrap();
        assert_eq!(
            stillness(&set),
            Stillness::Frozen,
            "a dead slot counts for nothing"
        );
        set.wake(d).unwrap();
        assert_eq!(stillness(&set), Stillness::Moving);
    }

    /// Per step: the state hash and the bodies woken and put to sleep.
    type Trace = Vec<(u64, Vec<BodyHandle>, Vec<BodyHandle>)>;

    /// A stack of three boxes beside a kinematic pusher that starts moving at step 150; a
    /// box dropped on the stack at step 200; a user wake-up at step 300; a second stack
    /// that never sleeps (`can_sleep` false on its bottom box); sleeping off from step 330
    /// to 360.
    fn run(force: bool, time_to_sleep: Real) -> Trace {
        FORCE.with(|f| f.set(force));
        let mut p = PipelineParams::default();
        p.dynamics.gravity = Vec3::new(0.0, -10.0, 0.0);
        p.dynamics.sleep.enabled = true;
        p.dynamics.sleep.time_to_sleep = time_to_sleep;
        p.dynamics.parallel = false;
        let mut w = World::new(p).unwrap();
        let ground = BodyDesc::fixed(
            cuboid(Vec3::new(50.0, 1.0, 50.0)),
            Isometry::from_translation(Vec3::new(0.0, -1.0, 0.0)),
        );
        w.add_body(&ground).unwrap();
        let at = |x: Real, y: Real| Isometry::new(Vec3::new(x, y, 0.0), Quat::IDENTITY);
        let mut stack = Vec::new();
        for (x, no_sleep) in [(0.0, false), (5.0, true)] {
            for k in 0..3 {
                let mut d =
                    BodyDesc::dynamic(cuboid(Vec3::splat(0.5)), at(x, 0.5 + k as Real), 1.0);
                d.can_sleep = !(no_sleep && k == 0);
                stack.push(w.add_body(&d).unwrap());
            }
        }
        let mut pusher = BodyDesc::fixed(cuboid(Vec3::splat(0.5)), at(-3.0, 0.5));
        pusher.body_type = BodyType::Kinematic;
        let pusher = w.add_body(&pusher).unwrap();
        let mut trace = Trace::new();
        for step in 0..400 {
            match step {
                150 => w
                    .bodies_mut()
                    .set_linear_velocity(pusher, Vec3::new(1.0, 0.0, 0.0))
                    .unwrap(),
                170 => w
                    .bodies_mut()
                    .set_linear_velocity(pusher, Vec3::ZERO)
                    .unwrap(),
                200 => {
                    let d = BodyDesc::dynamic(cuboid(Vec3::splat(0.3)), at(0.1, 5.0), 1.0);
                    w.add_body(&d).unwrap();
                }
                300 => w.bodies_mut().wake(stack[1]).unwrap(),
                // Sleeping turned off while bodies sleep, then on again: the rest timers
                // stand still meanwhile (the cached bound of `needed` must still hold).
                330 | 360 => {
                    let mut d = w.params().dynamics;
                    d.sleep.enabled = step == 360;
                    w.set_dynamics_params(d).unwrap();
                }
                _ => {}
            }
            let r = w.step(1.0 / 60.0).unwrap();
            let (woken, slept) = (r.dynamics.woken.clone(), r.dynamics.slept.clone());
            trace.push((w.state_hash(), woken, slept));
        }
        FORCE.with(|f| f.set(false));
        trace
    }

    /// Skipping the islands when no body sleeps or can fall asleep this step
    /// ([`super::needed`]) changes nothing: the same states, wake-ups and sleeps every step as
    /// building them every step.
    #[test]
    fn skipping_the_islands_matches_building_them_every_step() {
        for time_to_sleep in [0.5, 1.0 / 60.0, 0.0] {
            let (fast, oracle) = (run(false, time_to_sleep), run(true, time_to_sleep));
            let (woken, slept) = oracle
                .iter()
                .fold((0, 0), |(w, s), t| (w + t.1.len(), s + t.2.len()));
            // The run exercises both sleeping and waking.
            assert!(
                woken > 0 && slept > 0,
                "{time_to_sleep}: woken {woken} slept {slept}"
            );
            for (k, (a, b)) in fast.iter().zip(&oracle).enumerate() {
                assert_eq!(a, b, "time_to_sleep {time_to_sleep}, step {k}");
            }
        }
    }
}
