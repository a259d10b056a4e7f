//! Contact-manifold micro-benchmarks, each beside parry3d's `contact_manifolds`
//! (`PersistentQueryDispatcher` of `DefaultQueryDispatcher`) in the same run: box–box,
//! hull–hull (8 and 32 vertices), capsule–box, sphere–mesh and box–mesh (Bullet's landscape
//! mesh, internal-edge fixing on in both libraries).
//!
//! Run briefly with
//! `cargo bench -p carom-bench --bench contacts -- --warm-up-time 1 --measurement-time 2`.
//!
//! Each measurement updates 64 manifolds (one per configuration, a shallow penetration of
//! 1 cm at a random orientation) once, for both libraries, with the same prediction
//! distance (2 cm: points are generated up to 2 cm apart in both) and the same inputs (the
//! relative poses converted once; Carom also receives A's pose and composes the relative
//! pose itself). Neither library takes a requested point count: Carom reduces to at most 4
//! points per manifold, parry3d keeps every clipped point within the prediction, so parry3d
//! does more work per manifold on the polyhedral pairs; the point totals of both are printed
//! after each group so the comparison can be read with that in mind. `contacts/*`: persistent manifolds at an unchanged pose, the steady state of a
//! resting pile (both libraries reuse the points by spatial coherence); `contacts-fresh/*`:
//! the manifolds (and parry's workspaces) are cleared first, so every call generates the
//! contacts from scratch. parry3d uses glam 0.33:
//! values are converted through arrays once, outside the timed loops.

use carom_collision::math::{Isometry, Real, Vec3};
use carom_collision::narrowphase::{ContactManifold, Dispatcher};
use carom_collision::query;
use carom_collision::shape::{Capsule, ConvexHull, Cuboid, Shape, Sphere, TriMesh};
use criterion::{criterion_group, criterion_main, Criterion};
use parry3d::math::{Pose as PPose, Vec3 as PVec3};
use parry3d::query::{
    ContactManifold as PManifold, ContactManifoldsWorkspace, DefaultQueryDispatcher,
    PersistentQueryDispatcher,
};
use parry3d::shape::{SharedShape, TriMeshFlags};
use std::hint::black_box;

mod common;
use common::{pp, pv, Rng};

const N: usize = 64;
/// The prediction distance of both libraries (carom's `ManifoldConfig::default()`).
const PREDICTION: Real = 0.02;

#[allow(clippy::unnecessary_cast)] // a no-op in the f32 build, a conversion in the f64 build
fn pf(x: Real) -> f32 {
    x as f32
}

struct Case {
    name: &'static str,
    a: Shape,
    b: Shape,
    pa: SharedShape,
    pb: SharedShape,
    /// B's poses in A's frame (A at the identity).
    poses: Vec<Isometry>,
}

/// B at a random orientation, moved along the contact normal to 1 cm of penetration.
fn convex_poses(rng: &mut Rng, a: &Shape, b: &Shape, dist: Real) -> Vec<Isometry> {
    let mut out = Vec::new();
    while out.len() < N {
        let mut p = Isometry::new(rng.unit() * dist, rng.quat());
        let Ok(Some(c)) = query::contact(a, &Isometry::IDENTITY, b, &p, 10.0) else {
            continue;
        };
        p.translation -= c.normal * (c.distance + 0.01);
        out.push(p);
    }
    out
}

/// B resting on random landscape triangles (1 cm of penetration, random orientation).
fn mesh_poses(rng: &mut Rng, mesh: &TriMesh, a: &Shape, b: &Shape) -> Vec<Isometry> {
    let mut out = Vec::new();
    while out.len() < N {
        let t = (rng.next() * mesh.num_triangles() as Real) as usize % mesh.num_triangles();
        let [p, q, r] = mesh.triangle(t);
        let Some(n) = (q - p).cross(r - p).try_normalize() else {
            continue;
        };
        let n = if n.y < 0.0 { -n } else { n };
        let c = (p + q + r) / 3.0;
        let mut pose = Isometry::new(c + n * 2.0, rng.quat());
        let Ok(Some(k)) = query::contact(a, &Isometry::IDENTITY, b, &pose, 10.0) else {
            continue;
        };
        pose.translation -= k.normal * (k.distance + 0.01);
        out.push(pose);
    }
    out
}

fn hull(rng: &mut Rng, n: usize, r: Real) -> (Shape, SharedShape) {
    let p: Vec<Vec3> = (0..n).map(|_| rng.unit() * r).collect();
    let h = ConvexHull::new(&p).unwrap();
    let pts: Vec<PVec3> = h.vertices().iter().map(|v| pv(*v)).collect();
    (
        Shape::ConvexHull(h),
        SharedShape::convex_hull(&pts).unwrap(),
    )
}

fn cases() -> Vec<Case> {
    let mut rng = Rng(7);
    let mut out = Vec::new();
    let bx = Shape::Cuboid(Cuboid::new(Vec3::new(0.5, 0.4, 0.6)).unwrap());
    let pbx = || SharedShape::cuboid(0.5, 0.4, 0.6);
    let poses = convex_poses(&mut rng, &bx, &bx, 1.2);
    out.push(Case {
        name: "box-box",
        a: bx.clone(),
        b: bx.clone(),
        pa: pbx(),
        pb: pbx(),
        poses,
    });
    for n in [8, 32] {
        let (ha, pha) = hull(&mut rng, n, 0.6);
        let (hb, phb) = hull(&mut rng, n, 0.6);
        let poses = convex_poses(&mut rng, &ha, &hb, 1.2);
        out.push(Case {
            name: if n == 8 {
                "hull8-hull8"
            } else {
                "hull32-hull32"
            },
            a: ha,
            b: hb,
            pa: pha,
            pb: phb,
            poses,
        });
    }
    let cap = Shape::Capsule(Capsule::new(0.3, 0.5).unwrap());
    let poses = convex_poses(&mut rng, &bx, &cap, 1.2);
    out.push(Case {
        name: "box-capsule",
        a: bx.clone(),
        b: cap,
        pa: pbx(),
        pb: SharedShape::capsule_y(0.5, 0.3),
        poses,
    });
    let part = carom_scenes::data::landscape_parts().swap_remove(0);
    let mesh = TriMesh::new(part.vertices.clone(), part.indices.clone()).unwrap();
    let pmesh = SharedShape::trimesh_with_flags(
        part.vertices.iter().map(|v| pv(*v)).collect(),
        part.indices.clone(),
        TriMeshFlags::FIX_INTERNAL_EDGES,
    )
    .unwrap();
    let sm = Shape::TriMesh(mesh.clone());
    let ball = Shape::Sphere(Sphere::new(0.5).unwrap());
    let poses = mesh_poses(&mut rng, &mesh, &sm, &ball);
    out.push(Case {
        name: "mesh-sphere",
        a: sm.clone(),
        b: ball,
        pa: pmesh.clone(),
        pb: SharedShape::ball(0.5),
        poses,
    });
    let poses = mesh_poses(&mut rng, &mesh, &sm, &bx);
    out.push(Case {
        name: "mesh-box",
        a: sm,
        b: bx,
        pa: pmesh,
        pb: pbx(),
        poses,
    });
    out
}

fn bench_contacts(c: &mut Criterion) {
    let d = Dispatcher::default();
    assert_eq!(d.config.prediction, PREDICTION);
    let pd = DefaultQueryDispatcher;
    for case in cases() {
        let ppos: Vec<PPose> = case.poses.iter().map(pp).collect();
        for fresh in [false, true] {
            let group = if fresh { "contacts-fresh" } else { "contacts" };
            let mut g = c.benchmark_group(format!("{group}/{}", case.name));
            let mut ours: Vec<ContactManifold> = vec![ContactManifold::new(); N];
            g.bench_function("carom", |bch| {
                bch.iter(|| {
                    for (p, m) in case.poses.iter().zip(&mut ours) {
                        if fresh {
                            m.clear();
                        }
                        d.update_manifold(&case.a, &Isometry::IDENTITY, &case.b, p, m)
                            .unwrap();
                    }
                    black_box(&ours);
                })
            });
            let ours_pts: usize = ours.iter().map(|m| m.len()).sum();
            type Slot = (Vec<PManifold<(), ()>>, Option<ContactManifoldsWorkspace>);
            let mut theirs: Vec<Slot> = (0..N).map(|_| (Vec::new(), None)).collect();
            g.bench_function("parry3d", |bch| {
                bch.iter(|| {
                    for (p, (m, ws)) in ppos.iter().zip(&mut theirs) {
                        if fresh {
                            m.clear();
                            *ws = None;
                        }
                        pd.contact_manifolds(p, &*case.pa, &*case.pb, pf(PREDICTION), m, ws)
                            .unwrap();
                    }
                    black_box(&theirs);
                })
            });
            let theirs_pts: usize = theirs
                .iter()
                .map(|(m, _)| m.iter().map(|m| m.points.len()).sum::<usize>())
                .sum();
            g.finish();
            println!(
                "{group}/{}: {ours_pts} points over {N} manifolds (carom), {theirs_pts} (parry3d)",
                case.name
            );
        }
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().without_plots();
    targets = bench_contacts
}
criterion_main!(benches);
