//! The World's bookkeeping: bad input, removal with joints, sub-stepping, sleeping with the
//! broadphase's resting hints, scenes, timings.
mod pipeline;
use carom_dynamics::collision::math::{Isometry, Real, Vec3};
use carom_dynamics::*;
use carom_scenes::bullet;
use pipeline::*;

#[test]
fn bad_input_is_rejected_with_the_value_named() {
    let mut w = world(true);
    ground(&mut w, 0.5);
    let b = dyn_box(&mut w, Vec3::splat(0.5), Vec3::new(0.0, 0.5, 0.0));
    for dt in [Real::NAN, Real::INFINITY, 0.0, -1.0] {
        let e = w.step(dt).unwrap_err().to_string();
        assert!(e.contains("dt"), "{e}");
    }
    let e = w
        .step_simulation(Real::NAN, 4, 1.0 / 60.0)
        .unwrap_err()
        .to_string();
    assert!(e.contains("dt"), "{e}");
    let e = w.step_simulation(0.1, 4, 0.0).unwrap_err().to_string();
    assert!(e.contains("fixed_step"), "{e}");
    let e = w
        .bodies_mut()
        .add_force(b, Vec3::new(Real::NAN, 0.0, 0.0))
        .unwrap_err()
        .to_string();
    assert!(e.contains("force"), "{e}");
    let nan_pose = Isometry::from_translation(Vec3::new(0.0, Real::NAN, 0.0));
    let e = w.set_pose(b, nan_pose).unwrap_err().to_string();
    assert!(e.contains("pose"), "{e}");
    for m in [0.0, -2.0, Real::NAN] {
        let mut d = BodyDesc::dynamic(cuboid(Vec3::ONE), Isometry::IDENTITY, 1.0);
        d.mass = MassSpec::Mass(m);
        let e = w.add_body(&d).unwrap_err().to_string();
        assert!(e.contains("mass"), "{e}");
    }
    let mut d = BodyDesc::dynamic(cuboid(Vec3::ONE), nan_pose, 1.0);
    assert!(w.add_body(&d).unwrap_err().to_string().contains("pose"));
    d.pose = Isometry::IDENTITY;
    d.linear_velocity = Vec3::splat(Real::INFINITY);
    assert!(w.add_body(&d).is_err());
    // Nothing was half-created: one ground, one box, and the world still steps.
    assert_eq!(w.bodies().len(), 2);
    assert_eq!(w.collision().len(), 2);
    w.step(1.0 / 60.0).unwrap();
    assert!(pos(&w, b).is_finite());
}

#[test]
fn removing_bodies_with_joints_between_steps_cannot_corrupt() {
    let mut w = world(false);
    ground(&mut w, 0.5);
    let chain: Vec<BodyHandle> = (0..5)
        .map(|i| {
            dyn_box(
                &mut w,
                Vec3::splat(0.2),
                Vec3::new(i as Real * 0.5, 2.0, 0.0),
            )
        })
        .collect();
    let mut joints = Vec::new();
    for p in chain.windows(2) {
        let desc = JointDesc {
            body_a: p[0],
            body_b: p[1],
            frame_a: Isometry::from_translation(Vec3::new(0.25, 0.0, 0.0)),
            frame_b: Isometry::from_translation(Vec3::new(-0.25, 0.0, 0.0)),
            kind: JointKind::Ball,
            break_impulse: Real::INFINITY,
            disable_collisions: true,
        };
        joints.push(w.create_joint(&desc).unwrap());
    }
    for _ in 0..30 {
        w.step(1.0 / 60.0).unwrap();
    }
    let removed = w.remove_body(chain[2]).unwrap();
    assert_eq!(removed.len(), 2);
    assert!(w.remove_body(chain[2]).is_err(), "stale handle");
    assert!(w.bodies().pose(chain[2]).is_err());
    assert!(w.remove_joint(removed[0]).is_err());
    // A new body may reuse the slot; the stale handle still names nothing.
    let fresh = dyn_box(&mut w, Vec3::splat(0.2), Vec3::new(5.0, 1.0, 0.0));
    assert!(w.bodies().pose(chain[2]).is_err());
    for _ in 0..120 {
        w.step(1.0 / 60.0).unwrap();
    }
    for &b in chain.iter().filter(|&&b| b != chain[2]).chain([&fresh]) {
        let p = pos(&w, b);
        assert!(p.is_finite() && p.y > 0.0, "{b:?} at {p}");
    }
    // Every manifold handed to the solver names live bodies.
    for pc in w.collision().narrowphase().pairs() {
        assert!(w.body_of_object(pc.a).is_some() && w.body_of_object(pc.b).is_some());
    }
}

#[test]
fn step_simulation_accumulates_fixed_steps() {
    let mut w = world(false);
    let b = w
        .add_body(&BodyDesc::dynamic(sphere(0.5), Isometry::IDENTITY, 1000.0))
        .unwrap();
    let h: Real = 1.0 / 60.0;
    assert_eq!(w.step_simulation(0.5 * h, 4, h).unwrap(), 0);
    assert_eq!(
        pos(&w, b),
        Vec3::ZERO,
        "no step yet: poses are not extrapolated"
    );
    assert_eq!(w.step_simulation(0.6 * h, 4, h).unwrap(), 1);
    assert!((w.accumulator() - 0.1 * h).abs() < 1e-5);
    assert_eq!(w.step_simulation(2.0 * h, 4, h).unwrap(), 2);
    // A long frame is clamped to max_sub_steps; the excess time is dropped.
    assert_eq!(w.step_simulation(10.0 * h, 3, h).unwrap(), 3);
    assert!(w.accumulator() < h);
    // Free fall over the 6 fixed steps of `substeps` substeps each: symplectic Euler over
    // m substeps of s gives y = -g s² m(m+1)/2.
    let k = w.params().dynamics.solver.substeps as Real;
    let (m, s) = (6.0 * k, h / k);
    let expected = -10.0 * s * s * m * (m + 1.0) / 2.0;
    assert!(
        (pos(&w, b).y - expected).abs() < 1e-4,
        "{} vs {expected}",
        pos(&w, b).y
    );
    // max_sub_steps = 0: one variable step.
    assert_eq!(w.step_simulation(0.5 * h, 0, h).unwrap(), 1);
}

#[test]
fn resting_bodies_sleep_in_the_broadphase_and_wake_on_hit() {
    let mut w = world(true);
    ground(&mut w, 0.5);
    let boxes = box_column(&mut w, 3);
    for _ in 0..200 {
        w.step(1.0 / 60.0).unwrap();
    }
    assert_eq!(w.sleeping_count(), 3);
    w.step(1.0 / 60.0).unwrap();
    for &b in &boxes {
        let o = w.object(b).unwrap().unwrap();
        assert!(w.collision().get(o).unwrap().resting, "{b:?} not resting");
        // The object has the pose the body fell asleep at (not the one synced before the
        // step that integrated it last).
        let pose = w.bodies().pose(b).unwrap();
        assert_eq!(w.collision().get(o).unwrap().pose, pose, "{b:?}");
    }
    let before: Vec<Vec3> = boxes.iter().map(|&b| pos(&w, b)).collect();
    w.step(1.0 / 60.0).unwrap();
    assert_eq!(
        before,
        boxes.iter().map(|&b| pos(&w, b)).collect::<Vec<_>>()
    );
    // A ball dropped on top wakes the stack through a real contact.
    let ball = w
        .add_body(&BodyDesc::dynamic(
            sphere(0.3),
            Isometry::from_translation(Vec3::new(0.1, 4.0, 0.0)),
            1000.0,
        ))
        .unwrap();
    let mut woken = Vec::new();
    for _ in 0..60 {
        woken.extend(w.step(1.0 / 60.0).unwrap().dynamics.woken.iter().copied());
    }
    for &b in &boxes {
        assert!(woken.contains(&b), "{b:?} not woken");
    }
    assert!(
        pos(&w, ball).y > 2.5,
        "ball on top of the stack: {}",
        pos(&w, ball).y
    );
}

#[test]
fn scene_builder_matches_the_scene_and_timings_are_reported() {
    let scene = bullet::ragdolls();
    let w = World::from_scene(&scene).unwrap();
    assert_eq!(w.bodies().len(), scene.bodies.len());
    assert_eq!(w.joints().len(), scene.joints.len());
    for (h, b) in w.handles().iter().zip(&scene.bodies) {
        let p = w.bodies().pose(*h).unwrap();
        assert!((p.translation - b.pose.translation).length() < 1e-4);
        assert_eq!(w.bodies().inv_mass(*h).unwrap() == 0.0, b.is_static());
    }
    let mut scene = bullet::falling_boxes();
    scene.bodies.truncate(65);
    let mut w = World::from_scene(&scene).unwrap();
    let mut r = PipelineReport::default();
    let mut handed = 0;
    for _ in 0..100 {
        r = w.step(scene.dt).unwrap().clone();
        assert!(r.contact_points >= r.manifolds);
        handed = handed.max(r.manifolds);
    }
    let t = r.timings;
    assert!(t.total >= t.broadphase + t.narrowphase + t.solver);
    assert!(handed > 0 && r.pairs > 0);
    // Once the boxes sleep, their manifolds stay in the narrowphase but are not handed to
    // the solver.
    if w.sleeping_count() == w.bodies().len() - 1 {
        assert_eq!(r.manifolds, 0);
    }
}

/// A sleeping stack hands no manifold to the solver, but the islands still join its boxes
/// through their touching pairs: waking the bottom box wakes the whole stack in the same
/// step, and that step's solver gets every manifold of the stack (gathered again after the
/// wake), as many as a copy whose boxes were all woken by hand before the step gets. No box
/// moves by more than 1e-4 m in that step (without its contacts a box would fall g·dt² ≈
/// 2.7e-3 m), and the two copies agree to 1e-5 m (the copy woken by hand also updates the
/// manifolds of the pairs that slept, so the bits may differ).
#[test]
fn a_sleeping_stack_wakes_whole_with_its_contacts_in_the_same_step() {
    let mut w = world(true);
    ground(&mut w, 0.5);
    let boxes = box_column(&mut w, 4);
    for _ in 0..240 {
        w.step(1.0 / 60.0).unwrap();
    }
    assert_eq!(w.sleeping_count(), 4);
    let asleep = w.step(1.0 / 60.0).unwrap().clone();
    assert_eq!(asleep.manifolds, 0, "a sleeping stack hands manifolds on");
    assert!(asleep.pairs >= 4);

    let mut all = w.clone();
    for &b in &boxes {
        all.bodies_mut().wake(b).unwrap();
    }
    let before: Vec<Vec3> = boxes.iter().map(|&b| pos(&w, b)).collect();
    w.bodies_mut().wake(boxes[0]).unwrap();
    let one = w.step(1.0 / 60.0).unwrap().clone();
    let every = all.step(1.0 / 60.0).unwrap().clone();
    for (&b, p) in boxes.iter().zip(&before) {
        assert!(one.dynamics.woken.contains(&b), "{b:?} not woken");
        assert!((pos(&w, b) - *p).length() < 1e-4, "{b:?} moved");
        assert!((pos(&w, b) - pos(&all, b)).length() < 1e-5, "{b:?}");
    }
    assert_eq!(one.manifolds, every.manifolds);
    assert_eq!(one.contact_points, every.contact_points);
    assert!(one.manifolds >= 4);
}

/// Steps of a world whose bodies all sleep change nothing (they skip the solver, and the
/// narrowphase hands back its settled events): the state hash and the events stay as they
/// were, nothing wakes or sleeps, and a copy taken before those steps, poked the same way
/// afterwards, moves exactly (bit for bit) as the world that took them. A static body and
/// a joint between two sleeping boxes are part of the world; a kinematic body, even parked,
/// takes the full step (its rotation is renormalised), with the same outcome.
#[test]
fn steps_of_a_world_asleep_change_nothing() {
    for kinematic in [false, true] {
        let mut w = world(true);
        ground(&mut w, 0.5);
        let boxes = box_column(&mut w, 4);
        let up = |y: Real| Isometry::from_translation(Vec3::new(0.0, y, 0.0));
        let mut joint = JointDesc::new(boxes[2], boxes[3], up(0.5), up(-0.5), JointKind::Fixed);
        joint.disable_collisions = false;
        w.create_joint(&joint).unwrap();
        if kinematic {
            let far = Isometry::from_translation(Vec3::new(9.0, 5.0, 0.0));
            let mut k = BodyDesc::dynamic(sphere(0.3), far, 1.0);
            k.body_type = BodyType::Kinematic;
            w.add_body(&k).unwrap();
        }
        for _ in 0..240 {
            w.step(1.0 / 60.0).unwrap();
        }
        assert_eq!(w.sleeping_count(), 4);
        let before = w.clone();
        let (hash, events) = (
            w.state_hash(),
            w.collision().narrowphase().events().to_vec(),
        );
        assert!(events.len() >= 4);
        for _ in 0..30 {
            let r = w.step(1.0 / 60.0).unwrap();
            assert_eq!((r.manifolds, r.dynamics.woken.len()), (0, 0));
            assert!(r.dynamics.slept.is_empty() && r.dynamics.broken_joints.is_empty());
            assert_eq!(w.state_hash(), hash);
            assert_eq!(w.collision().narrowphase().events(), &events[..]);
        }
        let mut copies = [w, before];
        for c in &mut copies {
            let p = pos(c, boxes[3]);
            c.bodies_mut()
                .apply_impulse(boxes[3], Vec3::new(0.5, 0.0, 0.2), p)
                .unwrap();
            for _ in 0..60 {
                c.step(1.0 / 60.0).unwrap();
            }
        }
        assert_ne!(copies[0].state_hash(), hash, "the poke moved nothing");
        assert_eq!(
            copies[0].state_hash(),
            copies[1].state_hash(),
            "kinematic {kinematic}"
        );
    }
}

/// A force added in a world whose bodies all sleep acts for exactly one step, as in a moving
/// world: the idle steps before it skip zeroing the (already zero) accumulators, and the
/// step after it starts from zero again. Oracle: `Δv = F / m · dt` in a world without
/// gravity or contacts.
#[test]
fn a_force_added_to_an_idle_world_acts_for_one_step() {
    let mut p = PipelineParams::default();
    p.dynamics.gravity = Vec3::ZERO;
    p.dynamics.sleep.enabled = true;
    let mut w = World::new(p).unwrap();
    // A static body far away (its accumulators are cleared too) and a lone 1 m box.
    let wall = ground(&mut w, 0.5);
    let b = dyn_box(&mut w, Vec3::splat(0.5), Vec3::new(0.0, 10.0, 0.0));
    let dt = 1.0 / 60.0;
    for _ in 0..120 {
        w.step(dt).unwrap();
    }
    assert!(w.bodies().is_sleeping(b).unwrap());
    // A force on the static body wakes nothing and never reaches the box.
    w.bodies_mut()
        .add_force(wall, Vec3::new(0.0, 1.0e6, 0.0))
        .unwrap();
    for _ in 0..3 {
        w.step(dt).unwrap();
    }
    assert!(w.bodies().is_sleeping(b).unwrap());
    assert_eq!(w.bodies().linear_velocity(b).unwrap(), Vec3::ZERO);
    let mass = 1000.0;
    let f = Vec3::new(300.0, 0.0, 0.0);
    w.bodies_mut().add_force(b, f).unwrap();
    w.step(dt).unwrap();
    let v1 = w.bodies().linear_velocity(b).unwrap();
    let want = f.x / mass * dt;
    assert!((v1.x - want).abs() <= 1e-5 * want, "{v1} against {want}");
    for _ in 0..5 {
        w.step(dt).unwrap();
        assert_eq!(
            w.bodies().linear_velocity(b).unwrap(),
            v1,
            "the force acted again"
        );
    }
}
