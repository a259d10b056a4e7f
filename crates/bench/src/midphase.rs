//! `carom-bench midphase`: BVH build time, bytes per triangle and closest-hit ray casts per
//! second on the landscape mesh and a generated ~1M-triangle mesh, beside parry3d's `TriMesh`
//! on the same meshes and rays in the same run (single thread and all threads).
//!
//! Build and single-thread ray figures are process CPU time: robust on a shared machine, and
//! it counts work that construction hands to rayon workers (thread CPU time would hide it and
//! flatter a parallel build against parry's serial one). Batch rays
//! (`TriMesh::raycast_batch`, and parry through rayon) run in a 1-thread and an all-threads
//! rayon pool, interleaved: their wall times give the speed-up (bounded by the cores that
//! are free), their process CPU times the parallel overhead (1.0 = none).
//!
//! Options: `--rays N` (rays per mesh, default 200000), `--grid N` (cells per side of the
//! generated mesh, default 708 → 1,002,528 triangles), `--runs N` (timing repeats, median).

use carom_collision::math::{Real, Vec3};
use carom_collision::midphase::{triangle_aabbs, Bvh, BvhLayout};
use carom_collision::shape::{TriMesh, TriMeshOptions};
use parry3d::query::RayCast;
use rayon::prelude::*;
use std::time::Instant;

use crate::mesh_inputs::{generated_mesh, pv, rays, PVec};

struct Args {
    rays: usize,
    grid: usize,
    runs: usize,
}

fn parse_args(args: &[String]) -> Args {
    let mut a = Args {
        rays: 200_000,
        grid: 708,
        runs: 3,
    };
    let mut it = args.iter();
    while let Some(k) = it.next() {
        let v = it.next().and_then(|v| v.parse::<usize>().ok());
        match (k.as_str(), v) {
            ("--rays", Some(v)) => a.rays = v.max(1),
            ("--grid", Some(v)) => a.grid = v.max(1),
            ("--runs", Some(v)) => a.runs = v.max(1),
            _ => {
                eprintln!("usage: carom-bench midphase [--rays N] [--grid N] [--runs N]");
                std::process::exit(2);
            }
        }
    }
    a
}

/// Median CPU time of the whole process (all threads) in seconds of `runs` calls of `f`.
fn median_time<T>(runs: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..runs {
        let t0 = process_cpu_seconds();
        let out = f();
        times.push(process_cpu_seconds() - t0);
        last = Some(out);
    }
    times.sort_by(|a, b| a.total_cmp(b));
    (times[times.len() / 2], last.expect("runs >= 1"))
}

fn bench_mesh(name: &str, v: Vec<Vec3>, t: Vec<[u32; 3]>, args: &Args) {
    let ntri = t.len();
    let per_m = 1.0e6 / ntri as f64;
    println!("\n### {name}: {} vertices, {ntri} triangles", v.len());
    // Build: our BVH alone (triangle boxes + binned SAH + layout), and the whole TriMesh.
    let (t_bvh, bvh) = median_time(args.runs, || {
        Bvh::new(&triangle_aabbs(&v, &t), BvhLayout::Quantized).expect("valid mesh")
    });
    let (t_bvh_u, bvh_u) = median_time(args.runs, || {
        Bvh::new(&triangle_aabbs(&v, &t), BvhLayout::Unquantized).expect("valid mesh")
    });
    let (t_mesh, mesh) = median_time(args.runs, || {
        TriMesh::with_options(v.clone(), t.clone(), TriMeshOptions::default()).expect("valid")
    });
    let pverts: Vec<PVec> = v.iter().map(|p| pv(*p)).collect();
    let (t_parry, pmesh) = median_time(args.runs, || {
        parry3d::shape::TriMesh::new(pverts.clone(), t.clone()).expect("valid mesh")
    });
    let uq = TriMesh::with_options(
        v.clone(),
        t.clone(),
        TriMeshOptions {
            layout: BvhLayout::Unquantized,
            ..Default::default()
        },
    )
    .expect("valid");
    let rays = rays(&mesh.local_aabb(), args.rays);
    let max_t = 1.0e30 as Real;
    let (t_ours, hits_ours) = median_time(args.runs, || {
        rays.iter()
            .filter(|(o, d)| mesh.raycast(*o, *d, max_t).is_some())
            .count()
    });
    let (t_sl, hits_sl) = median_time(args.runs, || {
        let view = mesh.view();
        rays.iter()
            .filter(|(o, d)| view.ray_closest_stackless(*o, *d, max_t).is_some())
            .count()
    });
    assert_eq!(hits_sl, hits_ours, "stackless and ordered walks disagree");
    let (t_uq, hits_uq) = median_time(args.runs, || {
        rays.iter()
            .filter(|(o, d)| uq.raycast(*o, *d, max_t).is_some())
            .count()
    });
    let prays: Vec<parry3d::query::Ray> = rays
        .iter()
        .map(|(o, d)| parry3d::query::Ray::new(pv(*o), pv(*d)))
        .collect();
    let (t_parry_r, hits_parry) = median_time(args.runs, || {
        prays
            .iter()
            .filter(|r| {
                pmesh
                    .cast_local_ray_and_get_normal(r, max_t as _, false)
                    .is_some()
            })
            .count()
    });
    let batch = batch_scaling(&mesh, &pmesh, &rays, &prays, max_t, args.runs);
    let n = rays.len() as f64;
    let threads = rayon::current_num_threads();
    println!(
        "hits: carom {hits_ours}, carom-unquantised {hits_uq}, parry {hits_parry} of {} rays",
        rays.len()
    );
    println!(
        "| metric | carom (quantised) | carom (unquantised) | parry3d 0.31.1 | carom / parry |"
    );
    println!("|---|---|---|---|---|");
    println!(
        "| BVH build, ms per 1M tri | {:.0} | {:.0} | {:.0} (whole TriMesh::new) | {:.2}x faster |",
        t_bvh * per_m * 1e3,
        t_bvh_u * per_m * 1e3,
        t_parry * per_m * 1e3,
        t_parry / t_bvh
    );
    println!(
        "| TriMesh::new (BVH + edges), ms per 1M tri | {:.0} | | {:.0} | {:.2}x |",
        t_mesh * per_m * 1e3,
        t_parry * per_m * 1e3,
        t_parry / t_mesh
    );
    println!(
        "| BVH bytes per triangle | {:.1} | {:.1} | {:.1} | |",
        bvh.memory_bytes() as f64 / ntri as f64,
        bvh_u.memory_bytes() as f64 / ntri as f64,
        pmesh.bvh().total_memory_size() as f64 / ntri as f64
    );
    println!(
        "| closest-hit rays/s, 1 thread | {:.2}M | {:.2}M | {:.2}M | {:.2}x |",
        n / t_ours / 1e6,
        n / t_uq / 1e6,
        n / t_parry_r / 1e6,
        t_parry_r / t_ours
    );
    println!(
        "| closest-hit rays/s, 1 thread, stackless escape walk | {:.2}M | | | {:.2}x |",
        n / t_sl / 1e6,
        t_parry_r / t_sl
    );
    batch.print(n, threads);
}

/// Wall and CPU times of the batch ray path on one thread and on all threads.
struct BatchScaling {
    /// Median wall seconds: (carom, parry) on 1 thread, then on all threads.
    wall_1: (f64, f64),
    wall_n: (f64, f64),
    /// Median process CPU seconds, same order.
    cpu_1: (f64, f64),
    cpu_n: (f64, f64),
    runs: usize,
}

impl BatchScaling {
    fn print(&self, n: f64, threads: usize) {
        let r = |t: f64| n / t / 1e6;
        println!(
            "| batch rays/s, 1-thread pool (wall) | {:.2}M | | {:.2}M | {:.2}x |",
            r(self.wall_1.0),
            r(self.wall_1.1),
            self.wall_1.1 / self.wall_1.0
        );
        println!(
            "| batch rays/s, {threads}-thread pool (wall) | {:.2}M | | {:.2}M | {:.2}x |",
            r(self.wall_n.0),
            r(self.wall_n.1),
            self.wall_n.1 / self.wall_n.0
        );
        println!(
            "| batch speed-up, {threads} threads / 1 (wall) | {:.2}x | | {:.2}x | |",
            self.wall_1.0 / self.wall_n.0,
            self.wall_1.1 / self.wall_n.1
        );
        println!(
            "| batch CPU efficiency (CPU s on 1 / CPU s on {threads}) | {:.2} | | {:.2} | |",
            self.cpu_1.0 / self.cpu_n.0,
            self.cpu_1.1 / self.cpu_n.1
        );
        println!(
            "(batch: medians of {} interleaved runs; wall speed-up is bounded by the free cores, \
             CPU efficiency 1.0 means the parallel path costs no extra work)",
            self.runs
        );
    }
}

/// Process CPU time in seconds (all threads).
fn process_cpu_seconds() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec; the clock id is a constant of libc.
    unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut ts) };
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

/// Wall and process CPU seconds of `f`.
fn wall_and_cpu<T>(f: impl FnOnce() -> T) -> (f64, f64, T) {
    let (w0, c0) = (Instant::now(), process_cpu_seconds());
    let out = f();
    (w0.elapsed().as_secs_f64(), process_cpu_seconds() - c0, out)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

/// The batch entry point (`TriMesh::raycast_batch`, rayon inside) and parry's rays through
/// `par_iter`, each in a 1-thread and an all-threads rayon pool, runs interleaved so both
/// see the same load; checks that the batch results equal the serial ones.
fn batch_scaling(
    mesh: &TriMesh,
    pmesh: &parry3d::shape::TriMesh,
    rays: &[(Vec3, Vec3)],
    prays: &[parry3d::query::Ray],
    max_t: Real,
    runs: usize,
) -> BatchScaling {
    let threads = rayon::current_num_threads();
    let pool = |n: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .expect("rayon pool")
    };
    let (p1, pn) = (pool(1), pool(threads));
    let origins: Vec<Vec3> = rays.iter().map(|r| r.0).collect();
    let dirs: Vec<Vec3> = rays.iter().map(|r| r.1).collect();
    let ours = || {
        mesh.raycast_batch(&origins, &dirs, max_t)
            .expect("same lengths")
    };
    let theirs = || {
        prays
            .par_iter()
            .map(|r| pmesh.cast_local_ray_and_get_normal(r, max_t as _, false))
            .collect::<Vec<_>>()
    };
    let serial: Vec<_> = rays
        .iter()
        .map(|(o, d)| mesh.raycast(*o, *d, max_t))
        .collect();
    let mut t: [Vec<f64>; 8] = Default::default();
    for _ in 0..runs {
        for (k, p) in [&p1, &pn].into_iter().enumerate() {
            let (w, c, out) = wall_and_cpu(|| p.install(ours));
            assert!(out == serial, "batch rays differ from serial rays");
            t[4 * k].push(w);
            t[4 * k + 1].push(c);
            let (w, c, _) = wall_and_cpu(|| p.install(theirs));
            t[4 * k + 2].push(w);
            t[4 * k + 3].push(c);
        }
    }
    let [w1, c1, pw1, pc1, wn, cn, pwn, pcn] = t.map(median);
    BatchScaling {
        wall_1: (w1, pw1),
        wall_n: (wn, pwn),
        cpu_1: (c1, pc1),
        cpu_n: (cn, pcn),
        runs,
    }
}

/// Entry point of the subcommand.
pub fn run(args: &[String]) {
    let args = parse_args(args);
    println!(
        "carom-bench midphase: {} rays per mesh, median of {} runs, {} rayon threads",
        args.rays,
        args.runs,
        rayon::current_num_threads()
    );
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/data/landscape.obj");
    match TriMesh::load(path) {
        Ok(m) => bench_mesh(
            "landscape.obj",
            m.vertices().to_vec(),
            m.indices().to_vec(),
            &args,
        ),
        Err(e) => eprintln!("skipping the landscape: {e}"),
    }
    let (v, t) = generated_mesh(args.grid);
    bench_mesh("generated height grid", v, t, &args);
}
