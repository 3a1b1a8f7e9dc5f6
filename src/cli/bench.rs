//! `raypack bench …`: throughput measurements printed as a table or JSON.

use std::time::Duration;

use clap::{Args, Subcommand};

use crate::bench::kernels::{Measure, for_each_setup};
use crate::cli::{CliError, CliResult};

/// What to measure.
#[derive(Subcommand, Debug)]
pub enum BenchCommand {
    /// Ray-primitive tests per second, scalar vs packet kernels, per primitive.
    Kernels(KernelsArgs),
    /// BVH build time and traversal Mrays/s, single vs 8-ray packets, primary vs random rays.
    Traversal(TraversalArgs),
}

/// Options of `bench traversal`.
#[derive(Args, Debug)]
pub struct TraversalArgs {
    /// Generated scene kind: `mesh` (bumpy-sphere triangles) or `spheres`.
    #[arg(long, default_value = "mesh", value_parser = ["mesh", "spheres"])]
    pub scene: String,
    /// Primitive counts of the generated scenes.
    #[arg(long, value_delimiter = ',', default_value = "1000,10000,100000,1000000")]
    pub sizes: Vec<usize>,
    /// Measure this scene file instead (e.g. assets/dragon.ply), with its camera or a framing one.
    #[arg(long)]
    pub file: Option<std::path::PathBuf>,
    /// Image width of the primary rays.
    #[arg(long, default_value_t = 1024)]
    pub width: u32,
    /// Image height of the primary rays.
    #[arg(long, default_value_t = 1024)]
    pub height: u32,
    /// Random rays per scene.
    #[arg(long, default_value_t = 1 << 20)]
    pub random: usize,
    /// Thread counts to measure with.
    #[arg(long, value_delimiter = ',', default_value = "1")]
    pub threads: Vec<usize>,
    /// Timed rounds per variant (the best is kept).
    #[arg(long, default_value_t = 5)]
    pub rounds: usize,
    /// Print a JSON array instead of a table.
    #[arg(long)]
    pub json: bool,
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
        BenchCommand::Traversal(args) => traversal(args),
    }
}

fn traversal(args: TraversalArgs) -> CliResult {
    use crate::bench::scenes::framing_camera;
    use crate::bench::traversal::{TraversalSetup, measure, scene_bounds};

    let setups: Vec<TraversalSetup> = match &args.file {
        Some(path) => {
            let scene = crate::scene::load(path).map_err(|e| CliError::BadInput(e.into()))?;
            let camera = match scene.camera {
                Some(spec) => spec.camera_at(args.width, args.height),
                None => Ok(framing_camera(
                    scene_bounds(&scene.primitives),
                    args.width,
                    args.height,
                )),
            }
            .map_err(|e| CliError::BadInput(anyhow::anyhow!("{}: {e}", path.display())))?;
            let name = path
                .file_stem()
                .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
            vec![TraversalSetup::new(
                name,
                scene.primitives,
                &camera,
                args.random,
                2,
            )]
        }
        None => args
            .sizes
            .iter()
            .filter_map(|&n| TraversalSetup::generated(&args.scene, n, args.width, args.height, args.random))
            .collect(),
    };
    let mut rows = Vec::new();
    for setup in &setups {
        for &threads in &args.threads {
            let row = measure(setup, threads.max(1), args.rounds.max(1));
            if !args.json {
                let (p, s) = (&row.primary_packet_stats, &row.primary_single_stats);
                println!(
                    "{:<14} {:>8} prims {}t  build {:>7.1} ms  primary {}x{}: single {:>6.2} packet8 {:>6.2} \
                     Mrays/s ({:.2}x)  random: single {:>6.2} packet8 {:>6.2} Mrays/s ({:.2}x)  \
                     [single {}; packet {}]",
                    row.scene,
                    row.primitives,
                    row.threads,
                    1e3 * row.build_s,
                    row.resolution.0,
                    row.resolution.1,
                    row.primary_single_mrays,
                    row.primary_packet_mrays,
                    row.primary_packet_mrays / row.primary_single_mrays,
                    row.random_single_mrays,
                    row.random_packet_mrays,
                    row.random_packet_mrays / row.random_single_mrays,
                    s.caption(),
                    p.caption(),
                );
            }
            rows.push(row);
        }
    }
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&rows).map_err(anyhow::Error::from)?
        );
    } else {
        println!(
            "(BVH; best of {} rounds after a warm-up; random rays: {} from the scene box, uniform directions)",
            args.rounds, args.random
        );
    }
    Ok(())
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
