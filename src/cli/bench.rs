//! `raypack bench …`: throughput measurements printed as a table or JSON.

use std::time::Duration;

use clap::{Args, Subcommand};

use crate::bench::kernels::{Measure, for_each_setup};
use crate::cli::CliResult;

/// What to measure.
#[derive(Subcommand, Debug)]
pub enum BenchCommand {
    /// Ray-primitive tests per second, scalar vs packet kernels, per primitive.
    Kernels(KernelsArgs),
}

/// Options of `bench kernels`.
#[derive(Args, Debug)]
pub struct KernelsArgs {
    /// Print a JSON array instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Rays per primitive.
    #[arg(long, default_value_t = 4096)]
    pub rays: usize,
    /// Timed samples per variant (the best is kept).
    #[arg(long, default_value_t = 5)]
    pub rounds: usize,
    /// Milliseconds per sample.
    #[arg(long, default_value_t = 20)]
    pub sample_ms: u64,
    /// Seed of the random rays.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

/// Run a bench subcommand.
pub fn run(cmd: BenchCommand) -> CliResult {
    match cmd {
        BenchCommand::Kernels(args) => kernels(args),
    }
}

fn kernels(args: KernelsArgs) -> CliResult {
    let mut measure = Measure {
        sample: Duration::from_millis(args.sample_ms),
        rounds: args.rounds.max(1),
        rows: Vec::new(),
    };
    for_each_setup(args.rays.max(1), args.seed, &mut measure);
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&measure.rows).map_err(anyhow::Error::from)?
        );
        return Ok(());
    }
    println!(
        "{:<20} {:>14} {:>14} {:>8} {:>14} {:>14} {:>6}",
        "primitive", "scalar/s", "packet8/s", "ratio", "packet4/s", "packet16/s", "hits"
    );
    for r in &measure.rows {
        println!(
            "{:<20} {:>14.3e} {:>14.3e} {:>7.2}x {:>14.3e} {:>14.3e} {:>5.0}%",
            r.primitive,
            r.scalar_per_s,
            r.packet8_per_s,
            r.ratio,
            r.packet4_per_s,
            r.packet16_per_s,
            100.0 * r.hit_rate
        );
    }
    println!(
        "({} rays per primitive, best of {} samples of {} ms, one thread)",
        args.rays, args.rounds, args.sample_ms
    );
    Ok(())
}
