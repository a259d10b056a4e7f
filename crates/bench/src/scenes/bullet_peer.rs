//! The Bullet peer of `carom-bench scenes`: exports the scene to JSON (see
//! [`super::export`]), runs `crates/bench/peers/pybullet_scenes.py` with the bench venv's
//! Python (pybullet 3.2.7, `make bench-venv`), and turns its JSON answer into a
//! [`RunRecord`]. The deviations of the pybullet build are listed in the script's docstring.

use super::engine::{initial_states, BodyState, StageTimes};
use super::export::scene_json;
use super::record::RunRecord;
use super::sanity::sanity;
use carom_scenes::Scene;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The peer script, next to this crate's sources.
pub fn script() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("peers/pybullet_scenes.py")
}

/// The bench venv's Python (`<workspace>/.venv-bench/bin/python`).
pub fn default_python() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../.venv-bench/bin/python")
}

/// A Bullet run: the record (single-threaded step and rays) and the ray batch times with all
/// threads (`rayTestBatch(numThreads=0)`).
pub struct BulletRun {
    /// Step and single-threaded ray timings, sanity.
    pub record: RunRecord,
    /// Ray batch times with all threads, ms per step.
    pub ray_ms_mt: Vec<f64>,
}

fn floats(v: &Value, key: &str) -> Result<Vec<f64>, String> {
    v[key]
        .as_array()
        .ok_or_else(|| format!("pybullet output has no {key}"))?
        .iter()
        .map(|x| x.as_f64().ok_or_else(|| format!("bad number in {key}")))
        .collect()
}

fn triples(v: &Value, key: &str) -> Result<Vec<[f64; 3]>, String> {
    v[key]
        .as_array()
        .ok_or_else(|| format!("pybullet output has no {key}"))?
        .iter()
        .map(|t| {
            let f = |k: usize| t[k].as_f64().unwrap_or(f64::NAN);
            Ok([f(0), f(1), f(2)])
        })
        .collect()
}

/// Writes `scene` as JSON into `dir` (once per scene) and returns the file.
pub fn export_to(scene: &Scene, dir: &Path) -> Result<PathBuf, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let file = dir.join(format!("{}.json", scene.name.replace(' ', "_")));
    let text = serde_json::to_string(&scene_json(scene)?).map_err(|e| e.to_string())?;
    std::fs::write(&file, text).map_err(|e| format!("{}: {e}", file.display()))?;
    Ok(file)
}

/// Runs the exported scene `json` in pybullet for `steps` steps.
pub fn run(
    python: &Path,
    scene: &Scene,
    json: &Path,
    steps: usize,
    sleeping: bool,
) -> Result<BulletRun, String> {
    let out = Command::new(python)
        .arg(script())
        .arg(json)
        .args(["--steps", &steps.to_string()])
        .args(["--sleeping", if sleeping { "on" } else { "off" }])
        .output()
        .map_err(|e| format!("{}: {e}", python.display()))?;
    if !out.status.success() {
        return Err(format!(
            "pybullet peer failed on {}: {}",
            scene.name,
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    // pybullet prints a banner on stdout first: the answer is the last line.
    let stdout = String::from_utf8_lossy(&out.stdout);
    let line = stdout.lines().last().unwrap_or_default();
    let v: Value = serde_json::from_str(line).map_err(|e| format!("pybullet output: {e}"))?;
    let positions = triples(&v, "positions")?;
    let velocities = triples(&v, "velocities")?;
    let last: Vec<BodyState> = positions
        .into_iter()
        .zip(velocities)
        .map(|(position, velocity)| BodyState { position, velocity })
        .collect();
    let record = RunRecord {
        scene: scene.name.to_string(),
        engine: "bullet".to_string(),
        threads: 1,
        sleeping,
        step_ms: floats(&v, "step_ms")?,
        ray_ms: floats(&v, "ray_ms")?,
        stages: StageTimes::default(),
        hits: v["hits"].as_u64().unwrap_or(0) as usize,
        sanity: sanity(scene, &initial_states(scene), &last),
    };
    Ok(BulletRun {
        record,
        ray_ms_mt: floats(&v, "ray_ms_mt")?,
    })
}
