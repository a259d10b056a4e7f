//! Per-stage timings of a step (profiling), like Bullet's `CProfileManager` or Box2D's
//! `b2Profile`.

use std::time::{Duration, Instant};

/// Wall-clock time spent in each stage of the last step.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StepTimings {
    /// Input validation and islands (waking).
    pub islands: Duration,
    /// Gravity, forces and damping.
    pub forces: Duration,
    /// Constraint preparation and graph colouring.
    pub prepare: Duration,
    /// Warm starting.
    pub warm_start: Duration,
    /// Velocity iterations (with bias).
    pub solve: Duration,
    /// Position integration.
    pub integrate: Duration,
    /// Split-impulse iterations (sequential impulses) or relax iterations (soft step).
    pub relax: Duration,
    /// Restitution pass (soft step).
    pub restitution: Duration,
    /// Writing impulses and velocities back, joint breaking, sleeping.
    pub store: Duration,
    /// The whole step.
    pub total: Duration,
}

/// Adds the time since `*t` to `slot` and restarts `*t`.
#[inline]
pub(crate) fn lap(t: &mut Instant, slot: &mut Duration) {
    let now = Instant::now();
    *slot += now - *t;
    *t = now;
}
