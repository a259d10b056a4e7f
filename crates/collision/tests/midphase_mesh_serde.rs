//! Mesh robustness: the edge table against a brute-force scan of all triangle pairs, and
//! deserialisation of meshes (and other cached-data shapes) checked against their own data.

mod midphase_common;

use carom_collision::bvh::Bvh;
use carom_collision::math::{Aabb, Real, Vec3};
use carom_collision::midphase::{brute_force, BvhLayout};
use carom_collision::shape::serde_check::take_load_error;
use carom_collision::shape::{
    compute_edges, weld_vertices, ConvexHull, EdgeKind, HeightField, MeshEdge, Scaled, Shape,
    Sphere, TriMesh, TriMeshOptions, DEFAULT_FLAT_ANGLE, NO_NEIGHBOR,
};
use midphase_common::{grid_mesh, Rng};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// Brute-force edge table: for each edge slot, every other slot with the same unordered
/// vertex pair is found by scanning all triangles; the angle is computed from its definition.
fn brute_edges(
    v: &[Vec3],
    idx: &[[u32; 3]],
    flat: Real,
) -> Vec<[Option<(u32, Real, EdgeKind)>; 3]> {
    let normal = |t: usize| {
        let [a, b, c] = idx[t].map(|i| v[i as usize]);
        (b - a).cross(c - a).try_normalize()
    };
    let mut out = vec![[None; 3]; idx.len()];
    for t in 0..idx.len() {
        for k in 0..3 {
            let (a, b) = (idx[t][k], idx[t][(k + 1) % 3]);
            if a == b {
                continue;
            }
            let mut others = Vec::new();
            for (t2, tri2) in idx.iter().enumerate() {
                for k2 in 0..3 {
                    let (c, d) = (tri2[k2], tri2[(k2 + 1) % 3]);
                    if (t2, k2) != (t, k) && c != d && (c.min(d), c.max(d)) == (a.min(b), a.max(b))
                    {
                        others.push((t2, k2));
                    }
                }
            }
            if others.len() != 1 || others[0].0 == t {
                continue;
            }
            let (t2, k2) = others[0];
            let entry = match (normal(t), normal(t2)) {
                (Some(n), Some(m)) => {
                    let m = if idx[t2][k2] == a { -m } else { m };
                    let far = idx[t2]
                        .iter()
                        .map(|&i| v[i as usize])
                        .max_by(|p, q| {
                            let e = v[b as usize] - v[a as usize];
                            let dp = (*p - v[a as usize]).cross(e).length_squared();
                            let dq = (*q - v[a as usize]).cross(e).length_squared();
                            dp.total_cmp(&dq)
                        })
                        .unwrap();
                    let unsigned = n.cross(m).length().atan2(n.dot(m));
                    let below = (far - v[a as usize]).dot(n) <= 0.0;
                    let kind = if unsigned <= flat {
                        EdgeKind::Flat
                    } else if below {
                        EdgeKind::Convex
                    } else {
                        EdgeKind::Concave
                    };
                    (t2 as u32, if below { unsigned } else { -unsigned }, kind)
                }
                _ => (t2 as u32, 0.0, EdgeKind::Boundary),
            };
            out[t][k] = Some(entry);
        }
    }
    out
}

fn check_against_brute(v: &[Vec3], idx: &[[u32; 3]]) {
    let got = compute_edges(v, idx, DEFAULT_FLAT_ANGLE);
    let want = brute_edges(v, idx, DEFAULT_FLAT_ANGLE);
    assert_eq!(got.len(), idx.len());
    for t in 0..idx.len() {
        for k in 0..3 {
            let g: MeshEdge = got[t][k];
            match want[t][k] {
                None => {
                    assert_eq!(g.neighbor, NO_NEIGHBOR, "tri {t} edge {k}");
                    assert_eq!(g.kind, EdgeKind::Boundary);
                }
                Some((n, angle, kind)) => {
                    assert_eq!(g.neighbor, n, "tri {t} edge {k}");
                    assert_eq!(g.kind, kind, "tri {t} edge {k}");
                    assert_eq!(g.angle.to_bits(), angle.to_bits(), "tri {t} edge {k}");
                }
            }
        }
    }
}

#[test]
fn edges_match_brute_force_on_random_meshes() {
    let mut rng = Rng(11);
    for case in 0..300 {
        // A small vertex pool (so edges are shared by 1, 2 or more triangles), with
        // coincident copies (welded below) and repeated indices (degenerate triangles).
        let nv = 4 + (rng.next_u32() % 9) as usize;
        let far = if case % 3 == 0 {
            Vec3::splat(1.0e4)
        } else {
            Vec3::ZERO
        };
        let mut v: Vec<Vec3> = (0..nv).map(|_| far + rng.vec(-1.0, 1.0)).collect();
        if case % 4 == 0 {
            v.push(v[0]);
            v.push(v[1]);
        }
        if case % 5 == 0 {
            // Coplanar pool: flat edges.
            for p in &mut v {
                p.y = far.y;
            }
        }
        let nt = 1 + (rng.next_u32() % 30) as usize;
        let idx: Vec<[u32; 3]> = (0..nt)
            .map(|_| {
                let mut t = [0u32; 3];
                for c in &mut t {
                    *c = rng.next_u32() % v.len() as u32;
                }
                t
            })
            .collect();
        check_against_brute(&v, &idx);
        let (wv, wi) = weld_vertices(&v, &idx, 0.0).unwrap();
        check_against_brute(&wv, &wi);
    }
    // A manifold grid with random heights and a closed cube.
    let (mut v, idx) = grid_mesh(12, 10.0, Vec3::ZERO);
    for p in &mut v {
        p.y += rng.range(-1.0, 1.0);
    }
    check_against_brute(&v, &idx);
}

/// Mirror of the serialised layout of a `TriMesh` (postcard is positional), to craft
/// inconsistent data.
#[derive(Serialize, Deserialize, Clone)]
struct RawMesh {
    vertices: Vec<Vec3>,
    indices: Vec<[u32; 3]>,
    local_aabb: Aabb,
    bvh: Bvh,
    edges: Vec<[MeshEdge; 3]>,
    flat_angle: Real,
}

/// A named corruption of the raw mesh data.
type Mutation = Box<dyn Fn(&mut RawMesh)>;

fn mesh(n: usize, layout: BvhLayout) -> TriMesh {
    let (mut v, idx) = grid_mesh(n, 4.0, Vec3::new(100.0, -3.0, 7.0));
    let mut rng = Rng(5);
    for p in &mut v {
        p.y += rng.range(-0.5, 0.5);
    }
    let options = TriMeshOptions {
        layout,
        ..Default::default()
    };
    TriMesh::with_options(v, idx, options).unwrap()
}

fn load(bytes: &[u8]) -> Result<TriMesh, String> {
    let _ = take_load_error();
    postcard::from_bytes::<TriMesh>(bytes).map_err(|e| match take_load_error() {
        Some(err) => err.to_string(),
        None => e.to_string(),
    })
}

#[test]
fn valid_meshes_round_trip() {
    for layout in [BvhLayout::Quantized, BvhLayout::Unquantized] {
        let m = mesh(6, layout);
        let back = load(&postcard::to_allocvec(&m).unwrap()).unwrap();
        assert_eq!(back, m);
        // A refit (deformed) mesh and a custom flat angle also load.
        let mut d = m.clone();
        let moved: Vec<Vec3> = d.vertices().iter().map(|p| *p * 1.5 + Vec3::Y).collect();
        d.set_vertices(moved).unwrap();
        assert_eq!(load(&postcard::to_allocvec(&d).unwrap()).unwrap(), d);
        let (v, i) = (m.vertices().to_vec(), m.indices().to_vec());
        let options = TriMeshOptions {
            layout,
            flat_angle: 0.3,
            weld_tolerance: Some(0.0),
        };
        let f = TriMesh::with_options(v, i, options).unwrap();
        assert_eq!(load(&postcard::to_allocvec(&f).unwrap()).unwrap(), f);
    }
}

#[test]
fn inconsistent_meshes_are_rejected_with_a_named_problem() {
    let m = mesh(4, BvhLayout::Quantized);
    let raw: RawMesh = postcard::from_bytes(&postcard::to_allocvec(&m).unwrap()).unwrap();
    let other = mesh(5, BvhLayout::Quantized);
    let cases: Vec<(&str, Mutation)> = vec![
        ("indices[3][1]", Box::new(|r| r.indices[3][1] = 10_000)),
        ("vertices[2]", Box::new(|r| r.vertices[2].x = Real::NAN)),
        ("indices", Box::new(|r| r.indices.clear())),
        ("flat_angle", Box::new(|r| r.flat_angle = Real::NAN)),
        ("local_aabb", Box::new(|r| r.local_aabb.max.x += 1.0)),
        (
            "edges.len()",
            Box::new(|r| {
                r.edges.pop();
            }),
        ),
        ("edges[", Box::new(|r| r.edges.swap(0, 1))),
        (
            "bvh.num_primitives",
            Box::new(move |r| r.bvh = other.bvh().clone()),
        ),
        ("bvh.", Box::new(|r| r.indices.swap(0, 5))),
        ("vertices[0]", Box::new(|r| r.vertices[0] = Vec3::INFINITY)),
        ("bvh.", Box::new(|r| r.vertices[0].y += 0.25)),
    ];
    for (name, mutate) in cases {
        let mut r = raw.clone();
        mutate(&mut r);
        let err = load(&postcard::to_allocvec(&r).unwrap()).unwrap_err();
        assert!(err.contains(name), "{name}: {err}");
    }
}

#[test]
fn every_flipped_byte_gives_an_error_or_a_consistent_mesh() {
    for layout in [BvhLayout::Quantized, BvhLayout::Unquantized] {
        let m = mesh(2, layout);
        let bytes = postcard::to_allocvec(&m).unwrap();
        let mut accepted = 0;
        for i in 0..bytes.len() {
            for mask in [0x01u8, 0x80, 0xFF] {
                let mut b = bytes.clone();
                b[i] ^= mask;
                let Ok(got) = load(&b) else { continue };
                accepted += 1;
                // Anything accepted is a mesh whose queries agree with brute force.
                let mut rng = Rng(i as u64);
                for _ in 0..8 {
                    let o = got.local_aabb().center() + rng.vec(-3.0, 3.0) + Vec3::Y * 5.0;
                    let d = rng.vec(-0.5, 0.5) - Vec3::Y;
                    let want = brute_force::ray_closest(&got.view(), o, d, 100.0);
                    assert_eq!(got.raycast(o, d, 100.0), want, "byte {i} mask {mask}");
                }
                assert_eq!(load(&postcard::to_allocvec(&got).unwrap()).unwrap(), got);
            }
        }
        assert!(accepted < bytes.len(), "{accepted} of {}", bytes.len() * 3);
    }
}

#[test]
fn other_cached_shapes_are_checked_on_load() {
    let decode = |b: &[u8]| {
        let _ = take_load_error();
        postcard::from_bytes::<Shape>(b).map_err(|e| {
            take_load_error()
                .map(|x| x.to_string())
                .unwrap_or(e.to_string())
        })
    };
    let shapes = [
        Shape::HeightField(
            HeightField::new(3, 4, (0..12).map(|i| i as Real).collect(), 1.0, 2.0).unwrap(),
        ),
        Shape::ConvexHull(
            ConvexHull::new(&[Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z, Vec3::ONE]).unwrap(),
        ),
        Shape::Scaled(
            Scaled::new(
                Arc::new(Shape::Sphere(Sphere::new(1.0).unwrap())),
                Vec3::new(1.0, 2.0, 3.0),
            )
            .unwrap(),
        ),
    ];
    for s in &shapes {
        let bytes = postcard::to_allocvec(s).unwrap();
        assert_eq!(&decode(&bytes).unwrap(), s);
        let mut rejected = 0;
        for i in 0..bytes.len() {
            for mask in [0x01u8, 0x80, 0xFF] {
                let mut b = bytes.clone();
                b[i] ^= mask;
                match decode(&b) {
                    Err(_) => rejected += 1,
                    // Accepted bytes re-encode to themselves (a consistent shape).
                    Ok(got) => {
                        assert_eq!(decode(&postcard::to_allocvec(&got).unwrap()).unwrap(), got)
                    }
                }
            }
        }
        assert!(
            rejected > bytes.len(),
            "{} rejected {rejected}",
            s.kind_name()
        );
    }
}

#[test]
fn load_with_options_welds_like_the_constructor() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 0 1\nv 1 0 0\nv 1 0 1\nv 0 0 1\nf 1 3 2\nf 4 6 5\n";
    let path = std::env::temp_dir().join(format!("carom_mesh2_{}.obj", std::process::id()));
    std::fs::write(&path, obj).unwrap();
    let plain = TriMesh::load(&path).unwrap();
    let options = TriMeshOptions {
        weld_tolerance: Some(0.0),
        ..Default::default()
    };
    let welded = TriMesh::load_with_options(&path, options).unwrap();
    let bad = TriMeshOptions {
        weld_tolerance: Some(-1.0),
        ..Default::default()
    };
    let err = TriMesh::load_with_options(&path, bad).unwrap_err();
    std::fs::remove_file(&path).unwrap();
    assert_eq!(plain.vertices().len(), 6);
    assert_eq!(welded.vertices().len(), 4);
    let built = TriMesh::with_options(plain.vertices().to_vec(), plain.indices().to_vec(), options);
    assert_eq!(welded, built.unwrap());
    // The shared diagonal is an interior edge only after welding.
    assert!(plain
        .edges()
        .iter()
        .flatten()
        .all(|e| e.neighbor == NO_NEIGHBOR));
    assert_eq!(
        welded
            .edges()
            .iter()
            .flatten()
            .filter(|e| e.neighbor != NO_NEIGHBOR)
            .count(),
        2
    );
    assert!(err.to_string().contains("weld_tolerance"), "{err}");
}
