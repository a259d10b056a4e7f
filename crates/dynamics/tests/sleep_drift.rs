//! The drift rule of sleeping on a whole scene: "1000 stack" (Bullet's benchmark scene 2, as
//! `carom-scenes` builds it), whose walls and tower jitter in place for a few steps while the
//! contacts settle under the load.
use carom_dynamics::collision::math::Real;
use carom_dynamics::{PipelineParams, World};

/// Steps until every body of "1000 stack" sleeps (within 240), with the sleep drift `drift`,
/// and the largest distance a body's centre moved from its start.
fn asleep_after(drift: Real) -> (Option<usize>, Real) {
    let scene = carom_scenes::bullet::scene(2).unwrap();
    let mut params = PipelineParams::default();
    params.dynamics.sleep.drift = drift;
    let mut world = World::from_scene_with(&scene, params).unwrap();
    let handles = world.handles();
    let start: Vec<_> = handles
        .iter()
        .map(|&h| world.bodies().pose(h).unwrap().translation)
        .collect();
    let dynamic = handles
        .iter()
        .filter(|&&h| world.bodies().inv_mass(h).unwrap() > 0.0)
        .count();
    let mut asleep = None;
    for step in 0..240 {
        world.step(1.0 / 60.0).unwrap();
        if asleep.is_none() && world.sleeping_count() == dynamic {
            asleep = Some(step);
        }
    }
    let moved = handles
        .iter()
        .zip(&start)
        .map(|(&h, &p)| (world.bodies().pose(h).unwrap().translation - p).length())
        .fold(0.0, Real::max);
    (asleep, moved)
}

#[test]
fn a_settling_stack_sleeps_sooner_and_stands_the_same() {
    let (with, moved_with) = asleep_after(0.015);
    let (without, moved_without) = asleep_after(0.0);
    // 47 and 53 in f32, 48 and 54 in f64 when written.
    println!("asleep at {with:?} with the drift rule, {without:?} without");
    let (with, without) = (with.expect("asleep"), without.expect("asleep"));
    assert!(with < without, "{with} vs {without}");
    // The stack stands either way (the benchmark's 0.5 m bound on any body's drift).
    assert!(
        moved_with < 0.5 && moved_without < 0.5,
        "{moved_with} {moved_without}"
    );
}
