//! `query::contact` on exactly touching and barely overlapping boxes whose faces are
//! coplanar: the cross products of in-plane edges are the face normal itself, and may win
//! the separating-axis test by round-off although those edges do not touch. The witness
//! points must still lie on the boxes and be `distance` apart along the normal (oracle:
//! the boxes' own surfaces, and the analytic gap of the stacked faces).

mod common;

use carom_collision::math::{Isometry, Quat, Real, Vec3};
use carom_collision::query;
use carom_collision::shape::{Cuboid, Shape};
use common::Rng;

/// Distance from `x` to the surface of the box `h` at `pose` (0 on it).
fn off_surface(x: Vec3, h: Vec3, pose: &Isometry) -> Real {
    let l = pose.inverse_transform_point(x);
    let out = (l.abs() - h).max(Vec3::ZERO).length();
    if out > 0.0 {
        out
    } else {
        (h - l.abs()).min_element()
    }
}

#[test]
fn touching_coplanar_boxes_have_witnesses_on_both_boxes() {
    let mut rng = Rng::new(7);
    let scale_tol = |p: Vec3| 2e-4 * (1.0 + p.abs().max_element() * 1e-3);
    let mut checked = 0;
    for i in 0..3000 {
        let ha = Vec3::new(
            rng.range(0.05, 1.0),
            rng.range(0.05, 1.0),
            rng.range(0.05, 1.0),
        );
        let hb = Vec3::new(
            rng.range(0.05, 1.0),
            rng.range(0.05, 1.0),
            rng.range(0.05, 1.0),
        );
        let far = if i % 3 == 0 {
            Vec3::new(
                rng.range(-1e3, 1e3),
                rng.range(-1e3, 1e3),
                rng.range(-1e3, 1e3),
            )
        } else {
            Vec3::ZERO
        };
        // B lies on A's top face (y = ha.y), turned about the shared normal; the gap is 0
        // (touching) or a small overlap.
        let gap: Real = [0.0, 0.0, -1e-3, -1e-5][i % 4];
        // The whole pair turned by a random rotation `g`, so that no axis is exact.
        let g = Quat::from_axis_angle(rng.unit(), rng.range(0.0, 3.1));
        let pa = Isometry::new(far, g);
        let turn = Quat::from_rotation_y(rng.range(-3.1, 3.1));
        let off = Vec3::new(
            rng.range(-ha.x, ha.x),
            ha.y + hb.y + gap,
            rng.range(-ha.z, ha.z),
        );
        let pb = Isometry::new(far + g * off, g * turn);
        let (a, b) = (
            Shape::Cuboid(Cuboid::new(ha).unwrap()),
            Shape::Cuboid(Cuboid::new(hb).unwrap()),
        );
        let c = query::contact(&a, &pa, &b, &pb, 0.01).unwrap().unwrap();
        let tol = scale_tol(far);
        let ctx = format!("case {i}: {c:?} ha {ha:?} hb {hb:?} off {off:?} turn {turn:?}");
        assert!((c.distance - gap).abs() < tol, "{ctx}");
        assert!((g.inverse() * c.normal).y > 0.9999, "{ctx}");
        assert!(
            off_surface(c.point_a, ha, &pa) < tol,
            "{ctx}: point_a off A"
        );
        assert!(
            off_surface(c.point_b, hb, &pb) < tol,
            "{ctx}: point_b off B"
        );
        let w = c.point_b - c.point_a - c.normal * c.distance;
        assert!(w.length() < tol, "{ctx}: witnesses {w:?} apart");
        checked += 1;
    }
    assert_eq!(checked, 3000);
}
