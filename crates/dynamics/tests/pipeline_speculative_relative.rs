//! Speculative contacts count a pair's *relative* motion: two boxes falling side by side at
//! the same speed get no speculative contact from their common velocity, while a box falling
//! at that speed towards the ground (or towards a box at rest) gets one before it arrives.
mod pipeline;
use carom_dynamics::collision::math::{Real, Vec3};
use carom_dynamics::BodyHandle;
use carom_dynamics::World;
use pipeline::{dyn_box, ground, world};

fn manifolds_between(w: &World, a: BodyHandle, b: BodyHandle) -> usize {
    let (oa, ob) = (w.object(a).unwrap().unwrap(), w.object(b).unwrap().unwrap());
    let key = (oa.min(ob), oa.max(ob));
    w.collision()
        .narrowphase()
        .manifolds()
        .filter(|p| (p.a, p.b) == key)
        .count()
}

#[test]
fn bodies_moving_together_get_no_speculative_contact_from_their_common_speed() {
    let mut w = world(false);
    ground(&mut w, 0.5);
    // Two unit boxes 10 cm apart side by side, high above the ground, falling at 20 m/s
    // (0.33 m per step: the old per-body margins, 2 x 0.33 m, covered the 10 cm gap).
    let a = dyn_box(&mut w, Vec3::splat(0.5), Vec3::new(0.0, 50.0, 0.0));
    let b = dyn_box(&mut w, Vec3::splat(0.5), Vec3::new(1.1, 50.0, 0.0));
    // A third box falling at the same speed 0.2 m above a box at rest on the ground.
    let rest = dyn_box(&mut w, Vec3::splat(0.5), Vec3::new(10.0, 0.5, 0.0));
    let c = dyn_box(&mut w, Vec3::splat(0.5), Vec3::new(10.0, 1.7, 0.0));
    for h in [a, b, c] {
        w.bodies_mut()
            .set_linear_velocity(h, Vec3::new(0.0, -20.0, 0.0))
            .unwrap();
    }
    w.step(1.0 / 60.0).unwrap();
    // The side-by-side pair has no points; its broadphase boxes (grown by the margin's own
    // 1 cm and swept down along the motion, not grown by the 0.33 m motion on every side)
    // do not even overlap any more.
    let (oa, ob) = (w.object(a).unwrap().unwrap(), w.object(b).unwrap().unwrap());
    let key = (oa.min(ob), oa.max(ob));
    assert!(
        !w.collision().pairs().contains(&key),
        "the swept boxes do not pair them"
    );
    assert_eq!(manifolds_between(&w, a, b), 0);
    // The falling box sees the resting box ahead (relative speed 20 m/s).
    assert_eq!(manifolds_between(&w, c, rest), 1);
    // And it stops on it without passing through: speculative contacts do their job.
    for _ in 0..120 {
        w.step(1.0 / 60.0).unwrap();
    }
    let top = w.bodies().pose(c).unwrap().translation.y;
    assert!(
        (top - 1.5).abs() < 0.05,
        "the falling box rests on the other: {top}"
    );
}

/// A body that has just landed may stop while a body falling with it does not. "1000
/// stack"'s pyramid starts with its layers 4 cm apart, and they land one step after another,
/// each on the layer that landed in the step before. That layer is still moving at the start
/// of the step, at about the speed that closed its gap, so counting only the relative motion,
/// a box above got speculative points against the supports that had slowed and none against
/// the others: it was caught at one corner, sank into the rest and spun, and the top of the
/// pyramid rocked (up to 0.27 rad/s) until step 28. The landed body's pairs now count its
/// stop too (`CollisionObject::may_stop`): the landings are square and the pyramid is still
/// from step 20 on.
#[test]
fn the_pyramid_layers_land_square_and_stop_rocking() {
    let scene = carom_scenes::bullet::scene(2).unwrap();
    let mut params = carom_dynamics::PipelineParams::default();
    params.dynamics.sleep.enabled = false;
    let mut w = World::from_scene_with(&scene, params).unwrap();
    let pyramid: Vec<BodyHandle> = w
        .handles()
        .into_iter()
        .filter(|&h| {
            let b = w.bodies();
            b.inv_mass(h).unwrap() > 0.0 && b.pose(h).unwrap().translation.x < -5.0
        })
        .collect();
    assert_eq!(pyramid.len(), 650);
    for step in 0..40 {
        w.step(scene.dt).unwrap();
        let spin = pyramid
            .iter()
            .map(|&h| w.bodies().angular_velocity(h).unwrap().length())
            .fold(0.0, Real::max);
        if step >= 20 {
            assert!(
                spin < 0.1,
                "step {step}: a pyramid box turns at {spin} rad/s"
            );
        }
    }
}
