//! `carom-bench scenes`: Bullet's eight benchmark scenes (`carom-scenes`) run side by side by
//! every in-process engine ([`engine::builders`]: Rapier via rapier3d 0.36.1) and by Bullet
//! through pybullet ([`bullet_peer`]), sleeping off and on, on one thread and on all cores,
//! several runs each (interleaved: run r of every configuration before run r + 1); prints
//! the table (ms/step, first-200 mean, settled median, stage split, ratios, sanity) and the
//! ray-batch table, and writes JSON, CSV and a PNG chart.
//! `--check` runs a few steps per scene and checks the sanity figures instead of timing.

pub mod bullet_peer;
pub mod carom_engine;
pub mod chart;
pub mod control;
pub mod engine;
pub mod export;
pub mod inertia;
pub mod rapier_peer;
pub mod record;
pub mod report;
pub mod sanity;
pub mod stats;

use carom_scenes::bullet::{scene as scene_by_number, SCENE_NAMES};
use carom_scenes::Scene;
use engine::EngineConfig;
use indicatif::{ProgressBar, ProgressStyle};
use record::RunRecord;
use report::RayRow;
use std::path::PathBuf;

/// Options of `carom-bench scenes`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Scenes to run, by name or number 1–8, comma-separated (default: all).
    #[arg(long, value_delimiter = ',')]
    pub scene: Vec<String>,
    /// Steps of 1/60 s per run.
    #[arg(long, default_value_t = 600)]
    pub steps: usize,
    /// Runs per configuration.
    #[arg(long, default_value_t = 3)]
    pub runs: usize,
    /// Thread counts, comma-separated; 0 = all cores.
    #[arg(long, value_delimiter = ',', default_value = "1,0")]
    pub threads: Vec<usize>,
    /// Sleeping settings to run: off, on or both.
    #[arg(long, value_delimiter = ',', default_value = "off,on")]
    pub sleeping: Vec<String>,
    /// Peers to run beside Carom: rapier, bullet.
    #[arg(long, value_delimiter = ',', default_value = "rapier,bullet")]
    pub peers: Vec<String>,
    /// Python with pybullet (default: the workspace's .venv-bench).
    #[arg(long)]
    pub python: Option<PathBuf>,
    /// Output directory for JSON, CSV, PNG and the exported scenes.
    #[arg(long, default_value = "bench/results")]
    pub out: PathBuf,
    /// Only run a few steps (default 10) per scene and check the sanity figures.
    #[arg(long)]
    pub check: bool,
}

/// Looks a scene up by Bullet's name (case-insensitive) or number 1–8.
pub fn find_scene(name: &str) -> Option<Scene> {
    if let Ok(n) = name.parse::<usize>() {
        return scene_by_number(n);
    }
    let i = SCENE_NAMES
        .iter()
        .position(|s| s.eq_ignore_ascii_case(name.trim()))?;
    scene_by_number(i + 1)
}

fn selected_scenes(args: &Args) -> Result<Vec<Scene>, String> {
    if args.scene.is_empty() {
        return Ok((1..=SCENE_NAMES.len())
            .filter_map(scene_by_number)
            .collect());
    }
    args.scene
        .iter()
        .map(|n| {
            find_scene(n).ok_or_else(|| format!("unknown scene {n:?}; known: {SCENE_NAMES:?}"))
        })
        .collect()
}

/// Runs every scene for `steps` steps with every in-process engine and returns the sanity
/// problems found (empty = all sane). Used by `--check` and by the crate's tests.
pub fn check(scenes: &[Scene], steps: usize) -> Vec<String> {
    let mut problems = Vec::new();
    for scene in scenes {
        for (name, build) in engine::builders() {
            let config = EngineConfig {
                threads: 1,
                sleeping: false,
            };
            match record::run_in_process(scene, build, config, steps, &mut || {}) {
                Ok(r) => {
                    let n = scene.dynamic_count();
                    if r.sanity.bodies != n {
                        problems.push(format!(
                            "{} / {name}: {} bodies, scene has {n}",
                            scene.name, r.sanity.bodies
                        ));
                    }
                    for p in sanity::short_run_problems(scene, &r.sanity, steps, 15.0) {
                        problems.push(format!("{} / {name}: {p}", scene.name));
                    }
                }
                Err(e) => problems.push(format!("{} / {name}: {e}", scene.name)),
            }
        }
    }
    problems
}

fn parse_sleeping(args: &Args) -> Result<Vec<bool>, String> {
    args.sleeping
        .iter()
        .map(|s| match s.as_str() {
            "off" => Ok(false),
            "on" => Ok(true),
            other => Err(format!("--sleeping takes off/on, not {other:?}")),
        })
        .collect()
}

/// Entry point of `carom-bench scenes`.
pub fn run(args: &Args) -> Result<(), String> {
    let scenes = selected_scenes(args)?;
    if args.check {
        let steps = if args.steps == 600 { 10 } else { args.steps };
        let problems = check(&scenes, steps);
        for p in &problems {
            eprintln!("sanity: {p}");
        }
        if !problems.is_empty() {
            return Err(format!("{} sanity problems", problems.len()));
        }
        println!("{} scenes sane after {steps} steps", scenes.len());
        return Ok(());
    }
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut threads: Vec<usize> = args
        .threads
        .iter()
        .map(|&t| if t == 0 { cores } else { t })
        .collect();
    threads.dedup();
    let sleeping = parse_sleeping(args)?;
    let engines: Vec<_> = engine::builders()
        .into_iter()
        .filter(|(n, _)| *n == "carom" || args.peers.iter().any(|p| p == n))
        .collect();
    let python = args
        .python
        .clone()
        .unwrap_or_else(bullet_peer::default_python);
    let bullet = args.peers.iter().any(|p| p == "bullet");
    if bullet && !python.exists() {
        return Err(format!(
            "{} not found: run `make bench-venv` or drop bullet from --peers",
            python.display()
        ));
    }
    let jobs_per =
        sleeping.len() * args.runs * (engines.len() * threads.len() + usize::from(bullet));
    let bar = ProgressBar::new((scenes.len() * jobs_per * args.steps) as u64);
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} steps {msg}")
            .map_err(|e| e.to_string())?
            .progress_chars("=> "),
    );
    let mut summaries = Vec::new();
    let mut rays = Vec::new();
    let most = threads.iter().copied().max().unwrap_or(1);
    let mut control = control::Control::new(most)?;
    for scene in &scenes {
        let json = if bullet {
            Some(bullet_peer::export_to(scene, &args.out.join("scenes"))?)
        } else {
            None
        };
        for &sleep in &sleeping {
            // Round robin: run r of every configuration (thread count × engine, then
            // Bullet) before run r + 1 of any, so a slow spell of a shared machine falls on
            // all of them alike instead of on one configuration's block of runs; the ratios
            // (Carom / peer, two threads / one) compare runs made minutes apart at most.
            let configs: Vec<(usize, &str, engine::EngineBuilder)> = threads
                .iter()
                .flat_map(|&t| engines.iter().map(move |&(name, build)| (t, name, build)))
                .collect();
            let mut runs: Vec<Vec<RunRecord>> = vec![Vec::new(); configs.len()];
            let mut records = Vec::new();
            let mut mt = Vec::new();
            for _ in 0..args.runs {
                for (&(t, name, build), out) in configs.iter().zip(&mut runs) {
                    bar.set_message(format!("{} / {name} / {t} thr", scene.name));
                    let config = EngineConfig {
                        threads: t,
                        sleeping: sleep,
                    };
                    out.push(record::run_in_process(
                        scene,
                        build,
                        config,
                        args.steps,
                        &mut || bar.inc(1),
                    )?);
                }
                if let Some(json) = &json {
                    bar.set_message(format!("{} / bullet", scene.name));
                    let r = bullet_peer::run(&python, scene, json, args.steps, sleep)?;
                    bar.inc(args.steps as u64);
                    mt.extend(r.ray_ms_mt);
                    records.push(r.record);
                }
                if let Some(c) = &mut control {
                    bar.set_message(format!("{} / control", scene.name));
                    c.sample();
                }
            }
            for runs in &runs {
                let s = stats::summarize(runs);
                if let Some(ms) = s.rays_ms {
                    rays.push(ray_row(&s, ms, scene));
                }
                summaries.push(s);
            }
            if json.is_some() {
                let s = stats::summarize(&records);
                if let Some(ms) = s.rays_ms {
                    rays.push(ray_row(&s, ms, scene));
                    let mut row = ray_row(&s, stats::median(&mt), scene);
                    row.threads = cores;
                    rays.push(row);
                }
                summaries.push(s);
            }
        }
    }
    bar.finish_and_clear();
    println!(
        "{} steps of 1/60 s, {} run(s) per configuration, {cores} cores\n",
        args.steps, args.runs
    );
    println!("{}", report::table(&summaries));
    if !rays.is_empty() {
        println!("Ray batch of the raytests scene (500 rays, closest hit):\n");
        println!("{}", report::ray_table(&rays));
    }
    if let Some(c) = &control {
        println!(
            "Speed-up on {} threads over one (median ms/step; the control is a compute-bound \
             parallel loop timed between the runs, the ratio of its median times: what the \
             machine allowed meanwhile):\n",
            c.threads
        );
        println!("{}", report::speedup_table(&summaries, c));
    }
    report::write_files(&args.out, "scenes", &summaries, &rays, control.as_ref())?;
    let png = args.out.join("scenes.png");
    chart::draw(&summaries, &png)?;
    println!(
        "wrote {0}/scenes.json, {0}/scenes.csv, {1}",
        args.out.display(),
        png.display()
    );
    Ok(())
}

fn ray_row(s: &stats::Summary, ms: f64, scene: &Scene) -> RayRow {
    RayRow {
        engine: s.engine.clone(),
        threads: s.threads,
        sleeping: s.sleeping,
        median_ms: ms,
        rays: scene.rays.len(),
        hits: s.ray_hits,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_scene_stays_sane_for_a_few_steps() {
        let scenes: Vec<Scene> = (1..=8).filter_map(scene_by_number).collect();
        assert_eq!(scenes.len(), 8);
        let problems = check(&scenes, 10);
        assert!(problems.is_empty(), "{problems:#?}");
    }

    #[test]
    fn scenes_are_found_by_name_and_number() {
        assert_eq!(find_scene("1000 Stack").unwrap().name, "1000 stack");
        assert_eq!(find_scene("7").unwrap().name, "raytests");
        assert!(find_scene("9").is_none() && find_scene("nope").is_none());
    }
}
