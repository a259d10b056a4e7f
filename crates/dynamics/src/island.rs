//! Islands and sleeping.
//!
//! Each step, union-find over the awake-or-sleeping dynamic bodies joined by contacts and
//! joints (static and kinematic bodies do not join islands, as in Bullet's
//! `btSimulationIslandManager` and Box2D). An island containing an awake body wakes whole
//! (a new contact with an awake body, or a user call, wakes a sleeping island); an island
//! whose bodies all stayed below the velocity thresholds for `time_to_sleep` goes to sleep:
//! velocities are zeroed and the solver and integrator skip it.

use crate::body::BodyType;
use crate::body_set::{BodyHandle, BodySet};
use crate::contact::ContactManifold;
use crate::joint::JointSet;
use carom_collision::math::{check_non_negative, Real, Vec3};
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
}

impl Default for SleepParams {
    /// Box2D's thresholds (5 cm/s, 0.5 s) with an angular threshold of ~3°/s.
    fn default() -> Self {
        SleepParams {
            enabled: true,
            linear_threshold: 0.05,
            angular_threshold: 0.05,
            time_to_sleep: 0.5,
        }
    }
}

impl SleepParams {
    /// Checks every value.
    pub fn validate(&self) -> Result<()> {
        check_non_negative("sleep.linear_threshold", self.linear_threshold)?;
        check_non_negative("sleep.angular_threshold", self.angular_threshold)?;
        check_non_negative("sleep.time_to_sleep", self.time_to_sleep)?;
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

/// Computes the island root of every body slot into `scratch.roots`.
pub(crate) fn build(
    set: &BodySet,
    manifolds: &[ContactManifold],
    joints: &JointSet,
    scratch: &mut IslandScratch,
) {
    let parent = &mut scratch.roots;
    parent.clear();
    parent.extend(0..set.capacity());
    let edges = manifolds
        .iter()
        .filter(|m| !m.points().is_empty())
        .map(|m| (m.body_a.index as usize, m.body_b.index as usize))
        .chain(
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
pub(crate) fn wake_islands(
    set: &mut BodySet,
    scratch: &mut IslandScratch,
    manifolds: &[ContactManifold],
) -> Vec<BodyHandle> {
    let roots = &scratch.roots;
    let awake = &mut scratch.awake;
    awake.clear();
    awake.resize(roots.len(), false);
    for i in 0..roots.len() {
        if set.is_awake_dynamic(i) {
            awake[roots[i]] = true;
        }
    }
    for m in manifolds.iter().filter(|m| !m.points().is_empty()) {
        let (a, b) = (m.body_a.index as usize, m.body_b.index as usize);
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
    slots.sort_unstable();
    slots.dedup();
    slots
        .into_iter()
        .filter(|&i| set.is_alive(i))
        .map(|i| set.handle_of(i))
        .collect()
}

/// Advances the rest timers and puts resting islands to sleep. Returns the bodies that fell
/// asleep, in slot order.
pub(crate) fn update_sleep(
    set: &mut BodySet,
    scratch: &mut IslandScratch,
    dt: Real,
    params: &SleepParams,
) -> Vec<BodyHandle> {
    if !params.enabled {
        return Vec::new();
    }
    let roots = &scratch.roots;
    let min_time = &mut scratch.min_time;
    min_time.clear();
    min_time.resize(roots.len(), Real::INFINITY);
    let (lin_sq, ang_sq) = (
        params.linear_threshold * params.linear_threshold,
        params.angular_threshold * params.angular_threshold,
    );
    for (i, &r) in roots.iter().enumerate() {
        if !set.is_awake_dynamic(i) {
            continue;
        }
        let resting = set.info[i].can_sleep
            && set.linear_velocity[i].length_squared() <= lin_sq
            && set.angular_velocity[i].length_squared() <= ang_sq;
        let info = &mut set.info[i];
        info.sleep_time = if resting { info.sleep_time + dt } else { 0.0 };
        min_time[r] = min_time[r].min(info.sleep_time);
    }
    let mut slept = Vec::new();
    for i in 0..roots.len() {
        if set.is_awake_dynamic(i) && min_time[roots[i]] >= params.time_to_sleep {
            set.info[i].sleeping = true;
            set.linear_velocity[i] = Vec3::ZERO;
            set.angular_velocity[i] = Vec3::ZERO;
            slept.push(set.handle_of(i));
        }
    }
    slept
}
