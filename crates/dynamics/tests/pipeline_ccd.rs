//! Continuous collision through speculative contacts: fast bodies never pass through thin
//! walls (a box wall, a thin box "paper", a triangle-mesh wall).
mod pipeline;
use carom_dynamics::collision::math::{Isometry, Quat, Real, Vec3};
use carom_dynamics::collision::shape::{Shape, TriMesh};
use carom_dynamics::*;
use pipeline::*;
use std::sync::Arc;

const DT: Real = 1.0 / 60.0;

fn zero_g() -> World {
    let mut p = PipelineParams::default();
    p.dynamics.gravity = Vec3::ZERO;
    p.dynamics.sleep.enabled = false;
    World::new(p).unwrap()
}

/// A projectile of `shape` starting at x = -`start` flying along +x at `speed`; returns the
/// largest x its centre reached over `n` steps.
fn shoot(w: &mut World, shape: Arc<Shape>, start: Vec3, speed: Real, rot: Quat, n: usize) -> Real {
    let mut d = BodyDesc::dynamic(shape, Isometry::new(start, rot), 1000.0);
    d.linear_velocity = Vec3::new(speed, 0.0, 0.0);
    d.max_linear_speed = 2.0 * speed;
    let b = w.add_body(&d).unwrap();
    let mut max_x = Real::NEG_INFINITY;
    for _ in 0..n {
        w.step(DT).unwrap();
        max_x = max_x.max(pos(w, b).x);
    }
    max_x
}

/// Without speculative contacts the same shot tunnels: the tests below can fail.
#[test]
fn without_speculative_contacts_the_sphere_tunnels() {
    let mut w = zero_g();
    w.set_speculative(false);
    w.add_body(&BodyDesc::fixed(
        cuboid(Vec3::new(0.005, 1.0, 1.0)),
        Isometry::IDENTITY,
    ))
    .unwrap();
    let x = shoot(
        &mut w,
        sphere(0.025),
        Vec3::new(-3.0, 0.0, 0.0),
        500.0,
        Quat::IDENTITY,
        3,
    );
    assert!(x > 1.0, "expected tunnelling, max x {x}");
}

/// A 5 cm sphere at 500 m/s (8.3 m per step) against a 1 cm box wall, from several offsets
/// so the wall is crossed at different fractions of a step.
#[test]
fn fast_sphere_never_passes_a_one_centimetre_wall() {
    for (k, start) in [-3.0 as Real, -5.0, -7.77, -8.3].into_iter().enumerate() {
        let mut w = zero_g();
        w.add_body(&BodyDesc::fixed(
            cuboid(Vec3::new(0.005, 1.0, 1.0)),
            Isometry::IDENTITY,
        ))
        .unwrap();
        let y = 0.1 * k as Real;
        let x = shoot(
            &mut w,
            sphere(0.025),
            Vec3::new(start, y, 0.0),
            500.0,
            Quat::IDENTITY,
            10,
        );
        assert!(x < -0.005, "start {start}: centre reached x = {x}");
    }
}

/// Bullet through paper: a small rotated box at 300 m/s against a 2 mm thin box.
#[test]
fn fast_box_does_not_pass_thin_box() {
    for rot in [
        Quat::IDENTITY,
        Quat::from_rotation_y(0.3) * Quat::from_rotation_z(0.5),
    ] {
        let mut w = zero_g();
        w.add_body(&BodyDesc::fixed(
            cuboid(Vec3::new(0.001, 0.5, 0.5)),
            Isometry::IDENTITY,
        ))
        .unwrap();
        let x = shoot(
            &mut w,
            cuboid(Vec3::splat(0.02)),
            Vec3::new(-4.0, 0.05, 0.0),
            300.0,
            rot,
            10,
        );
        assert!(x < 0.0, "box centre reached x = {x}");
    }
}

/// A fast sphere against a two-triangle mesh wall (the plane x = 0).
#[test]
fn fast_sphere_does_not_pass_mesh_wall() {
    let v = vec![
        Vec3::new(0.0, -1.0, -1.0),
        Vec3::new(0.0, 1.0, -1.0),
        Vec3::new(0.0, 1.0, 1.0),
        Vec3::new(0.0, -1.0, 1.0),
    ];
    let mesh: Arc<Shape> = Arc::new(TriMesh::new(v, vec![[0, 1, 2], [0, 2, 3]]).unwrap().into());
    for start in [-3.0 as Real, -6.1] {
        let mut w = zero_g();
        w.add_body(&BodyDesc::fixed(mesh.clone(), Isometry::IDENTITY))
            .unwrap();
        let x = shoot(
            &mut w,
            sphere(0.025),
            Vec3::new(start, 0.2, 0.1),
            500.0,
            Quat::IDENTITY,
            10,
        );
        assert!(x < 0.0, "start {start}: centre reached x = {x}");
    }
}

/// A falling sphere dropped from high above a thin floor at a speed that would skip it.
#[test]
fn fast_falling_sphere_lands_on_thin_floor() {
    let mut p = PipelineParams::default();
    p.dynamics.sleep.enabled = false;
    let mut w = World::new(p).unwrap();
    w.add_body(&BodyDesc::fixed(
        cuboid(Vec3::new(2.0, 0.005, 2.0)),
        Isometry::IDENTITY,
    ))
    .unwrap();
    let mut d = BodyDesc::dynamic(
        sphere(0.05),
        Isometry::from_translation(Vec3::new(0.0, 3.0, 0.0)),
        1000.0,
    );
    d.linear_velocity = Vec3::new(0.0, -200.0, 0.0);
    let b = w.add_body(&d).unwrap();
    for _ in 0..120 {
        w.step(DT).unwrap();
        assert!(pos(&w, b).y > 0.0, "fell through: {}", pos(&w, b).y);
    }
    let y = pos(&w, b).y;
    assert!((y - 0.055).abs() < 0.01, "resting height {y}");
}
