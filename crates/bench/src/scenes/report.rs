//! Output of `carom-bench scenes`: the Markdown table on stdout (with each engine's ratio to
//! Rapier and to Bullet in the same configuration), the ray table, and the JSON and CSV files.

use super::control::Control;
use super::stats::Summary;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;

/// Ray batch timing of one engine and thread count on the ray scene.
#[derive(Debug, Clone, Serialize)]
pub struct RayRow {
    /// Engine name.
    pub engine: String,
    /// Threads used for the batch.
    pub threads: usize,
    /// Sleeping on or off in the run the rays were cast in.
    pub sleeping: bool,
    /// Median batch time, ms.
    pub median_ms: f64,
    /// Rays in the batch.
    pub rays: usize,
    /// Rays that hit in the last batch.
    pub hits: usize,
}

fn opt(x: Option<f64>) -> String {
    x.map_or("–".into(), |v| format!("{v:.2}"))
}

/// The time of `engine` in the same configuration as `s` (Bullet only runs one thread: its
/// single-threaded figure is the reference for every thread count).
fn peer<'a>(all: &'a [Summary], s: &Summary, engine: &str) -> Option<&'a Summary> {
    all.iter().find(|o| {
        o.engine == engine
            && o.scene == s.scene
            && o.sleeping == s.sleeping
            && (o.threads == s.threads || engine == "bullet")
    })
}

/// The Markdown table of all summaries.
pub fn table(all: &[Summary]) -> String {
    let mut out = String::new();
    out.push_str(
        "| scene | engine | thr | sleep | ms/step med (min–max) | first 200 | settled | \
         bp | mid+narrow | solver | integ | /rapier | /bullet | mean y | rest | below | \
         drift max | v max |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for s in all {
        let ratio = |e: &str| {
            peer(all, s, e)
                .filter(|p| p.engine != s.engine)
                .map_or("–".into(), |p| {
                    format!("{:.2}", s.ms_median / p.ms_median)
                })
        };
        let q = &s.sanity;
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {:.2} ({:.2}–{:.2}) | {:.2} | {:.2} | {} | {} | {} | {} | {} | {} | {:.2} | {}/{} | {} | {:.2} | {:.1} |",
            s.scene,
            s.engine,
            s.threads,
            if s.sleeping { "on" } else { "off" },
            s.ms_median,
            s.ms_min,
            s.ms_max,
            s.first200_mean,
            s.settled_median,
            opt(s.broadphase_ms),
            opt(s.narrowphase_ms),
            opt(s.solver_ms),
            opt(s.integration_ms),
            ratio("rapier"),
            ratio("bullet"),
            q.mean_height,
            q.resting,
            q.bodies,
            q.below_ground + q.non_finite,
            q.max_drift,
            q.max_speed,
        );
    }
    out
}

/// The Markdown table of the ray batches.
pub fn ray_table(rows: &[RayRow]) -> String {
    let mut out =
        String::from("| engine | threads | sleep | ms per batch (median) | rays | hits |\n|---|---|---|---|---|---|\n");
    for r in rows {
        let _ = writeln!(
            out,
            "| {} | {} | {} | {:.3} | {} | {} |",
            r.engine,
            r.threads,
            if r.sleeping { "on" } else { "off" },
            r.median_ms,
            r.rays,
            r.hits
        );
    }
    out
}

/// The Markdown table of speed-ups: per scene and sleeping setting, each engine's median
/// ms/step on one thread over its median on `control.threads` threads, and the control's
/// speed-up over the whole run (of the median times) in every row.
pub fn speedup_table(all: &[Summary], control: &Control) -> String {
    let c = control.speedup().map_or("–".into(), |m| format!("{m:.2}x"));
    let mut out = format!(
        "| scene | sleep | engine | 1 thread | {0} threads | speed-up | control |\n|---|---|---|---|---|---|---|\n",
        control.threads
    );
    for one in all
        .iter()
        .filter(|s| s.threads == 1 && s.engine != "bullet")
    {
        let Some(many) = all.iter().find(|o| {
            o.engine == one.engine
                && o.scene == one.scene
                && o.sleeping == one.sleeping
                && o.threads == control.threads
        }) else {
            continue;
        };
        let _ = writeln!(
            out,
            "| {} | {} | {} | {:.2} | {:.2} | {:.2}x | {c} |",
            one.scene,
            if one.sleeping { "on" } else { "off" },
            one.engine,
            one.ms_median,
            many.ms_median,
            one.ms_median / many.ms_median,
        );
    }
    out
}

fn csv_field(x: Option<f64>) -> String {
    x.map_or(String::new(), |v| format!("{v:.6}"))
}

/// The summaries as CSV (one row per configuration; empty cells where a stage has no timer).
pub fn csv(all: &[Summary]) -> String {
    let mut out = String::from(
        "scene,engine,threads,sleeping,runs,steps,ms_median,ms_min,ms_max,first200_mean,\
         settled_median,broadphase_ms,narrowphase_ms,solver_ms,integration_ms,rays_ms,ray_hits,\
         bodies,mean_height,resting,below_ground,non_finite,max_drift,max_speed\n",
    );
    for s in all {
        let q = &s.sanity;
        let _ = writeln!(
            out,
            "\"{}\",{},{},{},{},{},{:.6},{:.6},{:.6},{:.6},{:.6},{},{},{},{},{},{},{},{:.6},{},{},{},{:.6},{:.6}",
            s.scene,
            s.engine,
            s.threads,
            s.sleeping,
            s.runs,
            s.steps,
            s.ms_median,
            s.ms_min,
            s.ms_max,
            s.first200_mean,
            s.settled_median,
            csv_field(s.broadphase_ms),
            csv_field(s.narrowphase_ms),
            csv_field(s.solver_ms),
            csv_field(s.integration_ms),
            csv_field(s.rays_ms),
            s.ray_hits,
            q.bodies,
            q.mean_height,
            q.resting,
            q.below_ground,
            q.non_finite,
            q.max_drift,
            q.max_speed,
        );
    }
    out
}

/// Writes `<stem>.json` (summaries, ray rows and the two-thread control's ratios) and
/// `<stem>.csv` into `dir`.
pub fn write_files(
    dir: &Path,
    stem: &str,
    all: &[Summary],
    rays: &[RayRow],
    control: Option<&Control>,
) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let json = serde_json::json!({ "summaries": all, "rays": rays, "control": control });
    let text = serde_json::to_string_pretty(&json).map_err(|e| e.to_string())?;
    let write = |name: String, text: &str| {
        let path = dir.join(name);
        std::fs::write(&path, text).map_err(|e| format!("{}: {e}", path.display()))
    };
    write(format!("{stem}.json"), &text)?;
    write(format!("{stem}.csv"), &csv(all))
}
