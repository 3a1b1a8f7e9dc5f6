//! `raypack bench kernels`: ray-primitive tests per second of every shape's
//! scalar and packet kernels, and the packet/scalar ratio, per primitive.

use std::time::Duration;

use clap::Args;

use crate::bench::kernels::{KernelRow, Measure, for_each_setup};
use crate::cli::bench::output::{Output, Run, figure};
use crate::cli::error::CliResult;
use crate::cli::stdout::outln;

/// Options of `bench kernels`.
#[derive(Args, Debug)]
pub struct KernelsArgs {
    /// Rays per primitive.
    #[arg(long, default_value_t = 4096)]
    pub rays: usize,
    /// Timed samples per variant, interleaved (a 95% interval needs 6 or more).
    #[arg(long, default_value_t = 12)]
    pub rounds: usize,
    /// Milliseconds per sample.
    #[arg(long, default_value_t = 20)]
    pub sample_ms: u64,
    /// Seed of the random rays.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Output and baselines.
    #[command(flatten)]
    pub output: Output,
}

/// Measure and report.
pub fn run(args: KernelsArgs) -> CliResult {
    let run = Run::start(&args.output, "kernels")?;
    let mut measure = Measure {
        sample: Duration::from_millis(args.sample_ms),
        rounds: args.rounds.max(1),
        hooks: run.hooks.clone(),
        rows: Vec::new(),
    };
    for_each_setup(args.rays.max(1), args.seed, &mut measure);
    let figures = measure.rows.iter().flat_map(KernelRow::figures).collect();
    run.finish(measure.rows, figures, None, |rows| {
        print_table(rows)?;
        outln!(
            "({} rays per primitive, {} samples of {} ms per variant after a warm-up, interleaved, one thread)",
            args.rays, args.rounds, args.sample_ms
        )
    })
}

fn print_table(rows: &[KernelRow]) -> CliResult {
    outln!(
        "{:<20} {:>17} {:>17} {:>13} {:>17} {:>17} {:>6}",
        "primitive",
        "scalar Mtests/s",
        "packet8 Mtests/s",
        "ratio",
        "packet4",
        "packet16",
        "hits"
    )?;
    let mega = |s: crate::statistics::Summary| figure(&s.scaled(1e-6), 1, "");
    for r in rows {
        outln!(
            "{:<20} {:>17} {:>17} {:>13} {:>17} {:>17} {:>5.0}%",
            r.primitive,
            mega(r.scalar_per_s),
            mega(r.packet8_per_s),
            figure(&r.ratio, 2, "x"),
            mega(r.packet4_per_s),
            mega(r.packet16_per_s),
            100.0 * r.hit_rate
        )?;
    }
    Ok(())
}
