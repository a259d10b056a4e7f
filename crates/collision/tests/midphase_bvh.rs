//! BVH traversals against brute force over all triangles, on both node layouts, on a grid
//! (shared edges and vertices), a soup with degenerate triangles and meshes far from the
//! origin; and refit against a fresh build.

mod midphase_common;

use carom_collision::math::{Aabb, Isometry, Quat, Real, Vec3};
use carom_collision::midphase::{
    brute_force, triangle_aabbs, Bvh, BvhLayout, MeshView, WideNode, WideRealNode,
};
use midphase_common::{grid_mesh, soup_mesh, Rng};

struct Mesh {
    v: Vec<Vec3>,
    t: Vec<[u32; 3]>,
    q: Bvh,
    u: Bvh,
}

impl Mesh {
    fn new((v, t): (Vec<Vec3>, Vec<[u32; 3]>)) -> Self {
        let boxes = triangle_aabbs(&v, &t);
        let q = Bvh::new(&boxes, BvhLayout::Quantized).unwrap();
        let u = Bvh::new(&boxes, BvhLayout::Unquantized).unwrap();
        Mesh { v, t, q, u }
    }
    fn views(&self) -> [MeshView<'_>; 2] {
        [
            MeshView {
                bvh: &self.q,
                vertices: &self.v,
                indices: &self.t,
            },
            MeshView {
                bvh: &self.u,
                vertices: &self.v,
                indices: &self.t,
            },
        ]
    }
    fn bounds(&self) -> Aabb {
        Aabb::from_points(self.v.iter().copied())
    }
}

fn key(h: &carom_collision::midphase::MeshRayHit) -> (u32, String) {
    (h.triangle, format!("{:e}", h.t))
}

/// Random rays from around the mesh toward points of its (inflated) box; checks closest, any
/// and all hits against brute force; returns the hit rate.
fn check_rays(mesh: &Mesh, rng: &mut Rng, n: usize, inflate: Real) -> f64 {
    let b = mesh.bounds();
    let c = b.center();
    let r = b.extents().length();
    let mut hits = 0;
    for _ in 0..n {
        let origin = c + rng.unit() * r * rng.range(0.6, 1.5);
        let target = b.min - b.extents() * inflate
            + b.extents() * (1.0 + 2.0 * inflate) * Vec3::new(rng.f(), rng.f(), rng.f());
        let dir = (target - origin) * rng.range(0.5, 2.0);
        let max_t = if rng.f() < 0.2 {
            rng.range(0.3, 1.2)
        } else {
            1e30
        };
        let views = mesh.views();
        let want = brute_force::ray_closest(&views[0], origin, dir, max_t);
        let want_all = brute_force::ray_all(&views[0], origin, dir, max_t);
        hits += want.is_some() as usize;
        for view in &views {
            let got = view.ray_closest(origin, dir, max_t);
            assert_eq!(
                got.map(|h| key(&h)),
                want.map(|h| key(&h)),
                "closest {origin} {dir}"
            );
            let stackless = view.ray_closest_stackless(origin, dir, max_t);
            assert_eq!(stackless.map(|h| key(&h)), got.map(|h| key(&h)));
            let any = view.ray_any(origin, dir, max_t);
            assert_eq!(any.is_some(), want.is_some());
            if let Some(h) = any {
                assert!(want_all.iter().any(|w| key(w) == key(&h)));
            }
            let mut all = Vec::new();
            view.ray_all(origin, dir, max_t, &mut all);
            assert_eq!(all, want_all);
        }
        if let Some(h) = want {
            assert!(h.point.is_finite() && h.normal.is_finite());
            assert!((h.normal.length() - 1.0).abs() < 1e-3);
        }
    }
    hits as f64 / n as f64
}

#[test]
fn rays_match_brute_force_on_grid_soup_and_far_meshes() {
    let mut rng = Rng(1);
    let grid = Mesh::new(grid_mesh(24, 10.0, Vec3::ZERO));
    let rate = check_rays(&grid, &mut rng, 600, 0.15);
    assert!((0.3..0.8).contains(&rate), "grid hit rate {rate}");
    let soup = Mesh::new(soup_mesh(&mut rng, 1000, -5.0, 5.0));
    let rate = check_rays(&soup, &mut rng, 600, 0.0);
    assert!((0.3..0.9).contains(&rate), "soup hit rate {rate}");
    let far = Mesh::new(grid_mesh(12, 4.0, Vec3::new(3.0e3, -2.0e3, 1.0e3)));
    let rate = check_rays(&far, &mut rng, 300, 0.15);
    assert!((0.3..0.8).contains(&rate), "far hit rate {rate}");
}

#[test]
fn rays_through_shared_vertices_and_edges_never_slip() {
    // A closed-off grid seen from above: every ray aimed at a vertex or an edge midpoint of the
    // interior hits (watertight), in both layouts and by brute force.
    let mesh = Mesh::new(grid_mesh(8, 8.0, Vec3::new(0.25, 0.0, -0.5)));
    let mut rng = Rng(5);
    let mut aimed = 0;
    for (k, tri) in mesh.t.iter().enumerate() {
        for e in 0..3 {
            let (a, b) = (mesh.v[tri[e] as usize], mesh.v[tri[(e + 1) % 3] as usize]);
            for target in [a, (a + b) * 0.5, a + (b - a) * 0.25] {
                let interior = mesh.bounds().expanded(-0.01).contains_point(Vec3::new(
                    target.x,
                    mesh.bounds().center().y,
                    target.z,
                ));
                if !interior {
                    continue;
                }
                let origin = target + Vec3::new(rng.range(-2.0, 2.0), 5.0, rng.range(-2.0, 2.0));
                let dir = target - origin;
                for view in mesh.views() {
                    let h = view.ray_closest(origin, dir, 2.0);
                    assert!(h.is_some(), "ray at triangle {k} edge {e} slipped through");
                }
                assert!(brute_force::ray_closest(&mesh.views()[0], origin, dir, 2.0).is_some());
                aimed += 1;
            }
        }
    }
    assert!(aimed > 300);
    // Rays lying in the plane of a flat face: same answer as brute force (no NaN, no panic).
    let flat = Mesh::new(grid_mesh(4, 4.0, Vec3::ZERO));
    for view in flat.views() {
        let (o, d) = (Vec3::new(-1.0, 0.0, 0.0), Vec3::X);
        let got = view.ray_closest(o, d, 10.0).map(|h| key(&h));
        assert_eq!(
            got,
            brute_force::ray_closest(&view, o, d, 10.0).map(|h| key(&h))
        );
    }
}

#[test]
fn aabb_overlap_matches_brute_force() {
    let mut rng = Rng(2);
    for mesh in [
        Mesh::new(grid_mesh(20, 10.0, Vec3::ZERO)),
        Mesh::new(soup_mesh(&mut Rng(3), 300, -4.0, 4.0)),
        Mesh::new(grid_mesh(10, 2.0, Vec3::splat(-5.0e3))),
    ] {
        let b = mesh.bounds();
        let mut nonempty = 0;
        for _ in 0..300 {
            let c = b.min + b.extents() * Vec3::new(rng.f(), rng.f(), rng.f());
            let h = b.extents() * rng.range(0.0, 0.15);
            // Some flat and point boxes.
            let h = if rng.f() < 0.2 {
                h * Vec3::new(1.0, 0.0, 1.0)
            } else {
                h
            };
            let q = Aabb::from_center_half_extents(c, h);
            let want = brute_force::triangles_in_aabb(&mesh.views()[0], &q);
            nonempty += !want.is_empty() as usize;
            for view in mesh.views() {
                let mut got = Vec::new();
                view.triangles_in_aabb(&q, &mut got);
                assert_eq!(got, want);
            }
        }
        assert!((30..290).contains(&nonempty), "nonempty {nonempty}");
    }
}

#[test]
fn closest_point_matches_brute_force() {
    let mut rng = Rng(4);
    for mesh in [
        Mesh::new(grid_mesh(16, 10.0, Vec3::ZERO)),
        Mesh::new(soup_mesh(&mut Rng(6), 300, -4.0, 4.0)),
        Mesh::new(grid_mesh(8, 3.0, Vec3::new(-2.0e3, 1.0e3, 0.0))),
    ] {
        let b = mesh.bounds();
        let scale = b.extents().max_element();
        let mut found = 0;
        for _ in 0..300 {
            let p = b.center() + rng.vec(-1.0, 1.0) * scale;
            let max_d = if rng.f() < 0.5 {
                rng.range(0.0, 0.5) * scale
            } else {
                Real::INFINITY
            };
            let want = brute_force::closest_point(&mesh.views()[0], p, max_d);
            found += want.is_some() as usize;
            for view in mesh.views() {
                let got = view.closest_point(p, max_d);
                assert_eq!(got, want, "closest point of {p}");
            }
            if let Some(w) = want {
                assert!(w.point.is_finite() && w.distance.is_finite());
            }
        }
        assert!((150..300).contains(&found), "found {found}");
    }
}

#[test]
fn refit_matches_fresh_build() {
    let mut rng = Rng(8);
    let mut mesh = Mesh::new(grid_mesh(16, 10.0, Vec3::ZERO));
    // Deform and move far outside the old quantisation bounds.
    for v in &mut mesh.v {
        *v = Vec3::new(v.x * 1.5, v.y + (v.x * 0.9).cos() * 3.0, v.z) + Vec3::new(20.0, -7.0, 3.0);
    }
    let boxes = triangle_aabbs(&mesh.v, &mesh.t);
    mesh.q.refit(&boxes).unwrap();
    mesh.u.refit(&boxes).unwrap();
    let fresh = Mesh::new((mesh.v.clone(), mesh.t.clone()));
    assert_eq!(mesh.q.root_aabb(), fresh.q.root_aabb());
    let rate = check_rays(&mesh, &mut rng, 300, 0.3);
    assert!(rate > 0.3);
    let b = mesh.bounds();
    for _ in 0..100 {
        let p = b.center() + rng.vec(-1.0, 1.0) * b.extents();
        let q = Aabb::from_center_half_extents(p, b.extents() * 0.1);
        let want = brute_force::triangles_in_aabb(&fresh.views()[0], &q);
        let want_cp = fresh.views()[0].closest_point(p, 1e30);
        for view in mesh.views() {
            let mut got = Vec::new();
            view.triangles_in_aabb(&q, &mut got);
            assert_eq!(got, want);
            assert_eq!(view.closest_point(p, 1e30), want_cp);
        }
    }
}

#[test]
fn mesh_pairs_match_brute_force() {
    let a = Mesh::new(grid_mesh(10, 6.0, Vec3::ZERO));
    let (mut v, t) = soup_mesh(&mut Rng(9), 150, 0.0, 6.0);
    v.iter_mut().for_each(|p| p.y *= 0.1);
    let b = Mesh::new((v, t));
    let pose = Isometry::new(Vec3::new(0.5, -0.5, 0.2), Quat::from_rotation_z(0.3));
    let want = brute_force::triangle_pairs(&a.views()[0], &b.views()[0], &pose);
    assert!(want.len() > 20, "pairs {}", want.len());
    for va in a.views() {
        for vb in b.views() {
            let mut got = Vec::new();
            va.triangle_pairs(&vb, &pose, &mut got);
            assert_eq!(got, want);
        }
    }
}

#[test]
fn quantized_nodes_are_small() {
    let mesh = Mesh::new(grid_mesh(64, 10.0, Vec3::ZERO));
    let per_tri = mesh.q.memory_bytes() as f64 / mesh.t.len() as f64;
    assert!(per_tri <= 32.0, "{per_tri} bytes per triangle");
    // The binary quantised nodes are smaller than the unquantised ones; the 4-wide nodes
    // kept beside them for closest-hit rays are an extra 64 bytes each (128 unquantised).
    let wide = mesh.q.num_wide_nodes() * std::mem::size_of::<WideNode>();
    let wide_u = mesh.u.num_wide_nodes() * std::mem::size_of::<WideRealNode>();
    assert!(wide > 0 && wide_u > 0);
    assert_eq!(std::mem::size_of::<WideNode>(), 64);
    assert!(mesh.q.memory_bytes() - wide < mesh.u.memory_bytes() - wide_u);
}

#[test]
fn rays_along_edges_and_faces_match_brute_force() {
    // Rays running along a triangle's edge line (in the plane of the two faces sharing it)
    // and along the face plane through its centroid, on a wavy grid and a soup with
    // degenerate triangles: every layout and walk equals brute force, nothing is NaN.
    let mut rng = Rng(61);
    for mesh in [
        Mesh::new(grid_mesh(10, 10.0, Vec3::new(3.0, -1.0, 2.0))),
        Mesh::new(soup_mesh(&mut rng, 200, -4.0, 4.0)),
    ] {
        for (k, tri) in mesh.t.iter().enumerate().step_by(3) {
            let [a, b, c] = tri.map(|i| mesh.v[i as usize]);
            let centroid = (a + b + c) / 3.0;
            for (origin, dir) in [
                (a - (b - a) * 2.0, b - a),
                (centroid - (c - b) * 3.0, c - b),
            ] {
                let want = brute_force::ray_closest(&mesh.views()[0], origin, dir, 1e30);
                for view in mesh.views() {
                    for got in [
                        view.ray_closest(origin, dir, 1e30),
                        view.ray_closest_stackless(origin, dir, 1e30),
                    ] {
                        assert_eq!(got.map(|h| key(&h)), want.map(|h| key(&h)), "tri {k}");
                        if let Some(h) = got {
                            assert!(h.point.is_finite() && h.normal.is_finite());
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn wide_walk_on_tiny_stacked_and_identical_meshes() {
    // The closest-hit walk runs on 4-wide nodes (both layouts): check it against brute
    // force where the collapse is unusual: one leaf (no wide node), a few triangles, a deep
    // stack of parallel triangles (many deferred children, ties only across layers) and
    // hundreds of identical triangles (every hit ties; the smallest index must win).
    let tri = [
        Vec3::ZERO,
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 1.0),
    ];
    let mut cases: Vec<(Vec<Vec3>, Vec<[u32; 3]>)> = Vec::new();
    for n in [1usize, 2, 3, 5, 9] {
        let mut v = Vec::new();
        let mut t = Vec::new();
        for i in 0..n {
            let off = Vec3::new(i as Real * 0.7, (i % 3) as Real * 0.1, 0.0);
            let b = v.len() as u32;
            v.extend(tri.map(|p| p + off));
            t.push([b, b + 1, b + 2]);
        }
        cases.push((v, t));
    }
    let layers: Vec<Vec3> = (0..1500)
        .flat_map(|i| tri.map(|p| p * 4.0 + Vec3::new(0.0, i as Real * 0.01, 0.0)))
        .collect();
    cases.push((
        layers,
        (0..1500u32)
            .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
            .collect(),
    ));
    cases.push((tri.to_vec(), vec![[0, 1, 2]; 700]));
    let mut rng = Rng(77);
    for (v, t) in cases {
        let mesh = Mesh::new((v, t));
        let b = mesh.bounds();
        let mut hits = 0;
        for k in 0..200 {
            let target = b.min + b.extents() * Vec3::new(rng.f(), rng.f(), rng.f());
            let origin = if k % 2 == 0 {
                target + Vec3::new(0.0, 50.0, 0.0)
            } else {
                b.center() + rng.unit() * (b.extents().length() + 1.0)
            };
            let dir = target - origin;
            let want = brute_force::ray_closest(&mesh.views()[0], origin, dir, 1e30);
            hits += want.is_some() as usize;
            for view in mesh.views() {
                let got = view.ray_closest(origin, dir, 1e30);
                assert_eq!(
                    got.map(|h| key(&h)),
                    want.map(|h| key(&h)),
                    "{} tris",
                    mesh.t.len()
                );
            }
        }
        assert!(hits > 20, "{hits} hits on {} triangles", mesh.t.len());
    }
}
