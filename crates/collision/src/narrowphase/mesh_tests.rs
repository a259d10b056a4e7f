//! The plane cull of `mesh_convex_contacts` against GJK/EPA distances: a culled triangle is
//! always farther than the prediction from the shape.

use super::*;
use crate::math::{consts::PI, Quat};
use crate::query::distance_convex;
use crate::shape::{Capsule, Cuboid, Sphere};

/// xorshift64*: deterministic, dependency-free.
struct Rng(u64);

impl Rng {
    fn uniform(&mut self) -> Real {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let x = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D);
        ((x >> 11) as f64 / (1u64 << 53) as f64) as Real
    }
    fn range(&mut self, lo: Real, hi: Real) -> Real {
        lo + (hi - lo) * self.uniform()
    }
    fn unit(&mut self) -> Vec3 {
        let z = self.range(-1.0, 1.0);
        let a = self.range(0.0, 2.0 * PI);
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * a.cos(), r * a.sin(), z)
    }
}

#[test]
fn plane_cull_only_skips_triangles_beyond_the_prediction() {
    let mut rng = Rng(0x51_7CC1_B727_220A);
    let sphere = Sphere::new(0.7).unwrap();
    let capsule = Capsule::new(0.4, 0.9).unwrap();
    let cuboid = Cuboid::new(Vec3::new(0.3, 1.1, 0.6)).unwrap();
    let shapes = [
        ConvexRef::Sphere(&sphere),
        ConvexRef::Capsule(&capsule),
        ConvexRef::Cuboid(&cuboid),
    ];
    let (mut culled, mut kept) = (0, 0);
    for k in 0..6000 {
        let b = shapes[k % 3];
        let far = if k % 7 == 0 { 1.0e3 } else { 1.0 };
        let pose = Isometry::new(
            rng.unit() * rng.range(0.0, 3.0) * far,
            Quat::from_axis_angle(rng.unit(), rng.range(0.0, 3.0)),
        );
        // A triangle whose plane passes near the shape (grazing, touching, or just clear),
        // sometimes large (coplanar with a box face when the normal is one of its axes).
        let n = if k % 5 == 0 {
            pose.rotation * [Vec3::X, Vec3::Y, Vec3::Z][k % 3]
        } else {
            rng.unit()
        };
        let reach = match b {
            ConvexRef::Sphere(s) => s.radius(),
            _ => {
                let p = b.support_world(&pose, n);
                n.dot(p - pose.translation)
            }
        };
        let prediction = [0.0, 0.02, 0.1][k % 3];
        let gap = reach + prediction + rng.range(-0.05, 0.05) * [1.0, 1.0e-3][k % 2];
        let centre = pose.translation + n * gap + rng.unit().cross(n) * rng.range(0.0, 2.0);
        let (t1, t2) = (
            n.any_orthonormal_vector(),
            n.cross(n.any_orthonormal_vector()),
        );
        let size = rng.range(0.1, 5.0);
        let corner = |a: Real| centre + (t1 * a.cos() + t2 * a.sin()) * size;
        let tri = Triangle {
            a: corner(0.0),
            b: corner(2.1),
            c: corner(4.2),
        };
        let Some(tn) = tri.normal() else { continue };
        let slab = PlaneSlab::new(b, &pose).unwrap();
        let tri_ref = ConvexRef::Triangle(&tri);
        if slab.clear_of_plane(tn, tn.dot(tri.a), prediction) {
            culled += 1;
            let d = distance_convex(tri_ref, b, &pose).distance;
            assert!(d > prediction, "culled at distance {d} (case {k})");
        } else {
            kept += 1;
        }
    }
    assert!(culled > 1000 && kept > 1000, "culled {culled}, kept {kept}");
}

#[test]
fn hull_box_cull_only_skips_triangles_beyond_the_prediction() {
    let mut rng = Rng(0x2545_F491_4F6C_DD1D);
    let pts: Vec<Vec3> = (0..30)
        .map(|_| rng.unit() * Vec3::new(1.8, 2.0, 1.2) * rng.range(0.5, 1.0))
        .collect();
    let hull = ConvexHull::new(&pts).unwrap();
    let b = ConvexRef::ConvexHull(&hull);
    let (mut culled, mut kept) = (0, 0);
    for k in 0..6000 {
        let far = if k % 7 == 0 { 1.0e3 } else { 1.0 };
        let pose = Isometry::new(
            rng.unit() * rng.range(0.0, 3.0) * far,
            Quat::from_axis_angle(rng.unit(), rng.range(0.0, 3.0)),
        );
        let (lo, hi) = hull.rotated_bounds(pose.rotation);
        let slab = PlaneSlab::from_box(lo + pose.translation, hi + pose.translation);
        // A triangle whose plane passes near the hull's box (grazing, touching, or clear),
        // sometimes along a box axis (coplanar with a box face).
        let n = if k % 5 == 0 {
            [Vec3::X, Vec3::Y, Vec3::Z][k % 3]
        } else {
            rng.unit()
        };
        let half = (hi - lo) * 0.5;
        let reach = half.x * n.x.abs() + half.y * n.y.abs() + half.z * n.z.abs();
        let centre_box = (lo + hi) * 0.5 + pose.translation;
        let prediction = [0.0, 0.02, 0.1][k % 3];
        let gap = reach + prediction + rng.range(-0.05, 0.05) * [1.0, 1.0e-3][k % 2];
        let centre = centre_box + n * gap + rng.unit().cross(n) * rng.range(0.0, 2.0);
        let (t1, t2) = (
            n.any_orthonormal_vector(),
            n.cross(n.any_orthonormal_vector()),
        );
        let size = rng.range(0.1, 5.0);
        let corner = |a: Real| centre + (t1 * a.cos() + t2 * a.sin()) * size;
        let tri = Triangle {
            a: corner(0.0),
            b: corner(2.1),
            c: corner(4.2),
        };
        let Some(tn) = tri.normal() else { continue };
        if slab.clear_of_plane(tn, tn.dot(tri.a), prediction) {
            culled += 1;
            let d = distance_convex(ConvexRef::Triangle(&tri), b, &pose).distance;
            assert!(d > prediction, "culled at distance {d} (case {k})");
            // The hull's own face test rejects it too: no contact is lost.
            let pb = Polyhedron::from_hull(&hull);
            let posed = super::posed_hull(&pb, &pose);
            let mut out = ContactList::new();
            let mut scratch = super::EdgeScratch::new(&pb, &posed);
            let pa = Polyhedron::from_triangle(&tri);
            super::triangle_hull_manifold(
                &pa,
                &pb,
                &posed,
                &pose,
                prediction,
                &mut scratch,
                &mut out,
            );
            assert!(out.is_empty(), "case {k}");
        } else {
            kept += 1;
        }
    }
    assert!(culled > 1000 && kept > 1000, "culled {culled}, kept {kept}");
}
