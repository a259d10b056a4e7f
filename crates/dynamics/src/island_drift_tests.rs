//! The drift rule of sleeping ([`super::SleepParams::drift`]) against its definition: the
//! bound against every vertex of a hull, then the rest timers of one body driven through
//! jitter, travel, spin and creep.

use super::{update_sleep, IslandScratch, SleepParams};
use crate::body::MassSpec;
use crate::body_set::reach;
use crate::collision::math::motion_bound;
use crate::collision::math::{Isometry, Mat3, Quat, Real, Vec3};
use crate::collision::shape::{ConvexHull, Cuboid, MassProperties, Shape};
use crate::{BodyDesc, BodySet};
use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use std::sync::Arc;

/// Unit quaternions from an axis (any non-zero vector) and an angle.
fn rotation() -> impl Strategy<Value = Quat> {
    (prop::array::uniform3(-1.0..1.0 as Real), -3.0..3.0 as Real).prop_map(|(a, angle)| {
        let axis = Vec3::from(a) + Vec3::splat(1e-3);
        Quat::from_axis_angle(axis.normalize(), angle)
    })
}

fn point(scale: Real) -> impl Strategy<Value = Vec3> {
    prop::array::uniform3(-scale..scale).prop_map(Vec3::from)
}

// The same cases on every machine (the project's convention for proptests in CI).
proptest! {
    #![proptest_config(ProptestConfig {
        cases: 1000,
        rng_seed: RngSeed::Fixed(0x6361_726f_6d19),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// For random hulls (their centres of mass off the shape origin) and pose changes (pure
    /// translations; tiny, small and large rotations; near and 1 km from the origin; the
    /// quaternion's sign flipped), no vertex moved farther than [`motion_bound`] says, within
    /// the rounding of the world points themselves; a pure translation's bound is its length.
    #[test]
    fn motion_bound_covers_every_point(
        offset in point(2.0),
        points in prop::collection::vec(point(1.0), 8..16),
        c0 in point(5.0),
        far in prop::bool::ANY,
        q0 in rotation(),
        turn_axis in rotation(), // turns X into a random unit axis
        angle in prop::sample::select(vec![0.0, 1e-5, 1e-3, 0.05, 2.0]),
        dc in point(1.0),
        dc_scale in prop::sample::select(vec![0.0, 1e-4, 0.01, 0.3]),
        flip in prop::bool::ANY,
    ) {
        let points: Vec<Vec3> = points.iter().map(|&p| p + offset).collect();
        let Ok(hull) = ConvexHull::new(&points) else {
            return Ok(()); // flat or degenerate point sets make no solid
        };
        let shape = Shape::from(hull.clone());
        let com = shape.mass_properties(1.0).center_of_mass;
        let r = reach(Some(&shape), com);
        let c0 = c0 + Vec3::splat(if far { 1000.0 } else { 0.0 });
        let turn = Quat::from_axis_angle(turn_axis * Vec3::X, angle);
        let dc = dc * dc_scale;
        let (c, q) = (c0 + dc, (turn * q0).normalize());
        let bound = motion_bound(c0, q0, c, if flip { -q } else { q }, r);
        let moved = hull
            .vertices()
            .iter()
            .map(|&v| ((c + q * (v - com)) - (c0 + q0 * (v - com))).length())
            .fold(0.0, Real::max);
        // The world points carry rounding of their own size.
        let slack = 8.0 * Real::EPSILON * (c0.length() + r + 1.0);
        prop_assert!(moved <= bound + slack, "moved {}, bound {}", moved, bound);
        if angle == 0.0 {
            let err = (bound - dc.length()).abs();
            prop_assert!(err <= 4.0 * Real::EPSILON * c0.length().max(1.0), "{}", err);
        }
    }
}

/// Drives body `desc` through `motion` (at step `k`: its centre of mass, rotation, linear
/// and angular velocity) for `steps` steps of 1/60 s, advancing the rest
/// timers each step as a world would after integrating; returns the step at which it fell
/// asleep.
fn sleeps_at(
    desc: &BodyDesc,
    params: &SleepParams,
    steps: usize,
    motion: impl Fn(usize) -> (Vec3, Quat, Vec3, Vec3),
) -> Option<usize> {
    let mut set = BodySet::new();
    let h = set.insert(desc).unwrap();
    let i = set.slot(h).unwrap();
    let mut scratch = IslandScratch::default();
    for k in 0..steps {
        let (c, q, v, w) = motion(k);
        set.position[i] = c;
        set.rotation[i] = q;
        set.linear_velocity[i] = v;
        set.angular_velocity[i] = w;
        scratch.roots = (0..set.capacity()).collect();
        if !update_sleep(&mut set, &mut scratch, 1.0 / 60.0, params, true).is_empty() {
            assert!(set.is_sleeping(h).unwrap());
            return Some(k);
        }
    }
    None
}

/// The step at which a body resting from step 0 falls asleep: the first whose rest timer,
/// summed step by step as `update_sleep` does, reaches `time_to_sleep` (29 in `f32`, 30 in
/// `f64`, where 30 sixtieths round below 0.5).
fn full_rest(params: &SleepParams) -> usize {
    let (mut t, mut k): (Real, usize) = (1.0 / 60.0, 0);
    while t < params.time_to_sleep {
        t += 1.0 / 60.0;
        k += 1;
    }
    k
}

#[test]
fn jitter_in_place_sleeps_and_going_anywhere_does_not() {
    let shape = Arc::new(Shape::from(Cuboid::new(Vec3::splat(0.5)).unwrap()));
    let boxed = BodyDesc::dynamic(shape, Isometry::IDENTITY, 1.0);
    let on = SleepParams::default();
    let off = SleepParams { drift: 0.0, ..on };
    let still = Quat::IDENTITY;
    let full = Some(full_rest(&on));
    // Bouncing ±3 mm at 0.3 m/s, six times the velocity threshold: resting by the drift
    // rule from the first step, so asleep once 0.5 s has passed.
    let jitter = |k: usize| {
        let s = if k.is_multiple_of(2) { 1.0 } else { -1.0 };
        (Vec3::Y * 0.003 * s, still, Vec3::Y * 0.3 * s, Vec3::ZERO)
    };
    assert_eq!(sleeps_at(&boxed, &on, 200, jitter), full);
    assert_eq!(sleeps_at(&boxed, &off, 200, jitter), None);
    // Wobbling by ±0.4° at 0.5 rad/s (corners ±3.5 mm), ten times the angular threshold.
    let wobble = |k: usize| {
        let s = if k.is_multiple_of(2) { 1.0 } else { -1.0 };
        let q = Quat::from_rotation_z(0.007 * s);
        (Vec3::ZERO, q, Vec3::ZERO, Vec3::Z * 0.5 * s)
    };
    assert_eq!(sleeps_at(&boxed, &on, 200, wobble), full);
    assert_eq!(sleeps_at(&boxed, &off, 200, wobble), None);
    // Travelling at 0.3 m/s, or spinning in place at 1 rad/s (the corners move 1.4 cm a
    // step): never at rest.
    let travel = |k: usize| {
        (
            Vec3::X * 0.005 * k as Real,
            still,
            Vec3::X * 0.3,
            Vec3::ZERO,
        )
    };
    assert_eq!(sleeps_at(&boxed, &on, 200, travel), None);
    let spin = |k: usize| {
        let q = Quat::from_rotation_y(k as Real / 60.0);
        (Vec3::ZERO, q, Vec3::ZERO, Vec3::Y)
    };
    assert_eq!(sleeps_at(&boxed, &on, 200, spin), None);
    // Creeping at 0.04 m/s, under the velocity threshold: 2 cm in 0.5 s is more than the
    // drift, so the anchor moves along, but the velocity rule goes on counting.
    let creep = |k: usize| {
        let c = Vec3::X * 0.04 / 60.0 * k as Real;
        (c, still, Vec3::X * 0.04, Vec3::ZERO)
    };
    assert_eq!(sleeps_at(&boxed, &on, 200, creep), full);
    // Slow for 20 steps, then a jolt away (0.3 m/s, 5 mm, more than the drift from the
    // anchor and not slow), then jitter around the new place: the timer restarts at the
    // jolt, and the anchor with it.
    let jolt = |k: usize| match k {
        0..20 => (Vec3::ZERO, still, Vec3::ZERO, Vec3::ZERO),
        20 => (Vec3::X * 0.02, still, Vec3::X * 0.3, Vec3::ZERO),
        _ => {
            let (c, q, v, w) = jitter(k);
            (c + Vec3::X * 0.02, q, v, w)
        }
    };
    assert_eq!(sleeps_at(&boxed, &on, 200, jolt), full.map(|k| k + 21));
    // A body that may not sleep, and one without a shape (nothing bounds what its rotation
    // moves), keep to their rules.
    let mut awake = boxed.clone();
    awake.can_sleep = false;
    assert_eq!(sleeps_at(&awake, &on, 200, jitter), None);
    let mut bare = boxed.clone();
    bare.shape = None;
    bare.mass = MassSpec::Properties(MassProperties {
        mass: 1.0,
        center_of_mass: Vec3::ZERO,
        inertia: Mat3::IDENTITY,
    });
    assert_eq!(sleeps_at(&bare, &on, 200, jitter), None);
    assert_eq!(sleeps_at(&bare, &on, 200, creep), full);
}
