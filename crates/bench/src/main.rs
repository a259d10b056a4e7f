//! The `carom-bench` command: `carom-bench <subcommand> [options]`.

mod midphase;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("midphase") => midphase::run(&args[1..]),
        _ => {
            eprintln!("usage: carom-bench midphase [options]");
            std::process::exit(2);
        }
    }
}
