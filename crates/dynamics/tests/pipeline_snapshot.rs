//! Snapshots: step N, save, restore, step M gives bit-identical states to stepping N + M
//! without stopping, on a scene with stacked contacts (warm starts), joints, sleeping
//! bodies, removed bodies (free slots) and the step_simulation accumulator; on 1 and 2
//! threads and every broadphase method. Corrupt and truncated bytes are errors.
mod pipeline;
use carom_dynamics::collision::broadphase::Method;
use carom_dynamics::collision::math::{Isometry, Quat, Real, Vec3};
use carom_dynamics::*;
use pipeline::*;
use std::sync::Arc;

/// Ground, a 6-box stack (falls asleep), a sphere pile, a hinge/ball/fixed/slider chain from
/// a static anchor, a 6-DOF pair and a breakable joint; two bodies removed.
fn scene(method: Method) -> World {
    let mut p = PipelineParams {
        broadphase: method,
        ..Default::default()
    };
    p.dynamics.gravity = Vec3::new(0.0, -10.0, 0.0);
    p.dynamics.solver.parallel_min_batch = 2;
    let mut w = World::new(p).unwrap();
    ground(&mut w, 0.6);
    let shared = cuboid(Vec3::splat(0.25));
    let mut stack = Vec::new();
    for i in 0..6 {
        let d = BodyDesc::dynamic(
            shared.clone(),
            Isometry::from_translation(Vec3::new(3.0, 0.25 + 0.5 * i as Real, 0.0)),
            500.0,
        );
        stack.push(w.add_body(&d).unwrap());
    }
    for i in 0..8 {
        let p = Vec3::new(
            -2.0 + 0.31 * (i % 3) as Real,
            0.5 + 0.6 * i as Real,
            0.1 * i as Real,
        );
        w.add_body(&BodyDesc::dynamic(
            sphere(0.3),
            Isometry::from_translation(p),
            700.0,
        ))
        .unwrap();
    }
    let anchor = w
        .add_body(&BodyDesc::fixed(
            cuboid(Vec3::splat(0.1)),
            Isometry::from_translation(Vec3::new(0.0, 4.0, -3.0)),
        ))
        .unwrap();
    let kinds = [
        JointKind::Hinge {
            limits: Some((-0.5, 0.8)),
            motor: None,
        },
        JointKind::Ball,
        JointKind::ConeTwist {
            swing1: 0.4,
            swing2: 0.3,
            twist: 0.2,
        },
        JointKind::Fixed,
        JointKind::Slider {
            limits: Some((-0.1, 0.1)),
            motor: Some(Motor {
                speed: 0.5,
                max_force: 50.0,
            }),
        },
    ];
    let mut prev = anchor;
    for (i, kind) in kinds.into_iter().enumerate() {
        let link = w
            .add_body(&BodyDesc::dynamic(
                cuboid(Vec3::new(0.3, 0.08, 0.08)),
                Isometry::new(
                    Vec3::new(0.6 * (i + 1) as Real, 4.0, -3.0),
                    Quat::from_rotation_y(0.1),
                ),
                300.0,
            ))
            .unwrap();
        let mut j = JointDesc::new(
            prev,
            link,
            Isometry::from_translation(Vec3::new(if i == 0 { 0.0 } else { 0.3 }, 0.0, 0.0)),
            Isometry::from_translation(Vec3::new(-0.3, 0.0, 0.0)),
            kind,
        );
        if i == 1 {
            j.break_impulse = 40.0;
        }
        w.create_joint(&j).unwrap();
        prev = link;
    }
    let axis = |mode| Axis {
        mode,
        motor: None,
        spring: Some(Spring {
            hertz: 2.0,
            damping_ratio: 0.3,
            rest: 0.0,
        }),
    };
    let a = dyn_box(&mut w, Vec3::splat(0.2), Vec3::new(-4.0, 2.0, 2.0));
    let b = dyn_box(&mut w, Vec3::splat(0.2), Vec3::new(-4.0, 1.4, 2.0));
    let six = JointKind::Generic6Dof {
        linear: [
            axis(AxisMode::Locked),
            axis(AxisMode::Limited {
                low: -0.2,
                high: 0.2,
            }),
            axis(AxisMode::Free),
        ],
        angular: [
            axis(AxisMode::Free),
            axis(AxisMode::Locked),
            axis(AxisMode::Free),
        ],
    };
    w.create_joint(&JointDesc::new(
        a,
        b,
        Isometry::from_translation(Vec3::new(0.0, -0.3, 0.0)),
        Isometry::from_translation(Vec3::new(0.0, 0.3, 0.0)),
        six,
    ))
    .unwrap();
    // Free slots in the body set and the collision world.
    let gone = dyn_box(&mut w, Vec3::splat(0.1), Vec3::new(8.0, 0.1, 8.0));
    let gone2 = dyn_box(&mut w, Vec3::splat(0.1), Vec3::new(8.0, 0.1, 9.0));
    w.step(1.0 / 60.0).unwrap();
    w.remove_body(gone).unwrap();
    w.remove_body(gone2).unwrap();
    w
}

fn advance(w: &mut World, n: usize) -> Vec<u64> {
    (0..n)
        .map(|_| {
            // 1/50 s frames through the fixed-step accumulator (leftover time carries over).
            w.step_simulation(1.0 / 50.0, 4, 1.0 / 60.0).unwrap();
            w.state_hash()
        })
        .collect()
}

fn check_round_trip(method: Method, threads: usize) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut w = scene(method);
        let n = steps(150, 60);
        advance(&mut w, n);
        assert!(w.sleeping_count() > 0, "{method:?}: nothing sleeps yet");
        assert!(
            w.last_report().manifolds > 5,
            "{method:?}: no stacked contacts"
        );
        assert!(w.accumulator() > 0.0, "{method:?}: empty accumulator");
        let bytes = w.to_bytes().unwrap();
        let mut r = World::from_bytes(&bytes).unwrap();
        assert_eq!(r.state_hash(), w.state_hash());
        assert_eq!(r.handles(), w.handles());
        assert_eq!(r.sleeping_count(), w.sleeping_count());
        assert_eq!(r.accumulator().to_bits(), w.accumulator().to_bits());
        assert_eq!(r.collision().pairs().len(), w.collision().pairs().len());
        assert_eq!(
            r.to_bytes().unwrap(),
            bytes,
            "{method:?}: re-encoding differs"
        );
        // Wake the sleepers in both, so the stack's warm starts matter again.
        let m = steps(90, 40);
        let h1 = advance(&mut w, m / 2);
        let h2 = advance(&mut r, m / 2);
        assert_eq!(
            h1, h2,
            "{method:?}, {threads} threads: diverged after restore"
        );
        let hs = w.handles();
        for &h in &hs[1..4] {
            w.bodies_mut()
                .apply_impulse(h, Vec3::X * 5.0, Vec3::ZERO)
                .unwrap();
            r.bodies_mut()
                .apply_impulse(h, Vec3::X * 5.0, Vec3::ZERO)
                .unwrap();
        }
        // A body added after the restore takes the same slot in both worlds.
        let na = dyn_box(&mut w, Vec3::splat(0.2), Vec3::new(6.0, 0.2, 6.0));
        let nb = dyn_box(&mut r, Vec3::splat(0.2), Vec3::new(6.0, 0.2, 6.0));
        assert_eq!(na, nb);
        assert_eq!(
            w.object(na).unwrap().map(|o| o.index),
            r.object(nb).unwrap().map(|o| o.index)
        );
        let h1 = advance(&mut w, m / 2);
        let h2 = advance(&mut r, m / 2);
        assert_eq!(
            h1, h2,
            "{method:?}, {threads} threads: diverged after waking"
        );
        let ev = |w: &World| format!("{:?}", w.collision().narrowphase().events());
        assert_eq!(ev(&w), ev(&r));
    });
}

#[test]
fn continuing_from_a_snapshot_is_bit_identical_on_one_and_two_threads() {
    check_round_trip(Method::default(), 1);
    check_round_trip(Method::default(), 2);
}

#[test]
fn every_broadphase_method_restores_exactly() {
    for m in Method::ALL {
        check_round_trip(m, 2);
    }
}

#[test]
fn warm_starts_survive_the_snapshot() {
    let mut w = scene(Method::default());
    advance(&mut w, 20);
    let r = World::from_bytes(&w.to_bytes().unwrap()).unwrap();
    let impulses = |w: &World| -> Vec<u64> {
        w.collision()
            .narrowphase()
            .manifolds()
            .flat_map(|p| {
                p.manifold
                    .points
                    .iter()
                    .map(|q| q.normal_impulse.to_bits() as u64)
            })
            .collect()
    };
    let before = impulses(&w);
    assert!(
        before.iter().any(|&x| x != 0),
        "no accumulated impulse to keep"
    );
    assert_eq!(before, impulses(&r));
}

#[test]
fn shared_shapes_are_stored_once() {
    let s = cuboid(Vec3::splat(0.5));
    let build = |shared: bool| {
        let mut w = world(false);
        for i in 0..50 {
            let p = Isometry::from_translation(Vec3::X * 2.0 * i as Real);
            let shape = if shared {
                s.clone()
            } else {
                cuboid(Vec3::splat(0.5))
            };
            w.add_body(&BodyDesc::dynamic(shape, p, 1.0)).unwrap();
        }
        w
    };
    let shared = build(true).to_bytes().unwrap();
    let distinct = build(false).to_bytes().unwrap();
    let one = postcard::to_allocvec(&*s).unwrap().len();
    assert_eq!(
        distinct.len() - shared.len(),
        49 * one,
        "one shape encoding each"
    );
    let r = World::from_bytes(&shared).unwrap();
    let hs = r.handles();
    let s0 = r.bodies().info(hs[0]).unwrap().shape.clone().unwrap();
    let s1 = r.bodies().info(hs[49]).unwrap().shape.clone().unwrap();
    assert!(Arc::ptr_eq(&s0, &s1), "restored shapes are shared again");
    let o = r.object(hs[3]).unwrap().unwrap();
    assert!(Arc::ptr_eq(&r.collision().get(o).unwrap().shape, &s0));
}

#[test]
fn corrupt_and_truncated_bytes_are_errors_not_panics() {
    let mut w = scene(Method::default());
    advance(&mut w, 5);
    let bytes = w.to_bytes().unwrap();
    for cut in [0, 5, 10, 12, 20, 21, 40, bytes.len() / 2, bytes.len() - 1] {
        let e = World::from_bytes(&bytes[..cut]).unwrap_err().to_string();
        assert!(e.contains("snapshot"), "cut {cut}: {e}");
    }
    let mut flipped = 0;
    for k in (0..bytes.len()).step_by(37) {
        let mut b = bytes.clone();
        b[k] ^= 0x5a;
        assert!(World::from_bytes(&b).is_err(), "flip at {k} accepted");
        flipped += 1;
    }
    assert!(flipped > 10);
    // Another version, including the last ones before manifolds kept their GJK simplex
    // (2) and before the landed bodies were stored (3): this build would misread them.
    for version in [99u16, 2, 3] {
        let mut b = bytes.clone();
        b[10..12].copy_from_slice(&version.to_le_bytes());
        let e = World::from_bytes(&b).unwrap_err().to_string();
        assert!(e.contains(&format!("format version {version}")), "{e}");
    }
    let mut b = bytes.clone();
    b[12] = 2; // precision
    assert!(World::from_bytes(&b)
        .unwrap_err()
        .to_string()
        .contains("bit reals"));
    let mut b = bytes.clone();
    b.push(0);
    assert!(World::from_bytes(&b).is_err());
    assert!(World::from_bytes(b"not a world").is_err());
}

/// Hull pairs keep their GJK simplex in their manifolds (`ContactManifold::warm`), and the
/// next query starts from it, so a restored world must carry it to continue bit for bit:
/// "convex pack" (90 hull cells falling into a pile) snapshotted mid-fall.
#[test]
fn hull_piles_continue_bit_for_bit_after_restore() {
    let scene = carom_scenes::bullet::scene(8).unwrap();
    let mut params = PipelineParams::default();
    params.dynamics.sleep.enabled = false;
    let mut w = World::from_scene_with(&scene, params).unwrap();
    for _ in 0..40 {
        w.step(scene.dt).unwrap();
    }
    let kept = w
        .collision()
        .narrowphase()
        .pairs()
        .filter(|p| p.manifold.warm.len > 0)
        .count();
    assert!(kept > 10, "only {kept} pairs keep a simplex");
    let mut r = World::from_bytes(&w.to_bytes().unwrap()).unwrap();
    for step in 0..40 {
        w.step(scene.dt).unwrap();
        r.step(scene.dt).unwrap();
        assert_eq!(w.state_hash(), r.state_hash(), "step {step} after restore");
    }
}

/// Which bodies landed on another in the last step sets the next step's speculative margins
/// (such a body may stop), so a restored world must carry it: "1000 stack"
/// snapshotted while the pyramid's layers land one on another.
#[test]
fn landing_layers_continue_bit_for_bit_after_restore() {
    let scene = carom_scenes::bullet::scene(2).unwrap();
    let mut w = World::from_scene(&scene).unwrap();
    for _ in 0..12 {
        w.step(scene.dt).unwrap();
    }
    let mut r = World::from_bytes(&w.to_bytes().unwrap()).unwrap();
    for step in 0..12 {
        w.step(scene.dt).unwrap();
        r.step(scene.dt).unwrap();
        assert_eq!(w.state_hash(), r.state_hash(), "step {step} after restore");
    }
}

/// Session 27's sweep: a world saved before its first step (no pairs yet) restored with the
/// rebuild's empty pairs, so its bytes were about 100 bytes longer per overlapping pair until
/// the next step. Empty, non-touching pairs are left out of the bytes, so saving, restoring
/// and saving again gives the same bytes, and both worlds step alike.
#[test]
fn a_restored_world_saves_the_bytes_it_came_from() {
    let mut w = World::new(PipelineParams::default()).unwrap();
    let cap: Arc<carom_dynamics::collision::shape::Shape> = Arc::new(
        carom_dynamics::collision::shape::Capsule::new(0.2, 0.3)
            .unwrap()
            .into(),
    );
    for y in [0.0, 0.7, 1.4] {
        w.add_body(&BodyDesc::dynamic(
            cap.clone(),
            Isometry::from_translation(Vec3::Y * y),
            1000.0,
        ))
        .unwrap();
    }
    let bytes = w.to_bytes().unwrap();
    let mut r = World::from_bytes(&bytes).unwrap();
    assert_eq!(r.to_bytes().unwrap(), bytes);
    w.step(1.0 / 60.0).unwrap();
    r.step(1.0 / 60.0).unwrap();
    assert_eq!(w.state_hash(), r.state_hash());
    assert_eq!(w.to_bytes().unwrap(), r.to_bytes().unwrap());
}
