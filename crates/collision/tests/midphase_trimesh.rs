//! The triangle-mesh shape on top of the midphase: loading (OBJ, STL), validation, welding,
//! edge adjacency, batch rays and deformation (refit).

mod midphase_common;

use carom_collision::math::{Aabb, Real, Vec3};
use carom_collision::midphase::{brute_force, BvhLayout};
use carom_collision::shape::{EdgeKind, TriMesh, TriMeshOptions, NO_NEIGHBOR};
use carom_collision::CaromError;
use midphase_common::{grid_mesh, Rng};
use std::path::PathBuf;

fn landscape_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes/data/landscape.obj")
}

#[test]
fn landscape_obj_loads_all_groups() {
    let mesh = TriMesh::load(landscape_path()).unwrap();
    assert_eq!(mesh.vertices().len(), 17_160);
    assert_eq!(mesh.num_triangles(), 32_768);
    let b = mesh.local_aabb();
    assert!((b.min.x + 250.0).abs() < 1e-3 && (b.max.z - 250.0).abs() < 1e-3);
    assert!((b.min.y + 21.8071).abs() < 1e-3 && (b.max.y - 62.1111).abs() < 1e-3);
    // A vertical ray down onto the terrain hits it, and matches brute force.
    let mut rng = Rng(3);
    let mut hits = 0;
    for _ in 0..50 {
        let o = Vec3::new(rng.range(-240.0, 240.0), 100.0, rng.range(-240.0, 240.0));
        let d = Vec3::new(rng.range(-0.3, 0.3), -1.0, rng.range(-0.3, 0.3));
        let got = mesh.raycast(o, d, 1e6);
        let want = brute_force::ray_closest(&mesh.view(), o, d, 1e6);
        assert_eq!(got, want);
        hits += got.is_some() as usize;
    }
    assert!(hits > 40, "{hits}");
    // Edges: the terrain pieces are mostly interior edges, with some boundaries.
    let mut kinds = [0usize; 4];
    for e in mesh.edges().iter().flatten() {
        kinds[e.kind as usize] += 1;
        if e.neighbor != NO_NEIGHBOR {
            assert!(e.angle.is_finite());
        }
    }
    assert!(kinds[EdgeKind::Boundary as usize] > 0);
    assert!(kinds[EdgeKind::Convex as usize] > 1000 && kinds[EdgeKind::Concave as usize] > 1000);
}

fn stl_bytes(v: &[Vec3], t: &[[u32; 3]], ascii: bool) -> Vec<u8> {
    let tris: Vec<stl_io::Triangle> = t
        .iter()
        .map(|tri| stl_io::Triangle {
            normal: stl_io::Normal::new([0.0, 0.0, 0.0]),
            vertices: tri.map(|i| {
                let p = v[i as usize];
                stl_io::Vertex::new([p.x as _, p.y as _, p.z as _])
            }),
        })
        .collect();
    let mut out = Vec::new();
    stl_io::write_stl(&mut out, tris.iter()).unwrap();
    if ascii {
        let mut s = String::from("solid test\n");
        for tri in &tris {
            s += "facet normal 0 0 0\nouter loop\n";
            for p in &tri.vertices {
                s += &format!("vertex {:e} {:e} {:e}\n", p[0], p[1], p[2]);
            }
            s += "endloop\nendfacet\n";
        }
        s += "endsolid test\n";
        return s.into_bytes();
    }
    out
}

#[test]
fn stl_round_trip_shares_vertices() {
    let (v, t) = grid_mesh(6, 3.0, Vec3::new(1.0, 2.0, 3.0));
    for ascii in [false, true] {
        let bytes = stl_bytes(&v, &t, ascii);
        let mesh = TriMesh::from_stl_bytes(&bytes, TriMeshOptions::default()).unwrap();
        assert_eq!(mesh.num_triangles(), t.len());
        assert_eq!(
            mesh.vertices().len(),
            v.len(),
            "identical corners are shared"
        );
        for (k, tri) in t.iter().enumerate() {
            let want = tri.map(|i| v[i as usize]);
            let got = mesh.triangle(k);
            for c in 0..3 {
                assert!((got[c] - want[c]).length() < 1e-5);
            }
        }
        // Interior edges found through the shared vertices.
        let interior = mesh
            .edges()
            .iter()
            .flatten()
            .filter(|e| e.neighbor != NO_NEIGHBOR)
            .count();
        assert_eq!(interior, 2 * (3 * 6 * 6 - 2 * 6));
    }
}

#[test]
fn bad_files_give_parse_errors() {
    let cases: Vec<(&[u8], &str)> = vec![
        (b"v 0 0 0\nv 1 0 0\nv 0 1 0\n", "no triangles"),
        (b"v 0 0 0\nv 1 0 0\nf 1 2 9\n", ""),
        (b"v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n", "vertices[1]"),
        (b"v 0 0 zz\nf 1 1 1\n", ""),
    ];
    for (bytes, needle) in cases {
        match TriMesh::from_obj_bytes(bytes, TriMeshOptions::default()) {
            Err(CaromError::Parse { what, reason }) => {
                assert_eq!(what, "OBJ data");
                assert!(reason.contains(needle), "{reason}");
            }
            other => panic!("expected a parse error, got {other:?}"),
        }
    }
    for bytes in [
        &b"solid x\nfacet normal 0 0 0\nouter loop\nvertex 1 2\n"[..],
        &[7u8; 90][..],
    ] {
        assert!(matches!(
            TriMesh::from_stl_bytes(bytes, TriMeshOptions::default()),
            Err(CaromError::Parse { .. })
        ));
    }
    let e = TriMesh::load("/nonexistent/mesh.obj").unwrap_err();
    assert!(e.to_string().contains("/nonexistent/mesh.obj"));
    assert!(TriMesh::load("mesh.ply")
        .unwrap_err()
        .to_string()
        .contains(".obj"));
}

#[test]
fn bad_meshes_are_rejected_with_names() {
    let v = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
    let e = TriMesh::new(v.clone(), vec![[0, 1, 3]]).unwrap_err();
    assert!(e.to_string().contains("indices[0][2]"), "{e}");
    assert!(TriMesh::new(v.clone(), vec![]).is_err());
    assert!(TriMesh::new(vec![], vec![[0, 0, 0]]).is_err());
    let nan = vec![Vec3::ZERO, Vec3::new(0.0, Real::NAN, 0.0), Vec3::Y];
    assert!(TriMesh::new(nan, vec![[0, 1, 2]])
        .unwrap_err()
        .to_string()
        .contains("vertices[1]"));
    let opts = TriMeshOptions {
        weld_tolerance: Some(-1.0),
        ..Default::default()
    };
    assert!(TriMesh::with_options(v, vec![[0, 1, 2]], opts).is_err());
}

#[test]
fn welding_joins_a_split_grid() {
    // Every triangle with its own corners: no adjacency until welded.
    let (v, t) = grid_mesh(5, 2.0, Vec3::ZERO);
    let mut sv = Vec::new();
    let mut st = Vec::new();
    let mut rng = Rng(1);
    for tri in &t {
        let base = sv.len() as u32;
        sv.extend(tri.map(|i| v[i as usize] + rng.vec(-1e-6, 1e-6)));
        st.push([base, base + 1, base + 2]);
    }
    let split = TriMesh::new(sv.clone(), st.clone()).unwrap();
    assert!(split
        .edges()
        .iter()
        .flatten()
        .all(|e| e.neighbor == NO_NEIGHBOR));
    let opts = TriMeshOptions {
        weld_tolerance: Some(1e-4),
        ..Default::default()
    };
    let welded = TriMesh::with_options(sv, st, opts).unwrap();
    assert_eq!(welded.vertices().len(), v.len());
    let reference = TriMesh::new(v, t).unwrap();
    let n = |m: &TriMesh| {
        m.edges()
            .iter()
            .flatten()
            .filter(|e| e.neighbor != NO_NEIGHBOR)
            .count()
    };
    assert_eq!(n(&welded), n(&reference));
}

#[test]
fn batch_rays_equal_single_rays_and_layouts_agree() {
    let (v, t) = grid_mesh(30, 10.0, Vec3::ZERO);
    let q = TriMesh::new(v.clone(), t.clone()).unwrap();
    let opts = TriMeshOptions {
        layout: BvhLayout::Unquantized,
        ..Default::default()
    };
    let u = TriMesh::with_options(v, t, opts).unwrap();
    let mut rng = Rng(11);
    let origins: Vec<Vec3> = (0..500)
        .map(|_| rng.vec(-2.0, 12.0) + Vec3::Y * 5.0)
        .collect();
    let dirs: Vec<Vec3> = origins
        .iter()
        .map(|o| (Vec3::new(rng.range(-4.0, 14.0), 0.0, rng.range(-4.0, 14.0)) - *o).normalize())
        .collect();
    let batch = q.raycast_batch(&origins, &dirs, 100.0).unwrap();
    let hits = batch.iter().filter(|h| h.is_some()).count();
    let brute = (0..500)
        .filter(|&i| brute_force::ray_closest(&q.view(), origins[i], dirs[i], 100.0).is_some())
        .count();
    assert_eq!(hits, brute);
    assert!((100..400).contains(&hits), "{hits}");
    for i in 0..origins.len() {
        assert_eq!(batch[i], q.raycast(origins[i], dirs[i], 100.0));
        assert_eq!(batch[i], u.raycast(origins[i], dirs[i], 100.0));
    }
    assert!(q.raycast_batch(&origins, &dirs[1..], 1.0).is_err());
    let cps = q.closest_point_batch(&origins, 8.0);
    assert!(cps.iter().any(|c| c.is_none()) && cps.iter().any(|c| c.is_some()));
    for (p, c) in origins.iter().zip(&cps) {
        assert_eq!(*c, brute_force::closest_point(&q.view(), *p, 8.0));
    }
    let all = q.raycast_all(Vec3::new(5.1, 10.0, 5.2), -Vec3::Y, 100.0);
    assert_eq!(all.len(), 1);
    assert!(q
        .raycast_any(Vec3::new(5.1, 10.0, 5.2), -Vec3::Y, 100.0)
        .is_some());
}

#[test]
fn deforming_mesh_refits() {
    let (v, t) = grid_mesh(12, 6.0, Vec3::ZERO);
    let mut mesh = TriMesh::new(v.clone(), t.clone()).unwrap();
    let moved: Vec<Vec3> = v
        .iter()
        .map(|p| *p * 2.0 + Vec3::new(0.0, p.x.sin() * 4.0, 30.0))
        .collect();
    mesh.set_vertices(moved.clone()).unwrap();
    let fresh = TriMesh::new(moved, t).unwrap();
    assert_eq!(mesh.local_aabb(), fresh.local_aabb());
    let mut rng = Rng(2);
    for _ in 0..200 {
        let p = fresh.local_aabb().center() + rng.vec(-8.0, 8.0);
        assert_eq!(
            mesh.closest_point(p, Real::INFINITY),
            fresh.closest_point(p, Real::INFINITY)
        );
        let bx = Aabb::from_center_half_extents(p, Vec3::splat(rng.range(0.0, 2.0)));
        assert_eq!(
            mesh.overlapping_triangles(&bx),
            fresh.overlapping_triangles(&bx)
        );
        let d = rng.unit();
        assert_eq!(mesh.raycast(p, d, 50.0), fresh.raycast(p, d, 50.0));
    }
    assert!(mesh.set_vertices(vec![Vec3::ZERO]).is_err());
}

#[test]
fn meshes_round_trip_through_serde() {
    let (v, t) = grid_mesh(6, 3.0, Vec3::ZERO);
    let mesh = TriMesh::new(v, t).unwrap();
    let bytes = postcard::to_allocvec(&mesh).unwrap();
    let back: TriMesh = postcard::from_bytes(&bytes).unwrap();
    assert_eq!(back, mesh);
    let o = Vec3::new(1.1, 5.0, 1.3);
    assert_eq!(
        back.raycast(o, -Vec3::Y, 10.0),
        mesh.raycast(o, -Vec3::Y, 10.0)
    );
}

#[test]
fn batch_rays_equal_serial_rays_on_any_thread_count() {
    // The batch path splits the rays over rayon's workers (no shared mutable state): the
    // results are those of the serial loop, bit for bit, whatever the thread count.
    let (v, t) = grid_mesh(40, 20.0, Vec3::new(-10.0, 0.0, -10.0));
    let mesh = TriMesh::new(v, t).unwrap();
    let mut rng = Rng(9);
    let origins: Vec<Vec3> = (0..3000)
        .map(|_| rng.vec(-12.0, 12.0) + Vec3::Y * 15.0)
        .collect();
    let dirs: Vec<Vec3> = (0..3000).map(|_| rng.vec(-0.5, 0.5) - Vec3::Y).collect();
    let serial: Vec<_> = origins
        .iter()
        .zip(&dirs)
        .map(|(&o, &d)| mesh.raycast(o, d, 100.0))
        .collect();
    let hits = serial.iter().filter(|h| h.is_some()).count();
    assert!((900..2900).contains(&hits), "{hits} hits");
    for threads in [1, 2, 3, 8] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let batch = pool.install(|| mesh.raycast_batch(&origins, &dirs, 100.0).unwrap());
        assert_eq!(batch, serial, "{threads} threads");
    }
}

#[test]
fn closed_mesh_mass_properties_match_the_analytic_box() {
    // A box with half extents h as a closed, outward-oriented mesh, near and far from the
    // origin: mass 8·hx·hy·hz·ρ, centre at the offset, inertia m/3·(hy² + hz², …).
    let h = Vec3::new(1.0, 0.5, 2.0);
    let density = 3.0;
    for offset in [Vec3::new(0.5, -1.0, 2.0), Vec3::new(1.0e3, -2.0e3, 5.0e2)] {
        let v: Vec<Vec3> = (0..8)
            .map(|i| {
                let s = |bit: u32| if i & bit != 0 { 1.0 } else { -1.0 };
                offset + Vec3::new(s(4), s(2), s(1)) * h
            })
            .collect();
        let t = vec![
            [0, 1, 3],
            [0, 3, 2],
            [4, 6, 7],
            [4, 7, 5],
            [0, 4, 5],
            [0, 5, 1],
            [2, 3, 7],
            [2, 7, 6],
            [0, 2, 6],
            [0, 6, 4],
            [1, 5, 7],
            [1, 7, 3],
        ];
        let mesh = TriMesh::new(v, t).unwrap();
        let mp = mesh.mass_properties(density);
        let mass = 8.0 * h.x * h.y * h.z * density;
        let rel = if offset.length() > 100.0 { 2e-3 } else { 1e-5 };
        assert!(
            (mp.mass - mass).abs() <= mass * rel,
            "{} vs {mass}",
            mp.mass
        );
        assert!((mp.center_of_mass - offset).length() <= offset.length() * rel + 1e-5);
        let want = Vec3::new(
            h.y * h.y + h.z * h.z,
            h.x * h.x + h.z * h.z,
            h.x * h.x + h.y * h.y,
        ) * (mass / 3.0);
        let got = Vec3::new(
            mp.inertia.x_axis.x,
            mp.inertia.y_axis.y,
            mp.inertia.z_axis.z,
        );
        let tol = if offset.length() > 100.0 { 0.05 } else { 1e-4 };
        assert!(
            (got - want).abs().max_element() <= want.max_element() * tol,
            "{got} vs {want}"
        );
        assert!((mesh.volume() - mass / density).abs() <= mass / density * rel);
    }
}
