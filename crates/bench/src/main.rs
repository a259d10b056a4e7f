//! `carom-bench`: Carom's benchmark command. One subcommand per benchmark, each in its own
//! module; every benchmark runs a peer (rapier3d / parry3d) in the same run and reports
//! ratios and how cost grows with size.

mod broadphase;
mod cdtest;
mod midphase;
mod plot;

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
}

fn main() {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Broadphase(args) => broadphase::run(&args),
        Command::Midphase { args } => {
            midphase::run(&args);
            Ok(())
        }
    };
    if let Err(e) = result {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}
