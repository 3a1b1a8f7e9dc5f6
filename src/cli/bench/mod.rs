//! `raypack bench …`: throughput measurements printed as a table or JSON,
//! stored as baselines and compared against them. One file per bench
//! subcommand; what they share is in [`output`].

mod kernels;
mod matrix;
mod output;
mod scene;
mod traversal;

use clap::Subcommand;

use crate::cli::error::CliResult;

/// What to measure.
#[derive(Subcommand, Debug)]
pub enum BenchCommand {
    /// Ray-primitive tests per second, scalar vs packet kernels, per primitive.
    Kernels(kernels::KernelsArgs),
    /// Primary-ray throughput of a scene per kernel and thread count.
    Scene(scene::SceneArgs),
    /// BVH build time and traversal Mrays/s, single rays vs 8- and 16-ray packets, per ray kind.
    Traversal(traversal::TraversalArgs),
    /// raypack against Embree on every ray kind, scene and thread count of
    /// issue 54's matrix, best path against best path, and the build times
    /// (needs the `embree` feature).
    Matrix(matrix::MatrixArgs),
}

/// Run a bench subcommand.
pub fn run(cmd: BenchCommand) -> CliResult {
    match cmd {
        BenchCommand::Kernels(args) => kernels::run(args),
        BenchCommand::Scene(args) => scene::run(args),
        BenchCommand::Traversal(args) => traversal::run(args),
        BenchCommand::Matrix(args) => matrix::run(args),
    }
}
