//! `query::raycast` and `query::project_point` on meshes and heightfields run the midphase
//! traversals (BVH, grid) through `TriangleSource`; checked here against the brute-force
//! twins over every triangle, on rays and points in general position, through vertices and
//! along faces, with degenerate triangles and far from the origin.

mod midphase_common;

use carom_collision::math::{Isometry, Quat, Real, Vec3};
use carom_collision::midphase::TriangleSource;
use carom_collision::query::{project_point_local, raycast, raycast_local, Ray};
use carom_collision::shape::{HeightField, Shape, TriMesh};
use midphase_common::{grid_mesh, soup_mesh, Rng};

fn field(offset: Real) -> HeightField {
    let (rows, cols) = (17, 23);
    let h = (0..rows * cols)
        .map(|k| ((k % cols) as Real * 0.6).sin() * ((k / cols) as Real * 0.4).cos() + offset)
        .collect();
    HeightField::new(rows, cols, h, 0.75, 1.25).unwrap()
}

fn shapes(rng: &mut Rng, far: Vec3) -> Vec<Shape> {
    let (v, i) = grid_mesh(12, 10.0, far);
    let (sv, si) = soup_mesh(rng, 300, -5.0, 5.0);
    let soup: Vec<Vec3> = sv.into_iter().map(|p| p + far).collect();
    vec![
        TriMesh::new(v, i).unwrap().into(),
        TriMesh::new(soup, si).unwrap().into(),
        field(far.y).into(),
    ]
}

fn check(rng: &mut Rng, far: Vec3) {
    let tol = 1e-4 * (1.0 + far.length());
    let pose = Isometry::new(Vec3::new(0.5, -1.0, 2.0), Quat::from_rotation_y(0.3));
    for shape in shapes(rng, far) {
        let src = TriangleSource::of(&shape).unwrap();
        let b = shape.aabb(&Isometry::IDENTITY);
        let (mut hits, mut rays, mut worlds, mut world_rays) = (0, 0, 0, 0);
        for k in 0..300 {
            let target = if k % 3 == 0 {
                // Through a vertex of some triangle (grazing a shared vertex or edge).
                let t = src.triangle(rng.next_u32() % src.num_triangles() as u32);
                if k % 2 == 0 {
                    t[0]
                } else {
                    (t[0] + t[1]) * 0.5
                }
            } else {
                b.min + b.extents() * Vec3::new(rng.f(), rng.f(), rng.f())
            };
            let origin = target + rng.unit() * rng.range(1.0, 20.0);
            // The direction exactly as `raycast` normalises it, so both sides see one ray.
            let dir = Ray::new(origin, target - origin).unwrap().dir;
            let max_t = if k % 5 == 0 { 3.0 } else { Real::INFINITY };
            // Local frame: the shape at the identity; world: the same ray moved by `pose`.
            let got = raycast_local(&shape, &Ray { origin, dir }, max_t, true);
            let want = src.brute_force_ray_closest(origin, dir, max_t);
            let direct = src.ray_closest(origin, dir, max_t);
            assert_eq!(direct.map(|h| h.t), got.map(|h| h.distance));
            rays += 1;
            match (got, want) {
                (None, None) => {}
                (Some(g), Some(w)) => {
                    hits += 1;
                    assert!((g.distance - w.t).abs() <= tol, "{} vs {}", g.distance, w.t);
                    assert!(!g.inside && g.normal.dot(dir) <= 0.0);
                    assert!(g.normal.is_finite() && g.point.is_finite());
                    if g.distance != w.t {
                        // Ties between triangles at the same distance may pick either.
                        assert!((g.distance - w.t).abs() <= tol);
                    } else {
                        assert_eq!(
                            g.feature,
                            Some(w.triangle),
                            "{:?} {origin:?} {dir:?} {max_t}",
                            src.num_triangles()
                        );
                    }
                }
                (g, w) => panic!("bvh {g:?} vs brute force {w:?}"),
            }
            // The world-frame entry point moves the ray (rounding), then agrees closely.
            if let Some(g) = got.filter(|_| k % 3 != 0) {
                let world = raycast(
                    &shape,
                    &pose,
                    pose.transform_point(origin),
                    pose.transform_vector(dir),
                    max_t,
                    true,
                )
                .unwrap();
                worlds += world.is_some_and(|w| (w.distance - g.distance).abs() <= tol) as usize;
                world_rays += 1;
            }

            let p = target + rng.unit() * rng.range(0.0, 4.0);
            let got = project_point_local(&shape, p);
            let want = src.brute_force_closest_point(p, Real::INFINITY).unwrap();
            assert!(!got.inside);
            assert!(
                (got.distance - want.distance).abs() <= tol,
                "{} vs {}",
                got.distance,
                want.distance
            );
            assert!((got.point - p).length() <= want.distance + tol);
        }
        assert!(hits * 5 > rays, "{hits} of {rays}");
        assert!(worlds * 10 >= world_rays * 9, "{worlds} of {world_rays}");
    }
}

#[test]
fn mesh_and_heightfield_queries_match_brute_force() {
    check(&mut Rng(51), Vec3::ZERO);
}

#[test]
fn far_from_origin_queries_match_brute_force() {
    check(&mut Rng(52), Vec3::new(1.0e4, -2.0e3, 5.0e3));
}
