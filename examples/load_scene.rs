//! Time scene loading (parsing and building primitives), best and median of N:
//!
//! ```text
//! cargo run --release --example load_scene -- [--rounds N] FILE...
//! ```
//!
//! e.g. `assets/dragon.ply` (binary) and `assets/dragon_vrip.ply.gz` (gzip ASCII)
//! after `scripts/fetch-assets.sh`. Exit code 2 on a file that does not load.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::{Duration, Instant};

use raypack::scene;

fn main() -> ExitCode {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut rounds = 5;
    if let Some(i) = args.iter().position(|a| a == "--rounds") {
        match args
            .get(i + 1)
            .and_then(|n| n.parse().ok())
            .filter(|&n: &usize| n > 0)
        {
            Some(n) => rounds = n,
            None => {
                eprintln!("--rounds needs a positive number");
                return ExitCode::from(2);
            }
        }
        args.drain(i..i + 2);
    }
    if args.is_empty() {
        eprintln!("usage: load_scene [--rounds N] FILE...");
        return ExitCode::from(2);
    }
    for path in args.iter().map(PathBuf::from) {
        let mut times: Vec<Duration> = Vec::with_capacity(rounds);
        let mut primitives = 0;
        for _ in 0..rounds {
            let start = Instant::now();
            match scene::load(&path) {
                Ok(s) => primitives = s.primitives.len(),
                Err(e) => {
                    eprintln!("error: {e}");
                    return ExitCode::from(2);
                }
            }
            times.push(start.elapsed());
        }
        times.sort();
        println!(
            "{}: {primitives} primitives, best {:.3} s, median {:.3} s of {rounds} loads",
            path.display(),
            times[0].as_secs_f64(),
            times[rounds / 2].as_secs_f64()
        );
    }
    ExitCode::SUCCESS
}
