//! The closed-form world boxes of boxes, cylinders and cones (`Shape::aabb`) against the
//! box of the exact support function along the six world axes (the generic path they
//! replace): random poses near and 1 km from the origin, axis-aligned and quarter-turn
//! poses (a disk seen edge-on), nearly aligned axes (where `1 − a²` would cancel), flat and
//! thin shapes.

mod common;

use carom_collision::math::{Aabb, Isometry, Quat, Real, Vec3};
use carom_collision::shape::*;
use common::Rng;

/// The box of the support points along ±x, ±y, ±z.
fn six_support_box(shape: &Shape, pose: &Isometry) -> Aabb {
    let convex = shape.as_convex().unwrap();
    let mut lo = Vec3::ZERO;
    let mut hi = Vec3::ZERO;
    for i in 0..3 {
        let mut e = Vec3::ZERO;
        e[i] = 1.0;
        hi[i] = pose.transform_point(convex.support(pose.rotation.inverse() * e))[i];
        lo[i] = pose.transform_point(convex.support(pose.rotation.inverse() * -e))[i];
    }
    Aabb::new(lo, hi)
}

fn shapes() -> Vec<Shape> {
    let mut v: Vec<Shape> = Vec::new();
    for (r, h) in [(0.6, 0.4), (0.05, 2.0), (2.0, 0.01), (1.0, 1.0)] {
        v.push(Cylinder::new(r, h).unwrap().into());
        v.push(Cone::new(r, h).unwrap().into());
    }
    for he in [
        Vec3::new(0.5, 1.0, 2.0),
        Vec3::new(0.001, 3.0, 0.2),
        Vec3::ONE,
    ] {
        v.push(Cuboid::new(he).unwrap().into());
    }
    v
}

fn poses(rng: &mut Rng) -> Vec<Isometry> {
    let mut out = Vec::new();
    let t = |rng: &mut Rng, far: Real| Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * far;
    for k in 0..150 {
        let far = if k % 2 == 0 { 1.0 } else { 1000.0 };
        let axis = Vec3::new(
            rng.uniform() - 0.4,
            rng.uniform() - 0.5,
            rng.uniform() - 0.6,
        );
        let q = Quat::from_axis_angle(axis.normalize(), 6.0 * rng.uniform());
        out.push(Isometry::new(t(rng, far), q));
    }
    // Identity, quarter and half turns about each axis: the axis along a world axis, so a
    // disk's extent along it is exactly 0 (or the round-off of the turn).
    let h = std::f64::consts::FRAC_PI_2 as Real;
    for q in [
        Quat::IDENTITY,
        Quat::from_rotation_x(h),
        Quat::from_rotation_z(h),
        Quat::from_rotation_y(h),
        Quat::from_rotation_x(2.0 * h),
        Quat::from_rotation_z(-h),
    ] {
        out.push(Isometry::new(t(rng, 10.0), q));
    }
    // Nearly aligned: tilted by 1e-4 .. 1e-2 rad.
    for tilt in [1e-4, 1e-3, 1e-2] {
        out.push(Isometry::new(t(rng, 1.0), Quat::from_rotation_x(tilt)));
        out.push(Isometry::new(t(rng, 1.0), Quat::from_rotation_z(h + tilt)));
    }
    out
}

#[test]
fn closed_form_boxes_equal_the_six_support_box() {
    let mut rng = Rng::new(11);
    let poses = poses(&mut rng);
    for shape in shapes() {
        let size = shape.local_aabb().extents().max_element();
        for pose in &poses {
            let got = shape.aabb(pose);
            let want = six_support_box(&shape, pose);
            let far = pose.translation.abs().max_element();
            let tol = 16.0 * Real::EPSILON * (far + 4.0 * size + 1.0);
            assert!(
                (got.min - want.min).abs().max_element() <= tol
                    && (got.max - want.max).abs().max_element() <= tol,
                "{}: {got:?} vs {want:?} at {pose:?}",
                shape.kind_name()
            );
            assert!(got.min.cmple(got.max).all());
        }
    }
}

#[test]
fn closed_form_boxes_contain_surface_samples() {
    // An independent oracle: points on the rims and the apex, placed by the pose, lie in
    // the box (within round-off), and the box's faces are touched by some of them.
    let mut rng = Rng::new(5);
    let poses = poses(&mut rng);
    for (r, h) in [(0.6, 0.4), (2.0, 0.01)] {
        let cyl: Shape = Cylinder::new(r, h).unwrap().into();
        let cone: Shape = Cone::new(r, h).unwrap().into();
        for pose in &poses {
            let far = pose.translation.abs().max_element();
            let tol = 32.0 * Real::EPSILON * (far + 4.0);
            let rim = |y: Real, k: usize| {
                let a = k as Real * std::f64::consts::TAU as Real / 720.0;
                pose.transform_point(Vec3::new(r * a.cos(), y, r * a.sin()))
            };
            for (shape, top_rim) in [(&cyl, true), (&cone, false)] {
                let b = shape.aabb(pose);
                let mut pts: Vec<Vec3> = (0..720).map(|k| rim(-h, k)).collect();
                if top_rim {
                    pts.extend((0..720).map(|k| rim(h, k)));
                } else {
                    pts.push(pose.transform_point(Vec3::new(0.0, h, 0.0)));
                }
                let (mut lo, mut hi) = (Vec3::splat(Real::INFINITY), Vec3::splat(-Real::INFINITY));
                for p in &pts {
                    assert!(b.expanded(tol).contains_point(*p), "{p} outside {b:?}");
                    lo = lo.min(*p);
                    hi = hi.max(*p);
                }
                // Sampling every half degree: within r (1 − cos 0.25°) of the faces.
                let slack = tol + r * 1e-5 + 1e-5;
                assert!(
                    (lo - b.min).max_element() <= slack,
                    "loose min {lo} vs {b:?}"
                );
                assert!(
                    (b.max - hi).max_element() <= slack,
                    "loose max {hi} vs {b:?}"
                );
            }
        }
    }
}
