//! `raypack bench …`: throughput measurements printed as a table or JSON.

use std::path::Path;
use std::time::Duration;

use clap::{Args, Subcommand};

use crate::bench::kernels::{Measure, for_each_setup};
use crate::bench::rays::{RayKind, RaySet, RaySource, default_light};
use crate::bench::scene::{PrimaryFrame, Timing, Variant, measure, measure_set};
use crate::bench::traversal::{EngineVariant, TraversalRow, scene_bounds};
use crate::cli::args::{load_scene, parse_size, scene_camera};
use crate::cli::{CliError, CliResult};
use crate::engine::EmbreeIsa;
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
    /// The scene to measure (a file such as assets/dragon.ply, or
    /// `gen:NAME[:N[:SEED]]`), with its camera or a framing one; without it, a
    /// family of generated scenes of `--sizes` primitives.
    pub scene: Option<std::path::PathBuf>,
    /// Generated scene family when no SCENE is given: `mesh` (bumpy-sphere
    /// triangles) or `spheres`.
    #[arg(long, default_value = "mesh", value_parser = ["mesh", "spheres"])]
    pub generated: String,
    /// Primitive counts of the generated scenes.
    #[arg(long, value_delimiter = ',', default_value = "1000,10000,100000,1000000")]
    pub sizes: Vec<usize>,
    /// Image size of the primary rays, WIDTHxHEIGHT.
    #[arg(long, value_parser = parse_size, default_value = "1024x1024")]
    pub size: (u32, u32),
    /// Random rays per scene.
    #[arg(long, default_value_t = 1 << 20)]
    pub random: usize,
    /// Ray kinds to measure, comma-separated: `primary`, `shadow` (any hit, to
    /// the scene's first light or a point above its box), `ao` (any hit,
    /// cosine-distributed, a tenth of the box's diagonal long), `diffuse`
    /// (nearest hit, cosine-distributed) and `random`.
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = RayKind::ALL)]
    pub rays: Vec<RayKind>,
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
    /// Embree's kernels, comma-separated, each measured as an engine of its
    /// own: `avx2` (8-wide, as raypack's packets) and `default` (Embree's own
    /// choice for the CPU, AVX-512 where there is one).
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = [EmbreeIsa::Avx2, EmbreeIsa::Default])]
    pub embree_isa: Vec<EmbreeIsa>,
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
    use crate::bench::traversal::{Builder, TraversalSetup, measure};
    use crate::scene::generate::random::framing_camera;

    // Ask for the engines before generating scenes: Embree may be missing.
    let first_threads = args.threads.first().copied().unwrap_or(1);
    let mut builder =
        Builder::new(&args.engine, &args.embree_isa, first_threads).map_err(CliError::BadInput)?;

    let (width, height) = args.size;
    let setups: Vec<TraversalSetup> = match &args.scene {
        Some(path) => {
            let (scene, _) = load_scene(path)?;
            let camera = match scene.camera {
                Some(spec) => spec.camera_at(width, height),
                None => Ok(framing_camera(scene_bounds(&scene.primitives), width, height)),
            }
            .map_err(|e| CliError::BadInput(anyhow::anyhow!("{}: {e}", path.display())))?;
            let name = path
                .file_stem()
                .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
            let light = scene.lights.first().map(|l| l.position);
            vec![TraversalSetup::new(
                name,
                scene.primitives,
                &camera,
                light,
                args.random,
                &args.rays,
            )]
        }
        None => args
            .sizes
            .iter()
            .filter_map(|&n| {
                TraversalSetup::generated(&args.generated, n, args.size, args.random, &args.rays)
            })
            .collect(),
    };
    let mut rows = Vec::new();
    for &threads in &args.threads {
        if builder.threads() != threads.max(1) {
            // Embree's device takes the thread count, and its thread limit is
            // process-wide: the old device goes before the new one is made.
            drop(builder);
            builder = Builder::new(&args.engine, &args.embree_isa, threads).map_err(CliError::Failed)?;
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
            "(best of {} rounds after a warm-up, scenes, engines, ray kinds and variants interleaved round by \
             round; random rays: {} from the scene box, uniform directions; secondary rays from the primary \
             hits; transparent huge pages: {})",
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
        let sah = row
            .sah_cost
            .map_or(String::new(), |c| format!("  SAH cost {c:.1}"));
        println!(
            "{:<14} {:>8} prims {:<7} {}t  build {:>7.1} ms{sah}  primary rays {}x{}",
            row.scene,
            row.primitives,
            row.variant().name(),
            row.threads,
            1e3 * row.build_s,
            row.resolution.0,
            row.resolution.1,
        );
        for k in &row.kinds {
            let counts = match (&k.single_stats, &k.packet_stats) {
                (Some(s), Some(p)) => format!("  [single {}; packet {}]", s.caption(), p.caption()),
                _ => String::new(),
            };
            println!(
                "  {:<8} {:>8} rays {:>5.1}% hit: single {:>6.2} packet8 {:>6.2} Mrays/s ({:.2}x){counts}",
                k.kind.name(),
                k.rays,
                100.0 * k.hits as f64 / k.rays.max(1) as f64,
                k.single_mrays,
                k.packet_mrays,
                k.packet_mrays / k.single_mrays,
            );
        }
    }
    let mut variants: Vec<EngineVariant> = Vec::new();
    for row in rows {
        if !variants.contains(&row.variant()) {
            variants.push(row.variant());
        }
    }
    for variant in variants {
        let of_engine: Vec<&TraversalRow> = rows.iter().filter(|r| r.variant() == variant).collect();
        if let [first, rest @ ..] = of_engine.as_slice() {
            for row in rest {
                let kinds: Vec<String> = row
                    .kinds
                    .iter()
                    .map(|k| {
                        let [single, packet] = k.growth_vs_first;
                        format!("{} single {single:.2}x packet8 {packet:.2}x", k.kind.name())
                    })
                    .collect();
                println!(
                    "time per ray, {}, {} -> {} ({}t, same rounds): {}",
                    variant.name(),
                    first.scene,
                    row.scene,
                    row.threads,
                    kinds.join(", "),
                );
            }
        }
    }
    print_growth_against_embree(rows);
    for ours in rows.iter().filter(|r| r.engine == Engine::Raypack) {
        let theirs: Vec<&TraversalRow> = rows
            .iter()
            .filter(|r| r.engine == Engine::Embree && r.scene == ours.scene)
            .collect();
        let Some(fastest_build) = theirs.iter().map(|r| r.build_s).reduce(f64::min) else {
            continue;
        };
        println!(
            "raypack / Embree, {} ({}t, same rounds): build time {:.2}x against Embree's faster setting (both on {}t)",
            ours.scene,
            ours.threads,
            ours.build_s / fastest_build,
            ours.threads,
        );
        for (k, ours_k) in ours.kinds.iter().enumerate() {
            let (best_a, path_a) = ours_k.best();
            let (best_b, path_b) = best_embree(&theirs, k);
            let ratios: Vec<String> = theirs
                .iter()
                .map(|r| {
                    let b = &r.kinds[k];
                    format!(
                        "vs {}: single {:.2}x packet8 {:.2}x",
                        r.variant().name(),
                        ours_k.single_mrays / b.single_mrays,
                        ours_k.packet_mrays / b.packet_mrays
                    )
                })
                .collect();
            println!(
                "  {:<8} Mrays/s {}; best {:.2}x (raypack {path_a} {best_a:.2} vs {path_b} {best_b:.2})",
                ours_k.kind.name(),
                ratios.join("; "),
                best_a / best_b,
            );
        }
    }
}

/// Embree's best path on kind `k` over the rows of its settings: Mrays/s and
/// which it was (`embree(avx2) packet8`…).
fn best_embree(rows: &[&TraversalRow], k: usize) -> (f64, String) {
    rows.iter()
        .map(|r| {
            let (mrays, path) = r.kinds[k].best();
            (mrays, format!("{} {path}", r.variant().name()))
        })
        .fold((0.0, String::new()), |a, b| if b.0 > a.0 { b } else { a })
}

/// Per ray kind, how the time per ray of each engine's best path (single rays
/// or packets, whichever is faster on each scene; for Embree also the faster
/// of its ISA settings) grows from the first scene to each later one,
/// raypack's growth beside Embree's.
fn print_growth_against_embree(rows: &[TraversalRow]) {
    let ours: Vec<&TraversalRow> = rows.iter().filter(|r| r.engine == Engine::Raypack).collect();
    let theirs_on = |scene: &str| -> Vec<&TraversalRow> {
        rows.iter()
            .filter(|r| r.engine == Engine::Embree && r.scene == scene)
            .collect()
    };
    let Some(our_first) = ours.first() else { return };
    let their_first = theirs_on(&our_first.scene);
    if their_first.is_empty() {
        return;
    }
    for our_row in ours.iter().skip(1) {
        let theirs = theirs_on(&our_row.scene);
        if theirs.is_empty() {
            continue;
        }
        let kinds: Vec<String> = (0..our_row.kinds.len())
            .map(|k| {
                let ours = our_first.kinds[k].best().0 / our_row.kinds[k].best().0;
                let theirs = best_embree(&their_first, k).0 / best_embree(&theirs, k).0;
                format!(
                    "{} {ours:.2}x vs {theirs:.2}x ({:+.0}%)",
                    our_row.kinds[k].kind.name(),
                    100.0 * (ours / theirs - 1.0)
                )
            })
            .collect();
        println!(
            "growth of time per ray (best path), raypack vs Embree, {} -> {} ({}t): {}",
            our_first.scene,
            our_row.scene,
            our_row.threads,
            kinds.join(", ")
        );
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
    /// Ray kinds to measure, comma-separated (see `bench traversal --rays`):
    /// primary rays go through the tile scheduler in the blocks asked for, the
    /// others one by one (scalar) or in their 4×2-pixel packets (packet8).
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = RayKind::ALL)]
    pub rays: Vec<RayKind>,
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
    /// `mrays_per_s` over that of the first row of the same ray kind (first
    /// engine, kernel, block and thread count).
    pub ratio: f64,
    /// `mrays_per_s` over that of the same engine, kernel, block and ray kind
    /// on the fewest threads measured (1 by default): the thread scaling.
    pub vs_fewest_threads: f64,
    /// raypack rows: `mrays_per_s` over Embree's on the same kernel width, block,
    /// threads and ray kind in this run (when Embree was measured).
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
    /// The primary rays, if measured.
    frame: Option<&'a PrimaryFrame>,
    variants: &'a [Variant],
    /// The other ray kinds, and their variants (4×2 blocks).
    sets: &'a [RaySet],
    set_variants: &'a [Variant],
    runs: u32,
}

impl WithAccel for SceneJob<'_> {
    type Output = Result<(Vec<(RayKind, Timing)>, f64), String>;

    fn run<A: crate::accel::Accel>(self, accel: &A, setup_seconds: f64) -> Self::Output {
        let runs = self.runs as usize;
        let mut timings = Vec::new();
        if let Some(frame) = self.frame {
            let primary = measure(accel, frame, self.variants, runs)?;
            timings.extend(primary.into_iter().map(|t| (RayKind::Primary, t)));
        }
        for set in self.sets {
            let measured = measure_set(accel, set, self.set_variants, runs)?;
            timings.extend(measured.into_iter().map(|t| (set.kind, t)));
        }
        Ok((timings, setup_seconds))
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
    // The other kinds start from the primary hits (or the box): made once for every engine.
    let mut others: Vec<RayKind> = Vec::new();
    for &kind in &args.rays {
        if kind != RayKind::Primary && !others.contains(&kind) {
            others.push(kind);
        }
    }
    let sets = if others.is_empty() {
        Vec::new()
    } else {
        let bounds = scene_bounds(&scene.primitives);
        RaySource {
            prims: &scene.primitives,
            bounds,
            camera: &camera,
            light: scene
                .lights
                .first()
                .map_or_else(|| default_light(bounds), |l| l.position),
            random: camera.width as usize * camera.height as usize,
            seed: 2,
        }
        .make(&others)
    };
    let mut set_variants: Vec<Variant> = Vec::new();
    for &kernel in &args.kernel {
        for &threads in &args.threads {
            set_variants.push(Variant {
                kernel,
                block: Block::B4x2,
                threads: usize::from(threads),
            });
        }
    }
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
            frame: args.rays.contains(&RayKind::Primary).then_some(&frame),
            variants: &variants,
            sets: &sets,
            set_variants: &set_variants,
            runs: args.runs,
        };
        let (timings, setup_seconds) = with_engine(&scene, engine, args.accel, job)
            .map_err(CliError::BadInput)?
            .map_err(|e| CliError::Failed(anyhow::anyhow!(e)))?;
        let accel = match engine {
            Engine::Raypack => args.accel.name(),
            Engine::Embree => "embree",
        };
        rows.extend(timings.iter().map(|(kind, t)| SceneRow {
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
            rays_kind: kind.name(),
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
    // Ratios measured in this one run, within a ray kind: against its first
    // row, against the fewest threads of the same variant, and raypack against
    // Embree on the same kernel width, block and threads.
    let all = rows.clone();
    for r in &mut rows {
        let same_kind = all.iter().filter(|o| o.rays_kind == r.rays_kind);
        let same_variant = |o: &&SceneRow| o.kernel == r.kernel && o.block == r.block;
        r.ratio = same_kind
            .clone()
            .next()
            .map_or(1.0, |o| r.mrays_per_s / o.mrays_per_s);
        r.vs_fewest_threads = same_kind
            .clone()
            .filter(|o| o.engine == r.engine && same_variant(o))
            .min_by_key(|o| o.threads)
            .map_or(1.0, |o| r.mrays_per_s / o.mrays_per_s);
        if r.engine == "raypack" {
            r.vs_embree = same_kind
                .filter(|o| o.engine == "embree" && same_variant(o) && o.threads == r.threads)
                .map(|e| r.mrays_per_s / e.mrays_per_s)
                .next();
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
        "{}: {} primitives, {}x{} primary rays through pixel centres (other kinds from their hits), accel {}, \
         {}px tiles, best of {} runs",
        name,
        scene.primitives.len(),
        camera.width,
        camera.height,
        args.accel.name(),
        args.tile,
        args.runs
    );
    println!(
        "{:<8} {:<8} {:<8} {:>5} {:>7} {:>10} {:>10} {:>9} {:>12} {:>12} {:>10}",
        "rays",
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
            "{:<8} {:<8} {:<8} {:>5} {:>7} {:>10.3} {:>10.3} {:>9.2} {:>11.2}x {:>11.2}x {:>10}",
            r.rays_kind,
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
