//! The triangle-specialised test against the general one (`polyhedron_manifold_posed` with
//! the hull's arcs), bit for bit, over random and degenerate triangle–hull configurations.

use super::*;
use crate::math::{consts::PI, Quat};
use crate::narrowphase::polyhedron::polyhedron_manifold_posed;
use crate::shape::{ConvexHull, Triangle};

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

/// The 43 Taru points of Bullet's benchmark (the convex–trimesh scene's hull).
fn taru() -> ConvexHull {
    let pts: Vec<Vec3> = include_str!("../../../scenes/data/taru.obj")
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let c: Vec<f64> = l.split_whitespace().flat_map(|x| x.parse()).collect();
            Vec3::new(c[0] as Real, c[1] as Real, c[2] as Real)
        })
        .collect();
    ConvexHull::new(&pts).unwrap()
}

/// Bit patterns of a contact list, for exact comparison.
fn bits(cs: &[(crate::query::Contact, u32)]) -> Vec<[u64; 11]> {
    #[allow(clippy::useless_conversion)]
    let b = |x: Real| f64::from(x).to_bits();
    cs.iter()
        .map(|(c, id)| {
            let (p, q, n) = (c.point_a, c.point_b, c.normal);
            [
                b(c.distance),
                b(p.x),
                b(p.y),
                b(p.z),
                b(q.x),
                b(q.y),
                b(q.z),
                b(n.x),
                b(n.y),
                b(n.z),
                u64::from(*id),
            ]
        })
        .collect()
}

/// Compares both paths on `tri` against `hull` at `pose`; returns the contact count and
/// whether an edge pair was the feature.
fn compare(tri: &Triangle, hull: &ConvexHull, pose: &Isometry, prediction: Real) -> (usize, bool) {
    let (pa, pb) = (Polyhedron::from_triangle(tri), Polyhedron::from_hull(hull));
    let general = PosedPolyhedron::new(&pb, pose, true);
    let mut old = Vec::new();
    polyhedron_manifold_posed(&pa, &pb, &general, pose, prediction, &mut old);
    let posed = PosedPolyhedron::new(&pb, pose, false);
    let mut new = Vec::new();
    let mut scratch = EdgeScratch::new(&pb, &posed);
    triangle_hull_manifold(&pa, &pb, &posed, pose, prediction, &mut scratch, &mut new);
    assert_eq!(bits(&old), bits(&new), "triangle {tri:?} pose {pose:?}");
    let edge = new.iter().any(|(_, id)| id & 0x8000_0000 != 0);
    (new.len(), edge)
}

/// A triangle near the surface of `hull` at `pose` (mesh frame): around the hull's support
/// point along `u`, offset by `gap` along `u`, tilted from the plane perpendicular to `u`.
fn near_triangle(rng: &mut Rng, hull: &ConvexHull, pose: &Isometry, size: Real) -> Triangle {
    let u = rng.unit();
    let local = pose.inverse_transform_vector(-u);
    let s = pose.transform_point(hull.vertices()[hull.support_vertex(local)]);
    let gap = rng.range(-0.1, 0.05) * size.min(1.0);
    let centre = s - u * gap;
    let tilt = (rng.unit() * rng.range(0.0, 0.6) + u).normalize();
    let t1 = tilt.any_orthonormal_vector();
    let t2 = tilt.cross(t1);
    let corner = |_: usize, rng: &mut Rng| {
        let a = rng.range(0.0, 2.0 * PI);
        centre + (t1 * a.cos() + t2 * a.sin()) * size * rng.range(0.3, 1.0)
    };
    let (a, b, c) = (corner(0, rng), corner(1, rng), corner(2, rng));
    Triangle { a, b, c }
}

#[test]
fn matches_the_general_path_on_random_triangles() {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let mut sphere_pts: Vec<Vec3> = Vec::new();
    for _ in 0..120 {
        sphere_pts.push(rng.unit() * 0.8);
    }
    // Taru (the scene's hull), a many-faced hull (more than 64 faces: the unmasked path)
    // and a thin slab (nearly parallel faces and edges).
    let slab: Vec<Vec3> = (0..8)
        .map(|k| {
            Vec3::new(
                k as Real % 2.0 * 2.0 - 1.0,
                (k / 2 % 2) as Real * 0.02,
                (k / 4) as Real,
            )
        })
        .collect();
    let hulls = [
        taru(),
        ConvexHull::new(&sphere_pts).unwrap(),
        ConvexHull::new(&slab).unwrap(),
    ];
    assert!(hulls[1].faces().len() > 64);
    let (mut cases, mut touching, mut edges) = (0, 0, 0);
    for (h, hull) in hulls.iter().enumerate() {
        for k in 0..3000 {
            let far = if k % 5 == 0 { 1.0e3 } else { 1.0 };
            let pose = Isometry::new(
                rng.unit() * rng.range(0.0, 2.0) * far,
                Quat::from_axis_angle(rng.unit(), rng.range(0.0, 3.0)),
            );
            let size = [0.05, 0.5, 3.0, 20.0][k % 4];
            let tri = near_triangle(&mut rng, hull, &pose, size);
            let (n, edge) = compare(&tri, hull, &pose, [0.0, 0.02, 0.1][k % 3]);
            cases += 1;
            touching += usize::from(n > 0);
            edges += usize::from(edge);
        }
        assert!(
            touching > 1000 * (h + 1),
            "hull {h}: only {touching} in contact"
        );
    }
    assert!(
        edges > 100,
        "only {edges} edge-pair contacts in {cases} cases"
    );
}

#[test]
fn matches_the_general_path_on_degenerate_triangles() {
    let hull = taru();
    let mut rng = Rng(7);
    for (f, face) in hull.faces().iter().enumerate() {
        // Coplanar with a hull face (touching and slightly apart), the face's own corners
        // (shared vertices and edges), and a triangle with an edge along a hull edge.
        let lp = hull.face_vertices(f);
        let v = |i: usize| hull.vertices()[lp[i % lp.len()] as usize];
        let n = face.normal;
        for gap in [0.0, 1.0e-4, -1.0e-3] {
            let shift = n * gap;
            let tris = [
                Triangle {
                    a: v(0) + shift,
                    b: v(2) + shift,
                    c: v(1) + shift,
                },
                Triangle {
                    a: v(0) + shift,
                    b: v(1) + shift,
                    c: v(1) + shift + n * 0.5,
                },
                Triangle {
                    a: face.normal * face.offset + shift + rng.unit().cross(n) * 2.0,
                    b: face.normal * face.offset + shift + rng.unit().cross(n) * 2.0,
                    c: face.normal * face.offset + shift + rng.unit().cross(n) * 2.0,
                },
            ];
            for tri in &tris {
                if tri.normal().is_some() {
                    compare(tri, &hull, &Isometry::IDENTITY, 0.02);
                }
            }
        }
    }
}

#[test]
fn normal_range_lanes_matches_the_scalar_scan() {
    let mut rng = Rng(0xC0FF_EE00_1234_5678);
    let hull = taru();
    for k in 0..2000 {
        let far = [0.0, 1.0, 1.0e3][k % 3];
        let pose = Isometry::new(
            rng.unit() * far,
            Quat::from_axis_angle(rng.unit(), rng.range(0.0, 3.0)),
        );
        let pb = Polyhedron::from_hull(&hull);
        let posed = posed_hull(&pb, &pose);
        let scratch = EdgeScratch::new(&pb, &posed);
        // Random normals, the hull's own (placed) face normals (ties along a face) and
        // axis directions.
        let n = match k % 4 {
            0 => posed.normals[k % posed.normals.len()],
            1 => [Vec3::X, Vec3::Y, Vec3::Z][k % 3],
            _ => rng.unit(),
        };
        let (l0, h0) = normal_range(&posed.vertices, n);
        let (l1, h1) = normal_range_lanes(&scratch.verts, n);
        assert_eq!((l0.to_bits(), h0.to_bits()), (l1.to_bits(), h1.to_bits()));
    }
    // Every vertex count from 1 to 9 (padding of a partial block), a NaN vertex (skipped
    // alike) and a single vertex.
    for count in 1..10 {
        let pts: Vec<Vec3> = (0..count).map(|_| rng.unit() * 3.0).collect();
        let blocks: Vec<[W; 3]> = pts
            .chunks(4)
            .map(|c| {
                let l = [0, 1, 2, 3].map(|i| c.get(i).copied().unwrap_or(pts[0]));
                [l.map(|v| v.x), l.map(|v| v.y), l.map(|v| v.z)].map(W::new)
            })
            .collect();
        let n = rng.unit();
        let (l0, h0) = normal_range(&pts, n);
        let (l1, h1) = normal_range_lanes(&blocks, n);
        assert_eq!((l0.to_bits(), h0.to_bits()), (l1.to_bits(), h1.to_bits()));
        assert!(l0 <= h0);
        let mut with_nan = pts.clone();
        with_nan[count / 2] = Vec3::new(Real::NAN, 0.0, 0.0);
        let blocks: Vec<[W; 3]> = with_nan
            .chunks(4)
            .map(|c| {
                let l = [0, 1, 2, 3].map(|i| c.get(i).copied().unwrap_or(with_nan[0]));
                [l.map(|v| v.x), l.map(|v| v.y), l.map(|v| v.z)].map(W::new)
            })
            .collect();
        let (l0, h0) = normal_range(&with_nan, Vec3::X);
        let (l1, h1) = normal_range_lanes(&blocks, Vec3::X);
        assert_eq!((l0.to_bits(), h0.to_bits()), (l1.to_bits(), h1.to_bits()));
    }
}
