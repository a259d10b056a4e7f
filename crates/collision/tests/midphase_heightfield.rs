//! Heightfield traversals (cell range for boxes, 2D DDA for rays) against brute force over
//! all triangles.

mod midphase_common;

use carom_collision::math::{Aabb, Isometry, Real, Vec3};
use carom_collision::midphase::ray_triangle;
use carom_collision::shape::{HeightField, Shape};
use midphase_common::Rng;

fn field(rows: usize, cols: usize, offset: Real) -> HeightField {
    let mut h = Vec::new();
    for r in 0..rows {
        for c in 0..cols {
            let (x, z) = (c as Real, r as Real);
            h.push(
                (x * 0.6).sin() * (z * 0.4).cos() * 2.0
                    + offset
                    + if (r + c) % 7 == 0 { 1.0 } else { 0.0 },
            );
        }
    }
    HeightField::new(rows, cols, h, 0.75, 1.25).unwrap()
}

/// Closest hit over all triangles, ties to the smaller index.
fn brute_ray(h: &HeightField, o: Vec3, d: Vec3, max_t: Real) -> Option<(u32, Real)> {
    let mut best: Option<(u32, Real)> = None;
    for i in 0..h.num_triangles() {
        if let Some(hit) = ray_triangle(o, d, max_t, &h.triangle(i)) {
            if best.is_none_or(|(_, t)| hit.t < t) {
                best = Some((i as u32, hit.t));
            }
        }
    }
    best
}

#[test]
fn rays_match_brute_force() {
    let mut rng = Rng(21);
    for h in [field(17, 23, 0.0), field(9, 5, 500.0)] {
        let b = h.local_aabb();
        let mut hits = 0;
        let n = 600;
        for k in 0..n {
            let target = b.min
                + b.extents() * Vec3::new(rng.range(-0.2, 1.2), rng.f(), rng.range(-0.2, 1.2));
            let origin = match k % 4 {
                // Steep, shallow, vertical and aimed at a sample point.
                0 => target + Vec3::new(rng.range(-3.0, 3.0), 10.0, rng.range(-3.0, 3.0)),
                1 => {
                    target
                        + Vec3::new(
                            rng.range(-20.0, 20.0),
                            rng.range(0.5, 3.0),
                            rng.range(-20.0, 20.0),
                        )
                }
                2 => target + Vec3::new(0.0, 8.0, 0.0),
                _ => {
                    // Interior samples: a ray through a boundary vertex may rightly miss.
                    let r = 1 + rng.next_u32() as usize % (h.rows() - 2);
                    let c = 1 + rng.next_u32() as usize % (h.cols() - 2);
                    let p = h.point(r, c);
                    let o = p + Vec3::new(rng.range(-2.0, 2.0), 6.0, rng.range(-2.0, 2.0));
                    let got = h.raycast(o, (p - o) * 1.01, 1.0);
                    assert!(got.is_some(), "ray through sample ({r}, {c}) slipped");
                    o
                }
            };
            let dir = (target - origin) * rng.range(0.5, 1.5);
            let want = brute_ray(&h, origin, dir, 10.0);
            let got = h.raycast(origin, dir, 10.0);
            assert_eq!(got.map(|g| (g.triangle, g.t)), want, "ray {origin} {dir}");
            if let Some(g) = got {
                assert!(g.normal.y > 0.0 && g.point.is_finite());
            }
            hits += want.is_some() as usize;
        }
        let rate = hits as f64 / n as f64;
        assert!((0.3..0.9).contains(&rate), "hit rate {rate}");
    }
    let h = field(4, 4, 0.0);
    assert!(h.raycast(Vec3::ZERO, Vec3::ZERO, 1.0).is_none());
    assert!(h
        .raycast(Vec3::new(0.0, 10.0, 0.0), -Vec3::Y, Real::NAN)
        .is_none());
}

#[test]
fn boxes_match_brute_force() {
    let mut rng = Rng(22);
    let h = field(13, 11, 0.0);
    let b = h.local_aabb();
    let mut nonempty = 0;
    for _ in 0..400 {
        let c = b.min
            + b.extents()
                * Vec3::new(
                    rng.range(-0.2, 1.2),
                    rng.range(-0.5, 1.5),
                    rng.range(-0.2, 1.2),
                );
        let q = Aabb::from_center_half_extents(c, rng.vec(0.0, 1.5));
        let want: Vec<u32> = (0..h.num_triangles() as u32)
            .filter(|&i| Aabb::from_points(h.triangle(i as usize)).intersects(&q))
            .collect();
        assert_eq!(h.triangles_in_aabb(&q), want);
        nonempty += !want.is_empty() as usize;
    }
    assert!((80..380).contains(&nonempty), "{nonempty}");
}

#[test]
fn heightfield_is_a_shape() {
    let h = field(5, 6, 1.0);
    let local = h.local_aabb();
    let s = Shape::from(h);
    assert_eq!(s.kind_name(), "heightfield");
    assert!(s.as_convex().is_none());
    assert_eq!(s.mass_properties(3.0).mass, 0.0);
    let pose = Isometry::from_translation(Vec3::new(1.0, 2.0, 3.0));
    let w = s.aabb(&pose);
    assert!((w.min - (local.min + pose.translation)).length() < 1e-5);
}
