//! `raypack bench …`: throughput measurements printed as a table or JSON.

use std::path::Path;
use std::time::Duration;

use clap::{Args, Subcommand};

use crate::bench::kernels::{Measure, for_each_setup};
use crate::bench::scene::{PrimaryFrame, Timing, Variant, measure};
use crate::bench::traversal::TraversalRow;
use crate::cli::args::{load_scene, parse_size, scene_camera};
use crate::cli::{CliError, CliResult};
use crate::render::engine::{AccelKind, Engine, WithAccel, with_engine};
use crate::render::{Block, KernelKind};

/// What to measure.
#[derive(Subcommand, Debug)]
pub enum BenchCommand {
    /// Ray-primitive tests per second, scalar vs packet kernels, per primitive.
    Kernels(KernelsArgs),
    /// Primary-ray throughput of a scene per kernel and thread count.
    Scene(SceneArgs),
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
    /// Measure this scene instead (a file such as assets/dragon.ply, or
    /// `gen:NAME[:N[:SEED]]`), with its camera or a framing one.
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
    /// Engines to measure, comma-separated (`embree` needs the `embree` feature);
    /// each engine's time per ray grows from its own first scene.
    #[arg(long, value_enum, value_delimiter = ',', default_value = "raypack")]
    pub engine: Vec<Engine>,
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
        BenchCommand::Scene(args) => scene(args),
        BenchCommand::Traversal(args) => traversal(args),
    }
}

fn traversal(args: TraversalArgs) -> CliResult {
    use crate::bench::traversal::{Builder, TraversalSetup, measure, scene_bounds};
    use crate::scene::generate::random::framing_camera;

    // Ask for the engines before generating scenes: Embree may be missing.
    let first_threads = args.threads.first().copied().unwrap_or(1);
    let mut builder = Builder::new(&args.engine, first_threads).map_err(CliError::BadInput)?;

    let setups: Vec<TraversalSetup> = match &args.file {
        Some(path) => {
            let (scene, _) = load_scene(path)?;
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
    for &threads in &args.threads {
        if builder.threads() != threads.max(1) {
            // Embree's device takes the thread count, and its thread limit is
            // process-wide: the old device goes before the new one is made.
            drop(builder);
            builder = Builder::new(&args.engine, threads).map_err(CliError::Failed)?;
        }
        let measured = measure(&setups, &builder, args.rounds.max(1)).map_err(CliError::Failed)?;
        if !args.json {
            print_traversal(&measured);
        }
        rows.extend(measured);
    }
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&rows).map_err(anyhow::Error::from)?
        );
    } else {
        println!(
            "(best of {} rounds after a warm-up, scenes, engines and variants interleaved round by round; \
             random rays: {} from the scene box, uniform directions; transparent huge pages: {})",
            args.rounds,
            args.random,
            crate::huge_pages::system_mode().as_deref().unwrap_or("unknown")
        );
    }
    Ok(())
}

/// The rows of one thread count as a table, then each engine's growth of time
/// per ray from the first scene, then raypack's speed over Embree's per scene.
fn print_traversal(rows: &[TraversalRow]) {
    for row in rows {
        let counts = match (&row.primary_single_stats, &row.primary_packet_stats) {
            (Some(s), Some(p)) => format!("  [single {}; packet {}]", s.caption(), p.caption()),
            _ => String::new(),
        };
        println!(
            "{:<14} {:>8} prims {:<7} {}t  build {:>7.1} ms  primary {}x{}: single {:>6.2} packet8 {:>6.2} \
             Mrays/s ({:.2}x)  random: single {:>6.2} packet8 {:>6.2} Mrays/s ({:.2}x){counts}",
            row.scene,
            row.primitives,
            engine_name(row.engine),
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
        );
    }
    for engine in [Engine::Raypack, Engine::Embree] {
        let of_engine: Vec<&TraversalRow> = rows.iter().filter(|r| r.engine == engine).collect();
        if let [first, rest @ ..] = of_engine.as_slice() {
            for row in rest {
                let g = &row.growth_vs_first;
                println!(
                    "time per ray, {}, {} -> {} ({}t, same rounds): primary single {:.2}x packet8 {:.2}x, \
                     random single {:.2}x packet8 {:.2}x",
                    engine_name(engine),
                    first.scene,
                    row.scene,
                    row.threads,
                    g.primary_single,
                    g.primary_packet,
                    g.random_single,
                    g.random_packet,
                );
            }
        }
    }
    for ours in rows.iter().filter(|r| r.engine == Engine::Raypack) {
        let theirs = rows
            .iter()
            .find(|r| r.engine == Engine::Embree && r.scene == ours.scene);
        if let Some(theirs) = theirs {
            println!(
                "raypack / Embree Mrays/s, {} ({}t, same rounds): primary single {:.2}x packet8 {:.2}x, \
                 random single {:.2}x packet8 {:.2}x; build time raypack / Embree {:.2}x (both on {}t)",
                ours.scene,
                ours.threads,
                ours.primary_single_mrays / theirs.primary_single_mrays,
                ours.primary_packet_mrays / theirs.primary_packet_mrays,
                ours.random_single_mrays / theirs.random_single_mrays,
                ours.random_packet_mrays / theirs.random_packet_mrays,
                ours.build_s / theirs.build_s,
                ours.threads,
            );
        }
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
    /// Scene file (.nff, .obj, .ply, .ply.gz, .toml), or `gen:NAME[:N[:SEED]]` for a generated scene.
    pub scene: std::path::PathBuf,
    /// Thread counts to measure, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = [1u16, 2], value_parser = clap::value_parser!(u16).range(1..=1024))]
    pub threads: Vec<u16>,
    /// Kernels to measure, comma-separated.
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = [KernelKind::Scalar, KernelKind::Packet8])]
    pub kernel: Vec<KernelKind>,
    /// Acceleration structure.
    #[arg(long, value_enum, default_value_t = AccelKind::Bvh)]
    pub accel: AccelKind,
    /// Engines to measure, comma-separated (`embree` needs the `embree` feature).
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = [Engine::Raypack])]
    pub engine: Vec<Engine>,
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
    /// `raypack` or `embree`.
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
    /// `mrays_per_s` over that of the first row (first engine, kernel, block and thread count).
    pub ratio: f64,
    /// `mrays_per_s` over that of the same engine, kernel and block on the
    /// fewest threads measured (1 by default): the thread scaling.
    pub vs_fewest_threads: f64,
    /// raypack rows: `mrays_per_s` over Embree's on the same kernel width, block
    /// and threads in this run (when Embree was measured).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vs_embree: Option<f64>,
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

fn engine_name(engine: Engine) -> &'static str {
    match engine {
        Engine::Raypack => "raypack",
        Engine::Embree => "embree",
    }
}

fn scene(args: SceneArgs) -> CliResult {
    let (scene, _) = load_scene(&args.scene)?;
    let camera = scene_camera(&scene, Path::new(&args.scene), args.size)?;
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
    let name = args.scene.file_name().unwrap_or(args.scene.as_os_str());
    let name = name.to_string_lossy().into_owned();
    let mut rows: Vec<SceneRow> = Vec::new();
    for &engine in &args.engine {
        let job = SceneJob {
            frame: &frame,
            variants: &variants,
            runs: args.runs,
        };
        let (timings, setup_seconds) = with_engine(&scene, engine, args.accel, job)
            .map_err(CliError::BadInput)?
            .map_err(|e| CliError::Failed(anyhow::anyhow!(e)))?;
        let accel = match engine {
            Engine::Raypack => args.accel.name(),
            Engine::Embree => "embree",
        };
        rows.extend(timings.iter().map(|t| SceneRow {
            scene: name.clone(),
            engine: engine_name(engine),
            kernel: t.variant.kernel.name(),
            accel,
            threads: t.variant.threads,
            mrays_per_s: t.mrays_per_s(),
            median_mrays_per_s: t.rays as f64 / t.median_seconds / 1e6,
            ratio: 0.0,
            vs_fewest_threads: 0.0,
            vs_embree: None,
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
        }));
    }
    // Ratios measured in this one run: against the first row, against the
    // fewest threads of the same variant, and raypack against Embree on the
    // same kernel width, block and threads.
    let base = rows[0].mrays_per_s;
    let all = rows.clone();
    let embree: Vec<SceneRow> = rows.iter().filter(|r| r.engine == "embree").cloned().collect();
    for r in &mut rows {
        r.ratio = r.mrays_per_s / base;
        r.vs_fewest_threads = all
            .iter()
            .filter(|o| o.engine == r.engine && o.kernel == r.kernel && o.block == r.block)
            .min_by_key(|o| o.threads)
            .map_or(1.0, |o| r.mrays_per_s / o.mrays_per_s);
        if r.engine == "raypack" {
            r.vs_embree = embree
                .iter()
                .find(|e| e.kernel == r.kernel && e.threads == r.threads && e.block == r.block)
                .map(|e| r.mrays_per_s / e.mrays_per_s);
        }
    }
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
        "{:<8} {:<8} {:>5} {:>7} {:>10} {:>10} {:>9} {:>12} {:>12} {:>10}",
        "engine",
        "kernel",
        "block",
        "threads",
        "Mrays/s",
        "median",
        "best ms",
        "vs first",
        "vs fewest t",
        "vs embree"
    );
    for r in &rows {
        let vs_embree = r.vs_embree.map_or(String::new(), |x| format!("{x:.2}x"));
        println!(
            "{:<8} {:<8} {:>5} {:>7} {:>10.3} {:>10.3} {:>9.2} {:>11.2}x {:>11.2}x {:>10}",
            r.engine,
            r.kernel,
            r.block,
            r.threads,
            r.mrays_per_s,
            r.median_mrays_per_s,
            r.rays as f64 / r.mrays_per_s / 1e3,
            r.ratio,
            r.vs_fewest_threads,
            vs_embree
        );
    }
    Ok(())
}
