//! `carom-bench broadphase`: the talk's broadphase benchmark, Bullet's CDTestFramework
//! scenario (see [`crate::cdtest`]), for every Carom broadphase and rapier3d's
//! `BroadPhaseBvh` in the same run, at several N.
//!
//! Timed per frame: the proxy updates of the moved boxes plus pair finding (Carom:
//! `update_proxy` × moved + `update_pairs`, which also reports added/removed pairs; rapier:
//! `set_translation` × moved + `BroadPhaseBvh::update`, which reports pair events). Proxies
//! are created with the boxes already on the curve ([`start_scene`]); creation and the first
//! frame are not timed, as in CDTestFramework.

use crate::cdtest::Scene;
use crate::plot;
use carom_collision::broadphase::{
    AnyBroadPhase, BroadPhase, Filter, InsertStrategy, Method, ProxyHandle, TreeBroadPhase,
};
use carom_collision::math::{vec3_from_f64, Aabb, Real};
use serde::Serialize;
use std::path::PathBuf;
use std::time::Instant;

/// Options of `carom-bench broadphase`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Numbers of boxes.
    #[arg(long, value_delimiter = ',', default_value = "1000,8000,32000,128000")]
    pub sizes: Vec<usize>,
    /// Methods: tree, tree_manhattan, sap, sort_sweep, grid, hgrid, brute_force, rapier.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "tree,tree_manhattan,sap,sort_sweep,grid,hgrid,brute_force,rapier"
    )]
    pub methods: Vec<String>,
    /// Percentage of boxes moving each frame (CDTestFramework 2.82: 100).
    #[arg(long, default_value_t = 100.0)]
    pub percent: f64,
    /// Curve phase advance per frame of a moving box (CDTestFramework: 0.01).
    #[arg(long, default_value_t = 0.01)]
    pub speed: f64,
    /// Timed frames per run (default: 60 / 30 / 10 / 3 frames from 1k / 8k / 32k / 128k up).
    #[arg(long)]
    pub frames: Option<usize>,
    /// Scale the curve with N (amplitude 100·(N/8192)^(1/3): the boxes fill a volume, so
    /// the density and the pairs per box stay about constant); the default keeps
    /// CDTestFramework's fixed world, where pairs grow as N².
    #[arg(long)]
    pub constant_density: bool,
    /// Largest N for the O(N²) brute force.
    #[arg(long, default_value_t = 8192)]
    pub brute_max: usize,
    /// Worker threads (rayon global pool, used by Carom and rapier alike); 0 = rayon default.
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// Fat-box margin of the tree broadphases.
    #[arg(long, default_value_t = 0.1)]
    pub tree_margin: f64,
    /// Fat boxes of the trees are swept by this times the last displacement.
    #[arg(long, default_value_t = 2.0)]
    pub tree_motion_scale: f64,
    /// Output folder for JSON, CSV and PNG.
    #[arg(long, default_value = "bench-results")]
    pub out: PathBuf,
}

/// One (method, N) measurement.
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    pub method: String,
    pub n: usize,
    pub frames: usize,
    pub median_ms: f64,
    pub min_ms: f64,
    /// Median CPU time per frame summed over all threads of the process (robust to other
    /// load on the machine; for parallel runs it counts every thread's work).
    pub median_cpu_ms: f64,
    /// Pairs at the last frame (Carom: exact box overlaps; rapier: its fat-box pairs).
    pub pairs: usize,
    /// Mean pairs added + removed per frame.
    pub changes_per_frame: f64,
}

fn frames_for(n: usize) -> usize {
    match n {
        0..=2000 => 60,
        2001..=10000 => 30,
        10001..=40000 => 10,
        _ => 3,
    }
}

/// The scene with every box already on its curve. CDTestFramework creates the boxes at
/// random and the first (untimed) frame moves them all onto the curve; with rapier's BVH,
/// which refits moved leaves in place, that jump leaves a tree whose nodes span the whole
/// world, and its first traversals cost O(N²) (at N = 128k: over 13 minutes and 8 GB
/// before the first timed frame). Creating every structure at the curve positions removes
/// the jump for all methods alike; the timed frames are unchanged.
fn start_scene(n: usize, args: &Args, amp: f64) -> Scene {
    let mut scene = Scene::new(n, args.percent, args.speed, amp);
    scene.advance(n);
    scene
}

fn aabb_of(scene: &Scene, i: usize) -> Aabb {
    let (lo, hi) = scene.aabb(i);
    Aabb::new(vec3_from_f64(lo), vec3_from_f64(hi))
}

/// CPU time of the whole process (all threads), in ms, from `/proc/self/task/*/schedstat`
/// (0 where unavailable).
fn process_cpu_ms() -> f64 {
    let Ok(dir) = std::fs::read_dir("/proc/self/task") else {
        return 0.0;
    };
    let mut ns = 0u64;
    for t in dir.flatten() {
        if let Ok(s) = std::fs::read_to_string(t.path().join("schedstat")) {
            ns += s
                .split_whitespace()
                .next()
                .and_then(|x| x.parse().ok())
                .unwrap_or(0);
        }
    }
    ns as f64 * 1e-6
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn run_carom(method: Method, n: usize, frames: usize, args: &Args, amp: f64) -> Row {
    let mut scene = start_scene(n, args, amp);
    let mut bp = match method {
        Method::Tree | Method::TreeManhattan => {
            let strategy = if method == Method::Tree {
                InsertStrategy::SurfaceArea
            } else {
                InsertStrategy::Manhattan
            };
            let mut t = TreeBroadPhase::new(strategy, args.tree_margin as Real);
            t.set_motion_scale(args.tree_motion_scale as Real);
            AnyBroadPhase::Tree(t)
        }
        _ => AnyBroadPhase::new(method),
    };
    let handles: Vec<ProxyHandle> = (0..n)
        .map(|i| {
            bp.create_proxy(aabb_of(&scene, i), Filter::default())
                .expect("valid box")
        })
        .collect();
    bp.update_pairs();
    let mut times = Vec::new();
    let mut cpu = Vec::new();
    let mut changes = 0usize;
    for frame in 0..=frames {
        let count = if frame == 0 { n } else { scene.moving };
        let disp = scene.advance(count);
        let c0 = process_cpu_ms();
        let t0 = Instant::now();
        for (i, d) in disp.iter().enumerate() {
            bp.update_proxy(handles[i], aabb_of(&scene, i), vec3_from_f64(*d))
                .expect("valid box");
        }
        let ch = bp.update_pairs();
        let dt = t0.elapsed().as_secs_f64() * 1e3;
        let dc = process_cpu_ms() - c0;
        if frame > 0 {
            changes += ch.added.len() + ch.removed.len();
            times.push(dt);
            cpu.push(dc);
        }
    }
    if let AnyBroadPhase::Tree(t) = &bp {
        eprintln!(
            "    tree candidates (fat pairs): {}, height {}, area ratio {:.1}",
            t.candidate_count(),
            t.tree(0).height(),
            t.tree(0).area_ratio()
        );
    }
    let min = times.iter().copied().fold(f64::INFINITY, f64::min);
    Row {
        method: method.name().to_string(),
        n,
        frames,
        median_ms: median(&mut times),
        min_ms: min,
        median_cpu_ms: median(&mut cpu),
        pairs: bp.pair_count(),
        changes_per_frame: changes as f64 / frames as f64,
    }
}

fn run_rapier(n: usize, frames: usize, args: &Args, amp: f64) -> Row {
    use rapier3d::prelude::*;
    let mut scene = start_scene(n, args, amp);
    let params = IntegrationParameters::default();
    let bodies = RigidBodySet::new();
    let mut colliders = ColliderSet::new();
    let v = |c: [f64; 3]| Vector::new(c[0] as Real, c[1] as Real, c[2] as Real);
    let handles: Vec<ColliderHandle> = (0..n)
        .map(|i| {
            let h = scene.half[i];
            colliders.insert(
                ColliderBuilder::cuboid(h[0] as Real, h[1] as Real, h[2] as Real)
                    .translation(v(scene.centers[i]))
                    // Standalone colliders are "fixed": let them pair, as the boxes here do.
                    .active_collision_types(ActiveCollisionTypes::all())
                    .build(),
            )
        })
        .collect();
    let mut bp = BroadPhaseBvh::new();
    let mut events = Vec::new();
    bp.update(&params, &colliders, &bodies, &handles, &[], &mut events);
    let mut pairs = count_events(&events, 0);
    let mut times = Vec::new();
    let mut cpu = Vec::new();
    let mut changes = 0usize;
    for frame in 0..=frames {
        let count = if frame == 0 { n } else { scene.moving };
        scene.advance(count);
        events.clear();
        let c0 = process_cpu_ms();
        let t0 = Instant::now();
        for i in 0..count {
            colliders[handles[i]].set_translation(v(scene.centers[i]));
        }
        bp.update(
            &params,
            &colliders,
            &bodies,
            &handles[..count],
            &[],
            &mut events,
        );
        let dt = t0.elapsed().as_secs_f64() * 1e3;
        let dc = process_cpu_ms() - c0;
        pairs = count_events(&events, pairs);
        if frame > 0 {
            changes += events.len();
            times.push(dt);
            cpu.push(dc);
        }
    }
    let min = times.iter().copied().fold(f64::INFINITY, f64::min);
    Row {
        method: "rapier".into(),
        n,
        frames,
        median_ms: median(&mut times),
        min_ms: min,
        median_cpu_ms: median(&mut cpu),
        pairs,
        changes_per_frame: changes as f64 / frames as f64,
    }
}

fn count_events(events: &[rapier3d::geometry::BroadPhasePairEvent], mut pairs: usize) -> usize {
    use rapier3d::geometry::BroadPhasePairEvent as E;
    for e in events {
        match e {
            E::AddPair(_) => pairs += 1,
            E::DeletePair(_) => pairs = pairs.saturating_sub(1),
        }
    }
    pairs
}

/// Runs the benchmark, prints the table and writes JSON, CSV and PNG to `args.out`.
pub fn run(args: &Args) -> Result<(), String> {
    if args.threads > 0 {
        rayon::ThreadPoolBuilder::new()
            .num_threads(args.threads)
            .build_global()
            .map_err(|e| e.to_string())?;
    }
    let mut rows = Vec::new();
    for &n in &args.sizes {
        let frames = args.frames.unwrap_or_else(|| frames_for(n)).max(1);
        let amp = if args.constant_density {
            100.0 * (n as f64 / 8192.0).cbrt()
        } else {
            100.0
        };
        for m in &args.methods {
            let row = if m == "rapier" {
                run_rapier(n, frames, args, amp)
            } else {
                let method: Method = m.parse().map_err(|e| format!("{e}"))?;
                if method == Method::BruteForce && n > args.brute_max {
                    continue;
                }
                run_carom(method, n, frames, args, amp)
            };
            eprintln!(
                "  {:>14} N={:>6}: {:>9.3} ms/frame (min {:.3}, cpu {:.3}), {} pairs",
                row.method, row.n, row.median_ms, row.min_ms, row.median_cpu_ms, row.pairs
            );
            rows.push(row);
        }
    }
    print_table(&rows, args, "wall-clock", |r| r.median_ms);
    print_table(&rows, args, "CPU (all threads)", |r| r.median_cpu_ms);
    std::fs::create_dir_all(&args.out).map_err(|e| e.to_string())?;
    let tag = if args.constant_density {
        "broadphase_constant_density"
    } else {
        "broadphase"
    };
    let json = serde_json::to_string_pretty(&rows).map_err(|e| e.to_string())?;
    std::fs::write(args.out.join(format!("{tag}.json")), json).map_err(|e| e.to_string())?;
    let mut csv =
        String::from("method,n,frames,median_ms,min_ms,median_cpu_ms,pairs,changes_per_frame\n");
    for r in &rows {
        csv += &format!(
            "{},{},{},{:.4},{:.4},{:.4},{},{:.1}\n",
            r.method,
            r.n,
            r.frames,
            r.median_ms,
            r.min_ms,
            r.median_cpu_ms,
            r.pairs,
            r.changes_per_frame
        );
    }
    std::fs::write(args.out.join(format!("{tag}.csv")), csv).map_err(|e| e.to_string())?;
    let png = args.out.join(format!("{tag}.png"));
    plot::cost_vs_n(
        &rows,
        &png,
        "broadphase: CDTestFramework scene, ms per frame",
    )?;
    println!("wrote {}/{tag}.{{json,csv,png}}", args.out.display());
    Ok(())
}

fn print_table(rows: &[Row], args: &Args, label: &str, metric: fn(&Row) -> f64) {
    let mut methods: Vec<&str> = Vec::new();
    for r in rows {
        if !methods.contains(&r.method.as_str()) {
            methods.push(&r.method);
        }
    }
    let find = |m: &str, n: usize| rows.iter().find(|r| r.method == m && r.n == n);
    println!(
        "\nbroadphase, CDTestFramework scene ({}% moving, speed {}, {} world), median {label} \
         ms/frame; (x) = rapier time / this time",
        args.percent,
        args.speed,
        if args.constant_density {
            "constant-density"
        } else {
            "fixed"
        }
    );
    print!("{:>8} {:>10}", "N", "pairs");
    for m in &methods {
        print!(" {:>20}", m);
    }
    println!(" {:>12}", "best");
    for &n in &args.sizes {
        let pairs = rows
            .iter()
            .find(|r| r.n == n && r.method != "rapier")
            .map_or(0, |r| r.pairs);
        print!("{:>8} {:>10}", n, pairs);
        let rapier = find("rapier", n).map(metric);
        let mut best: Option<&Row> = None;
        for m in &methods {
            match find(m, n) {
                Some(r) => {
                    let ratio =
                        rapier.map_or(String::new(), |t| format!("({:.2}x)", t / metric(r)));
                    print!(" {:>11.3} {:>8}", metric(r), ratio);
                    if r.method != "rapier" && best.is_none_or(|b| metric(r) < metric(b)) {
                        best = Some(r);
                    }
                }
                None => print!(" {:>20}", "-"),
            }
        }
        println!(" {:>12}", best.map_or("-", |b| b.method.as_str()));
    }
    println!("\ngrowth of cost per N step: time ratio (exponent k in time ~ N^k)");
    for m in &methods {
        let pts: Vec<&Row> = args.sizes.iter().filter_map(|&n| find(m, n)).collect();
        let mut line = format!("{:>16}:", m);
        for w in pts.windows(2) {
            let (a, b) = (w[0], w[1]);
            let k = (metric(b) / metric(a)).ln() / (b.n as f64 / a.n as f64).ln();
            line += &format!(
                "  {}->{}: {:.2}x (k={:.2})",
                a.n,
                b.n,
                metric(b) / metric(a),
                k
            );
        }
        println!("{line}");
    }
    let mut line = String::from("  N log N (ref.):");
    for w in args.sizes.windows(2) {
        let (a, b) = (w[0].max(2) as f64, w[1].max(2) as f64);
        line += &format!("  {}->{}: {:.2}x", w[0], w[1], b * b.ln() / (a * a.ln()));
    }
    println!("{line}");
    println!("pairs growth (the output size bounds any method):");
    let pts: Vec<&Row> = args
        .sizes
        .iter()
        .filter_map(|&n| rows.iter().find(|r| r.n == n && r.method != "rapier"))
        .collect();
    let mut line = String::from("           pairs:");
    for w in pts.windows(2) {
        let k = (w[1].pairs.max(1) as f64 / w[0].pairs.max(1) as f64).ln()
            / (w[1].n as f64 / w[0].n as f64).ln();
        line += &format!("  {}->{}: k={:.2}", w[0].n, w[1].n, k);
    }
    println!("{line}");
}
