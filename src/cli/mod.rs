//! The `raypack` command line: one file per subcommand.

pub mod args;
mod bench;
mod check;
mod env;
mod error;
mod r#gen;
mod info;
pub mod render;
mod report;
mod robustness;
mod stats;
mod stdout;
mod trace;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::geometry::triangle::TriangleTest;
use crate::simd::Isa;
pub use error::{CliError, CliResult};

/// raypack: a CPU ray tracer built to be measured.
#[derive(Parser, Debug)]
#[command(name = "raypack", version, about)]
pub struct Cli {
    /// Instruction set of the BVH's kernels: auto (the best this CPU has),
    /// portable, avx2 or avx512
    #[arg(long, global = true, default_value = "auto", value_parser = clap::value_parser!(Isa))]
    pub isa: Isa,
    /// Ray/triangle test of every scene loaded: watertight (Woop, Benthin and
    /// Wald 2013: no ray slips between triangles sharing an edge; polygons are
    /// cut into such triangles) or barycentric (the lecture's kernels: the
    /// projected test, and the crossing test for polygons)
    #[arg(long, global = true, value_enum, default_value_t = TriangleTest::default())]
    pub triangle: TriangleTest,
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Measure throughput (kernels, scenes).
    #[command(subcommand)]
    Bench(bench::BenchCommand),
    /// Generate a scene (SPD sphereflake, tetra, fractal mountain; random spheres,
    /// random triangles, terrain) as NFF.
    Gen(r#gen::GenArgs),
    /// Describe the machine and the build: CPU, ISA, huge pages, rustc, flags, commit, Embree.
    Env(env::Args),
    /// Describe a scene file: primitive counts, bounds, camera, lights, materials.
    Info(info::Args),
    /// Compare raypack with Embree ray by ray (needs the `embree` feature).
    Check(check::CheckArgs),
    /// Trace rays from a CSV file and write each nearest hit to a CSV file.
    Trace(trace::TraceArgs),
    /// Render a scene into a timing-annotated PNG.
    Render(render::Args),
    /// Make one self-contained HTML page of charts from `bench … --json` results.
    Report(report::Args),
    /// The robustness oracle: rays with known answers through shared edges and
    /// vertices of closed meshes, grazing, spawned, far and small, against f64.
    Robustness(robustness::RobustnessArgs),
    /// Ray statistics: with --spd, the counts of the SPD's test procedure as JSON.
    Stats(stats::Args),
}

/// Exit code for input the user can fix (bad scene file, unwritable output).
pub const EXIT_BAD_INPUT: u8 = 2;

/// Parse the command line and run it.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    if let Err(e) = Isa::set_default(cli.isa) {
        eprintln!("error: --isa {}: {e}", cli.isa);
        return ExitCode::from(EXIT_BAD_INPUT);
    }
    args::set_triangle_test(cli.triangle);
    // A run stopped by Ctrl-C or `timeout` leaves no temporary output behind.
    if let Err(e) = crate::atomic_file::remove_temporaries_on_signals() {
        eprintln!("warning: cannot watch for signals ({e}): an interrupted run may leave a .tmp file");
    }
    let result = match cli.command {
        Command::Bench(cmd) => bench::run(cmd),
        Command::Gen(args) => r#gen::run(args),
        Command::Env(args) => env::run(args),
        Command::Info(args) => info::run(args),
        Command::Check(args) => check::run(args),
        Command::Trace(args) => trace::run(args),
        Command::Render(args) => render::run(args),
        Command::Report(args) => report::run(args),
        Command::Robustness(args) => robustness::run(args),
        Command::Stats(args) => stats::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(CliError::BadInput(e)) => {
            eprintln!("error: {e:#}");
            ExitCode::from(EXIT_BAD_INPUT)
        }
        Err(CliError::Failed(e)) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
        // The reader stopped early (`| head`): nothing is wrong.
        Err(CliError::StdoutClosed) => ExitCode::SUCCESS,
    }
}
