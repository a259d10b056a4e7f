//! Unit tests of the dispatcher (moved out of `dispatcher.rs`, the project's 700-line limit).

use super::{as_polyhedron, convert_points, is_polyhedral};
use crate::math::{Isometry, Quat, Real, Vec3};
use crate::narrowphase::contact::ContactPoint;
use crate::query::Contact;
use crate::shape::{
    Capsule, Cone, ConvexHull, ConvexRef, Cuboid, Cylinder, Scaled, Shape, Sphere, Triangle,
};
use std::sync::Arc;

/// The cheap dispatch guard agrees with building the view, for every kind of convex
/// (including a degenerate triangle, whose view still exists).
#[test]
fn is_polyhedral_matches_as_polyhedron() {
    let sphere = Sphere::new(0.5).unwrap();
    let cuboid = Cuboid::new(Vec3::new(0.3, 0.4, 0.5)).unwrap();
    let capsule = Capsule::new(0.2, 0.6).unwrap();
    let cylinder = Cylinder::new(0.3, 0.7).unwrap();
    let cone = Cone::new(0.3, 0.7).unwrap();
    let pts = [
        Vec3::ZERO,
        Vec3::X,
        Vec3::Y,
        Vec3::Z,
        Vec3::new(1.0, 1.0, 1.0),
    ];
    let hull = ConvexHull::new(&pts).unwrap();
    let tri = Triangle {
        a: Vec3::ZERO,
        b: Vec3::X,
        c: Vec3::Y,
    };
    let flat = Triangle {
        a: Vec3::ZERO,
        b: Vec3::X,
        c: Vec3::X * 2.0,
    };
    let scaled = Scaled::new(Arc::new(Shape::Cuboid(cuboid)), Vec3::new(2.0, 1.0, 0.5)).unwrap();
    let all = [
        ConvexRef::Sphere(&sphere),
        ConvexRef::Cuboid(&cuboid),
        ConvexRef::Capsule(&capsule),
        ConvexRef::Cylinder(&cylinder),
        ConvexRef::Cone(&cone),
        ConvexRef::ConvexHull(&hull),
        ConvexRef::Triangle(&tri),
        ConvexRef::Triangle(&flat),
        ConvexRef::Scaled(&scaled),
    ];
    let mut polyhedral = 0;
    for c in all {
        assert_eq!(is_polyhedral(c), as_polyhedron(c).is_some(), "{c:?}");
        polyhedral += usize::from(is_polyhedral(c));
    }
    assert_eq!(polyhedral, 4);
}

/// The bits of every float of a point (so `-0.0` and `0.0`, and NaNs, are told apart).
fn point_bits(p: &ContactPoint) -> Vec<u64> {
    let v = |v: Vec3| v.to_array().map(|x| x.to_bits() as u64);
    let mut out = vec![p.distance.to_bits() as u64, p.feature as u64];
    for x in [p.normal, p.point_b, p.local_a, p.local_b, p.local_normal_b] {
        out.extend(v(x));
    }
    out.push(p.normal_impulse.to_bits() as u64);
    out.extend(p.tangent_impulse.map(|x| x.to_bits() as u64));
    out.push(p.lifetime as u64);
    out
}

/// `convert_points` (SIMD columns, the normal formed once per run of equal normals) gives
/// `ContactPoint::from_local_contact_mat`'s points bit for bit: runs of one normal (a face
/// clip), alternating normals, normals equal as numbers but not as bits (`-0.0`), axis
/// normals with zero products, poses near and 1 km from the origin, and NaN inputs.
#[test]
fn convert_points_matches_the_scalar_conversion_bit_for_bit() {
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    let mut rnd = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as Real / (1u64 << 53) as Real - 0.5
    };
    let mut out = Vec::new();
    for case in 0..4000 {
        let far = if case % 3 == 0 { 1000.0 } else { 1.0 };
        let pose = |rnd: &mut dyn FnMut() -> Real| {
            let axis = Vec3::new(rnd(), rnd(), rnd()).normalize_or(Vec3::X);
            Isometry::new(
                Vec3::new(rnd(), rnd(), rnd()) * far,
                Quat::from_axis_angle(axis, rnd() * 7.0),
            )
        };
        let (pose_a, pose_b) = (pose(&mut rnd), pose(&mut rnd));
        let shared = match case % 4 {
            0 => Vec3::new(rnd(), rnd(), rnd()).normalize_or(Vec3::Y),
            1 => Vec3::new(0.0, -1.0, 0.0),
            2 => Vec3::new(-0.0, 1.0, 0.0),
            _ => Vec3::new(0.0, 0.0, -1.0),
        };
        let n_points = 1 + case % 9;
        let contacts: Vec<(Contact, u32)> = (0..n_points)
            .map(|k| {
                let normal = match (case / 4 % 4, k % 3) {
                    (0, _) => shared,
                    (1, 1) => Vec3::new(rnd(), rnd(), rnd()).normalize_or(Vec3::Z),
                    (2, 2) => shared * Vec3::new(-1.0, -1.0, -1.0) * -1.0,
                    (3, 0) => Vec3::new(0.0, -0.0, 1.0),
                    _ => shared,
                };
                let mut point_a = Vec3::new(rnd(), rnd(), rnd()) * far;
                if case % 97 == 0 && k == 0 {
                    point_a.x = Real::NAN;
                }
                let distance = rnd() * 0.1;
                let c = Contact {
                    distance,
                    point_a,
                    point_b: point_a + normal * distance,
                    normal,
                };
                (c, k as u32 * 7 + case as u32)
            })
            .collect();
        let (ra, rb) = (pose_a.rotation_matrix(), pose_b.rotation_matrix());
        let rb_t = rb.transpose();
        let (ta, tb) = (pose_a.translation, pose_b.translation);
        out.clear();
        convert_points(&contacts, (&ra, ta), (&rb_t, tb), &mut out);
        assert_eq!(out.len(), contacts.len());
        for ((c, id), p) in contacts.iter().zip(&out) {
            let want = ContactPoint::from_local_contact_mat(c, (&ra, ta), (&rb_t, tb), *id);
            assert_eq!(point_bits(p), point_bits(&want), "case {case}");
        }
    }
}
