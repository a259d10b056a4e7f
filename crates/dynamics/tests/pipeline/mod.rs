//! Helpers of the full-pipeline tests: real collision detection through [`World`].
#![allow(dead_code)]

use carom_dynamics::collision::math::{Isometry, Quat, Real, Vec3};
use carom_dynamics::collision::shape::{Cuboid, Shape, Sphere};
use carom_dynamics::*;
use std::sync::Arc;

pub fn sphere(r: Real) -> Arc<Shape> {
    Arc::new(Sphere::new(r).unwrap().into())
}

pub fn cuboid(h: Vec3) -> Arc<Shape> {
    Arc::new(Cuboid::new(h).unwrap().into())
}

/// A world with gravity (0, -10, 0) and sleeping as given.
pub fn world(sleep: bool) -> World {
    let mut p = PipelineParams::default();
    p.dynamics.gravity = Vec3::new(0.0, -10.0, 0.0);
    p.dynamics.sleep.enabled = sleep;
    World::new(p).unwrap()
}

/// A static ground box whose top face is y = 0.
pub fn ground(w: &mut World, friction: Real) -> BodyHandle {
    let mut d = BodyDesc::fixed(
        cuboid(Vec3::new(50.0, 1.0, 50.0)),
        Isometry::from_translation(Vec3::new(0.0, -1.0, 0.0)),
    );
    d.friction = friction;
    w.add_body(&d).unwrap()
}

/// A dynamic box of half extents `h` (density 1000) at `p`.
pub fn dyn_box(w: &mut World, h: Vec3, p: Vec3) -> BodyHandle {
    w.add_body(&BodyDesc::dynamic(
        cuboid(h),
        Isometry::new(p, Quat::IDENTITY),
        1000.0,
    ))
    .unwrap()
}

/// A column of `n` unit boxes standing on the ground, the lowest resting on it.
pub fn box_column(w: &mut World, n: usize) -> Vec<BodyHandle> {
    (0..n)
        .map(|i| dyn_box(w, Vec3::splat(0.5), Vec3::new(0.0, 0.5 + i as Real, 0.0)))
        .collect()
}

pub fn pos(w: &World, b: BodyHandle) -> Vec3 {
    w.bodies().center_of_mass(b).unwrap()
}

/// Largest displacement of `bodies` from `start`.
pub fn max_drift(w: &World, bodies: &[BodyHandle], start: &[Vec3]) -> Real {
    bodies
        .iter()
        .zip(start)
        .map(|(&b, &s)| (pos(w, b) - s).length())
        .fold(0.0, Real::max)
}

/// `release` steps in optimised builds, `debug` otherwise.
pub fn steps(release: usize, debug: usize) -> usize {
    if cfg!(debug_assertions) {
        debug
    } else {
        release
    }
}
