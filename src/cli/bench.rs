//! `raypack bench …`: throughput measurements printed as a table or JSON.

use std::path::PathBuf;
use std::time::Duration;

use clap::{Args, Subcommand};

use crate::bench::kernels::{Measure, for_each_setup};
use crate::bench::scene::{PrimaryFrame, Timing, Variant, measure};
use crate::cli::render::{load_scene, parse_size, scene_camera};
use crate::cli::{CliError, CliResult};
use crate::render::engine::{AccelKind, WithAccel, with_accel};
use crate::render::{Block, KernelKind};

/// What to measure.
#[derive(Subcommand, Debug)]
pub enum BenchCommand {
    /// Ray-primitive tests per second, scalar vs packet kernels, per primitive.
    Kernels(KernelsArgs),
    /// Primary-ray throughput of a scene per kernel and thread count.
    Scene(SceneArgs),
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
        BenchCommand::Scene(args) => scene(args),
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

/// Options of `bench scene`.
#[derive(Args, Debug)]
pub struct SceneArgs {
    /// Scene file.
    pub scene: PathBuf,
    /// Thread counts to measure, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = [1u16, 2], value_parser = clap::value_parser!(u16).range(1..=1024))]
    pub threads: Vec<u16>,
    /// Kernels to measure, comma-separated.
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = [KernelKind::Scalar, KernelKind::Packet8])]
    pub kernel: Vec<KernelKind>,
    /// Acceleration structure.
    #[arg(long, value_enum, default_value_t = AccelKind::None)]
    pub accel: AccelKind,
    /// Pixel blocks per packet to measure, comma-separated.
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = [Block::B4x2])]
    pub block: Vec<Block>,
    /// Tile edge in pixels.
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub tile: u32,
    /// Image size WxH (default: the scene camera's; the fields of view stay the scene's).
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Timed runs per variant (the best is kept).
    #[arg(long, default_value_t = 10, value_parser = clap::value_parser!(u32).range(1..=10000))]
    pub runs: u32,
    /// Print a JSON array instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// One row of `bench scene --json`.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SceneRow {
    /// Scene file name.
    pub scene: String,
    /// Always `raypack`.
    pub engine: &'static str,
    /// Kernel.
    pub kernel: &'static str,
    /// Acceleration structure.
    pub accel: &'static str,
    /// Worker threads.
    pub threads: usize,
    /// Million primary rays per second, best run.
    pub mrays_per_s: f64,
    /// Million primary rays per second, median run.
    pub median_mrays_per_s: f64,
    /// `mrays_per_s` over that of the first variant (first kernel, block and thread count).
    pub ratio: f64,
    /// Ray kind measured.
    pub rays_kind: &'static str,
    /// Rays per run.
    pub rays: u64,
    /// Rays that hit.
    pub hits: u64,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Pixel block per packet.
    pub block: &'static str,
    /// Tile edge.
    pub tile: u32,
    /// Timed runs (best kept).
    pub runs: u32,
    /// Primitives in the scene.
    pub primitives: usize,
    /// Acceleration structure build, ms.
    pub setup_ms: f64,
}

struct SceneJob<'a> {
    frame: &'a PrimaryFrame,
    variants: &'a [Variant],
    runs: u32,
}

impl WithAccel for SceneJob<'_> {
    type Output = Result<(Vec<Timing>, f64), String>;

    fn run<A: crate::accel::Accel>(self, accel: &A, setup_seconds: f64) -> Self::Output {
        Ok((
            measure(accel, self.frame, self.variants, self.runs as usize)?,
            setup_seconds,
        ))
    }
}

fn scene(args: SceneArgs) -> CliResult {
    let (scene, _) = load_scene(&args.scene)?;
    let camera = scene_camera(&scene, &args.scene, args.size)?;
    let frame = PrimaryFrame::new(&camera, args.tile);
    let mut variants = Vec::new();
    for &kernel in &args.kernel {
        for &block in &args.block {
            for &threads in &args.threads {
                variants.push(Variant {
                    kernel,
                    block,
                    threads: usize::from(threads),
                });
            }
        }
    }
    let job = SceneJob {
        frame: &frame,
        variants: &variants,
        runs: args.runs,
    };
    let (timings, setup_seconds) =
        with_accel(&scene, args.accel, job).map_err(|e| CliError::Failed(anyhow::anyhow!(e)))?;
    let name = args.scene.file_name().map_or_else(
        || args.scene.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    let base = timings[0].mrays_per_s();
    let rows: Vec<SceneRow> = timings
        .iter()
        .map(|t| SceneRow {
            scene: name.clone(),
            engine: "raypack",
            kernel: t.variant.kernel.name(),
            accel: args.accel.name(),
            threads: t.variant.threads,
            mrays_per_s: t.mrays_per_s(),
            median_mrays_per_s: t.rays as f64 / t.median_seconds / 1e6,
            ratio: t.mrays_per_s() / base,
            rays_kind: "primary",
            rays: t.rays,
            hits: t.hits,
            width: camera.width,
            height: camera.height,
            block: t.variant.block.name(),
            tile: args.tile,
            runs: args.runs,
            primitives: scene.primitives.len(),
            setup_ms: 1e3 * setup_seconds,
        })
        .collect();
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&rows).map_err(anyhow::Error::from)?
        );
        return Ok(());
    }
    println!(
        "{}: {} primitives, {}x{} primary rays through pixel centres, accel {}, {}px tiles, best of {} runs",
        name,
        scene.primitives.len(),
        camera.width,
        camera.height,
        args.accel.name(),
        args.tile,
        args.runs
    );
    println!(
        "{:<8} {:>5} {:>7} {:>10} {:>10} {:>9} {:>12}",
        "kernel", "block", "threads", "Mrays/s", "median", "best ms", "vs first"
    );
    for r in &rows {
        println!(
            "{:<8} {:>5} {:>7} {:>10.3} {:>10.3} {:>9.2} {:>11.2}x",
            r.kernel,
            r.block,
            r.threads,
            r.mrays_per_s,
            r.median_mrays_per_s,
            r.rays as f64 / r.mrays_per_s / 1e3,
            r.ratio
        );
    }
    Ok(())
}
