//! `carom-bench`: Carom's benchmark command. One subcommand per benchmark, each in its own
//! module; every benchmark runs a peer (rapier3d / parry3d) in the same run and reports
//! ratios and how cost grows with size.

mod broadphase;
mod cdtest;
mod mesh_inputs;
mod midphase;
mod plot;
mod scenes;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "carom-bench",
    about = "Carom benchmarks, with peers in the same run"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Broadphase N-body benchmark (Bullet's CDTestFramework scenario).
    Broadphase(broadphase::Args),
    /// Mesh BVH benchmark: build time, bytes per triangle, ray casts per second vs parry3d.
    Midphase {
        /// Options passed to the midphase benchmark (see its `--help`).
        #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
        args: Vec<String>,
    },
    /// Bullet's benchmark scenes with Carom, Rapier and Bullet (pybullet) side by side.
    Scenes(scenes::Args),
    /// Writes one scene (name or number 1–8) as JSON, the input of the pybullet peer.
    ExportScene {
        /// Scene name ("1000 stack") or number.
        name: String,
        /// Output file (default: stdout).
        #[arg(long)]
        out: Option<std::path::PathBuf>,
    },
}

fn main() {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Broadphase(args) => broadphase::run(&args),
        Command::Midphase { args } => {
            midphase::run(&args);
            Ok(())
        }
        Command::Scenes(args) => scenes::run(&args),
        Command::ExportScene { name, out } => export_scene(&name, out.as_deref()),
    };
    if let Err(e) = result {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn export_scene(name: &str, out: Option<&std::path::Path>) -> Result<(), String> {
    let scene = scenes::find_scene(name).ok_or_else(|| format!("unknown scene {name:?}"))?;
    let text =
        serde_json::to_string(&scenes::export::scene_json(&scene)?).map_err(|e| e.to_string())?;
    match out {
        Some(path) => std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display())),
        None => {
            println!("{text}");
            Ok(())
        }
    }
}
