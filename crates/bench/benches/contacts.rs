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

use carom_collision::math::Isometry;
use carom_collision::narrowphase::{ContactManifold, Dispatcher};
use criterion::{criterion_group, criterion_main, Criterion};
use parry3d::math::Pose as PPose;
use parry3d::query::{
    ContactManifold as PManifold, ContactManifoldsWorkspace, DefaultQueryDispatcher,
    PersistentQueryDispatcher,
};
use std::hint::black_box;

mod common;
#[path = "common/contact_cases.rs"]
mod contact_cases;
use common::pp;
use contact_cases::{cases, pf, N, PREDICTION};

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
