//! Bodies joined by a joint that disables their collisions are excluded from contact
//! generation: their broadphase pair keeps an empty manifold and reports no event, and the
//! exclusion follows the joints (added, removed, broken, two joints on one pair, snapshots,
//! body removal).
mod pipeline;
use carom_dynamics::collision::math::{Isometry, Real, Vec3};
use carom_dynamics::collision::narrowphase::PairContact;
use carom_dynamics::collision::world::ObjectHandle;
use carom_dynamics::*;
use pipeline::*;

const DT: Real = 1.0 / 60.0;

/// Two unit boxes overlapping by 0.2 along x, no gravity, no sleeping.
fn overlapping() -> (World, BodyHandle, BodyHandle) {
    let mut p = PipelineParams::default();
    p.dynamics.gravity = Vec3::ZERO;
    p.dynamics.sleep.enabled = false;
    let mut w = World::new(p).unwrap();
    let a = dyn_box(&mut w, Vec3::splat(0.5), Vec3::ZERO);
    let b = dyn_box(&mut w, Vec3::splat(0.5), Vec3::new(0.8, 0.0, 0.0));
    (w, a, b)
}

/// A ball joint whose anchors coincide at the boxes' current poses (it pushes nothing).
fn joint(a: BodyHandle, b: BodyHandle, disable_collisions: bool) -> JointDesc {
    JointDesc {
        body_a: a,
        body_b: b,
        frame_a: Isometry::from_translation(Vec3::new(0.4, 0.0, 0.0)),
        frame_b: Isometry::from_translation(Vec3::new(-0.4, 0.0, 0.0)),
        kind: JointKind::Ball,
        break_impulse: Real::INFINITY,
        disable_collisions,
    }
}

fn objects(w: &World, a: BodyHandle, b: BodyHandle) -> (ObjectHandle, ObjectHandle) {
    let (oa, ob) = (w.object(a).unwrap().unwrap(), w.object(b).unwrap().unwrap());
    (oa.min(ob), oa.max(ob))
}

/// The broadphase pair of the two bodies (it must exist: the boxes overlap).
fn pair(w: &World, a: BodyHandle, b: BodyHandle) -> &PairContact<ObjectHandle> {
    let (oa, ob) = objects(w, a, b);
    w.collision()
        .narrowphase()
        .get(oa, ob)
        .expect("the overlapping boxes are a broadphase pair")
}

/// The events of the last step naming the pair.
fn events(w: &World, a: BodyHandle, b: BodyHandle) -> Vec<ContactEventKind> {
    let (oa, ob) = objects(w, a, b);
    w.collision()
        .narrowphase()
        .events()
        .iter()
        .filter(|e| (e.a, e.b) == (oa, ob))
        .map(|e| e.kind)
        .collect()
}

use carom_dynamics::collision::narrowphase::ContactEventKind;

#[test]
fn a_jointed_pair_gets_no_manifold_until_its_joint_is_removed() {
    let (mut w, a, b) = overlapping();
    let j = w.create_joint(&joint(a, b, true)).unwrap();
    for _ in 0..10 {
        let r = w.step(DT).unwrap();
        assert_eq!((r.manifolds, r.contact_points), (0, 0));
        let p = pair(&w, a, b);
        assert!(p.excluded && p.manifold.is_empty() && !p.touching);
        assert!(events(&w, a, b).is_empty());
    }
    // Nothing pushed the overlapping boxes apart.
    assert!(pos(&w, a).length() < 1e-6, "{}", pos(&w, a));
    let (oa, ob) = objects(&w, a, b);
    assert!(w.collision().narrowphase().is_excluded(ob, oa));

    // Removed: the pair is generated at the next step and the solver separates the boxes.
    w.remove_joint(j).unwrap();
    let r = w.step(DT).unwrap();
    assert_eq!(r.manifolds, 1);
    let p = pair(&w, a, b);
    assert!(!p.excluded && p.manifold.len() == 4 && p.touching);
    assert_eq!(events(&w, a, b), [ContactEventKind::Begin]);
    w.step(DT).unwrap();
    assert!(
        pos(&w, a).x < -1e-4,
        "the contact pushes A away: {}",
        pos(&w, a)
    );

    // A new disabling joint while touching: the pair ends at the next step.
    let j = w.create_joint(&joint(a, b, true)).unwrap();
    let r = w.step(DT).unwrap();
    assert_eq!(r.manifolds, 0);
    assert!(pair(&w, a, b).manifold.is_empty());
    assert_eq!(events(&w, a, b), [ContactEventKind::End]);

    // Two disabling joints: removing one keeps the pair excluded; a joint that does not
    // disable collisions changes nothing.
    let k = w.create_joint(&joint(a, b, true)).unwrap();
    w.create_joint(&joint(a, b, false)).unwrap();
    w.remove_joint(j).unwrap();
    assert_eq!(w.step(DT).unwrap().manifolds, 0);
    w.remove_joint(k).unwrap();
    assert_eq!(w.step(DT).unwrap().manifolds, 1);
}

#[test]
fn a_broken_joint_lets_its_bodies_collide() {
    let (mut w, a, b) = overlapping();
    // A steady pull on B loads the joint in every substep: the first step breaks it. (A
    // joint whose frames ask the centres to coincide, with no load, broke in f32 but not
    // in f64: the peak impulse is read after the last substep's relax pass.)
    let mut d = joint(a, b, true);
    d.break_impulse = 1e-3;
    let j = w.create_joint(&d).unwrap();
    w.bodies_mut()
        .add_force(b, Vec3::new(1.0e4, 0.0, 0.0))
        .unwrap();
    let r = w.step(DT).unwrap();
    assert_eq!(r.dynamics.broken_joints, [j]);
    assert_eq!(
        r.manifolds, 0,
        "excluded during the step that broke the joint"
    );
    // Lifted at the end of that step, generated at the next one.
    let p = pair(&w, a, b);
    assert!(!p.excluded && p.manifold.is_empty());
    let r = w.step(DT).unwrap();
    assert!(r.manifolds == 1 && r.contact_points > 0, "{r:?}");
    assert!(!pair(&w, a, b).excluded && !pair(&w, a, b).manifold.is_empty());
    // Removing the broken joint keeps the pair in.
    w.remove_joint(j).unwrap();
    assert_eq!(w.step(DT).unwrap().manifolds, 1);
}

#[test]
fn exclusions_survive_snapshots_and_go_with_removed_bodies() {
    let (mut w, a, b) = overlapping();
    let c = dyn_box(&mut w, Vec3::splat(0.5), Vec3::new(-0.8, 0.0, 0.0));
    w.create_joint(&joint(a, b, true)).unwrap();
    for _ in 0..3 {
        w.step(DT).unwrap();
    }
    let mut restored = World::from_bytes(&w.to_bytes().unwrap()).unwrap();
    let (oa, ob) = objects(&restored, a, b);
    assert!(restored.collision().narrowphase().is_excluded(oa, ob));
    for _ in 0..5 {
        let (r1, r2) = (
            w.step(DT).unwrap().clone(),
            restored.step(DT).unwrap().clone(),
        );
        assert_eq!((r1.pairs, r1.manifolds), (r2.pairs, r2.manifolds));
        // Only the A–C pair touches.
        assert_eq!(r1.manifolds, 1);
        assert_eq!(w.state_hash(), restored.state_hash());
    }
    // Removing B lifts the exclusion with its object; the joint went with it.
    let (oa, ob) = objects(&w, a, b);
    assert_eq!(w.remove_body(b).unwrap().len(), 1);
    assert!(!w.collision().narrowphase().is_excluded(oa, ob));
    w.step(DT).unwrap();
    assert!(pair(&w, a, c).manifold.len() == 4);
}

#[test]
fn ragdolls_hand_the_same_contacts_with_fewer_pairs_generated() {
    // "136 ragdolls": every jointed neighbour pair is excluded, and each pair that does
    // generate points is between bodies without a disabling joint.
    let scene = carom_scenes::bullet::scene(3).unwrap();
    let mut w = World::from_scene(&scene).unwrap();
    for _ in 0..steps(40, 5) {
        w.step(scene.dt).unwrap();
        let np = w.collision().narrowphase();
        let mut excluded = 0;
        for p in np.pairs() {
            let (ba, bb) = (
                w.body_of_object(p.a).unwrap(),
                w.body_of_object(p.b).unwrap(),
            );
            let disabled = w.joints().collision_disabled(ba, bb);
            assert_eq!(p.excluded, disabled, "{ba:?} {bb:?}");
            if p.excluded {
                excluded += 1;
                assert!(p.manifold.is_empty() && !p.touching);
            }
        }
        assert!(excluded > 500, "{excluded} excluded pairs");
    }
}
