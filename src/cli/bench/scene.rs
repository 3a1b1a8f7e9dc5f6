//! `raypack bench scene`: a scene's throughput per ray kind, engine, kernel,
//! pixel block and thread count, with the ratios between them taken run by run.

use std::path::Path;

use clap::Args;

use crate::accel::AccelKind;
use crate::bench::callgrind;
use crate::bench::figure::{Better, Figure};
use crate::bench::rays::{KindRays, Query, RayKind, RaySource, default_light};
use crate::bench::scene::{PrimaryFrame, Rays, Timing, Unit, Variant, interleave, units};
use crate::bench::timing_hooks::TimingHooks;
use crate::bench::traversal::{EngineVariant, engine_variants, scene_bounds};
use crate::cli::args::{engine_error, load_scene, parse_size, scene_camera};
use crate::cli::bench::output::{Output, Run, figure};
use crate::cli::error::{CliError, CliResult};
use crate::cli::stdout::outln;
use crate::embree_settings::EmbreeIsa;
use crate::engines::{Engine, EngineOptions, WithAccel};
use crate::render::{Block, KernelKind};
use crate::scene::Scene;
use crate::statistics::{StatsError, Summary};

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
    /// Embree's ISA settings to measure with `--engine embree`,
    /// comma-separated; raypack's rows are compared with the faster.
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = [EmbreeIsa::Avx2, EmbreeIsa::Default])]
    pub embree_isa: Vec<EmbreeIsa>,
    /// Pixel blocks per batch (one 16-wide packet, or two 8-wide) to measure, comma-separated.
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = [Block::B4x4])]
    pub block: Vec<Block>,
    /// Tile edge in pixels.
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub tile: u32,
    /// Image size WxH (default: the scene camera's; the fields of view stay the scene's).
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Timed runs per variant, interleaved (a 95% interval needs 6 or more).
    #[arg(long, default_value_t = 10, value_parser = clap::value_parser!(u32).range(1..=10000))]
    pub runs: u32,
    /// Ray kinds to measure, comma-separated (see `bench traversal --rays`):
    /// primary rays go through the tile scheduler in the blocks asked for, the
    /// others one by one (scalar) or in their packets of 4×2 pixels (packet8)
    /// or 4×4 (packet16).
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = RayKind::ALL)]
    pub rays: Vec<RayKind>,
    /// Also count the instructions per ray of every engine, ray kind, kernel
    /// and block, at one thread: the run repeats under callgrind (valgrind),
    /// which is slow, and executes AVX2 code there (valgrind has no AVX-512).
    #[arg(long)]
    pub instructions: bool,
    /// Output and baselines.
    #[command(flatten)]
    pub output: Output,
}

/// One row of `bench scene --json`: the throughput of one variant (its
/// median, interval and samples inline) and its ratios to others of the same
/// ray kind, each from the two variants' runs paired round by round.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SceneRow {
    /// Scene file name.
    pub scene: String,
    /// `raypack`, or Embree with its ISA setting: `embree(avx2)`, `embree(default)`.
    pub engine: String,
    /// Kernel.
    pub kernel: &'static str,
    /// Acceleration structure.
    pub accel: &'static str,
    /// Worker threads.
    pub threads: usize,
    /// The unit of the row's figures: `Mrays/s`.
    pub unit: &'static str,
    /// Million rays per second: median, interval, spread, samples, noise flag.
    #[serde(flatten)]
    pub mrays_per_s: Summary,
    /// Over the first row of the same ray kind (first engine, kernel, block
    /// and thread count).
    pub ratio: Summary,
    /// Over the same engine, kernel, block and ray kind on the fewest threads
    /// measured (1 by default): the thread scaling.
    pub vs_fewest_threads: Summary,
    /// raypack rows: over Embree's on the same kernel width, block, threads
    /// and ray kind (when Embree was measured), the faster of its ISA
    /// settings there (by median).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vs_embree: Option<Summary>,
    /// The Embree setting of `vs_embree`: `embree(avx2)` or `embree(default)`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vs_embree_engine: Option<String>,
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
    /// Pixel block per batch.
    pub block: &'static str,
    /// Tile edge.
    pub tile: u32,
    /// Timed runs.
    pub runs: u32,
    /// Primitives in the scene.
    pub primitives: usize,
    /// Acceleration structure build, ms.
    pub setup_ms: f64,
    /// Instructions per ray at one thread, counted by callgrind (`--instructions`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub instructions_per_ray: Option<f64>,
}

impl SceneRow {
    /// The row's figures: its throughput and its ratios.
    fn figures(&self) -> Vec<Figure> {
        let labels = [
            ("scene", self.scene.clone()),
            ("rays", self.rays_kind.to_string()),
            ("engine", self.engine.to_string()),
            ("kernel", self.kernel.to_string()),
            ("block", self.block.to_string()),
            ("threads", self.threads.to_string()),
        ];
        let mut figures = vec![
            Figure::new("throughput", "Mrays/s", Better::Higher, &labels, self.mrays_per_s),
            Figure::new("vs first row", "x", Better::Neither, &labels, self.ratio),
            Figure::new(
                "vs fewest threads",
                "x",
                Better::Neither,
                &labels,
                self.vs_fewest_threads,
            ),
        ];
        if let Some(vs) = self.vs_embree {
            figures.push(Figure::new("raypack/embree", "x", Better::Neither, &labels, vs));
        }
        figures
    }
}

/// What `bench scene` measures: per ray kind, every variant on every engine.
struct MeasurementPlan<'a> {
    /// The primary rays, if measured.
    frame: Option<&'a PrimaryFrame>,
    variants: &'a [Variant],
    /// The other ray kinds, and their variants (4×4 blocks).
    kind_rays: &'a [KindRays],
    kind_variants: &'a [Variant],
    runs: usize,
    hooks: &'a TimingHooks,
    /// The engines measured, in the order of their units' numbers.
    engines: &'a [EngineVariant],
}

/// Builds one engine's units for some rays and variants, as its number.
type UnitsOf<'x> = dyn Fn(Rays<'x>, &[Variant], usize) -> Result<Vec<Unit<'x>>, String> + 'x;

impl MeasurementPlan<'_> {
    /// The engine of each unit number (Embree once per ISA setting).
    fn engine_families(&self) -> Vec<Engine> {
        self.engines.iter().map(|v| v.engine).collect()
    }

    /// The ray kinds measured, each with its rays and its variants.
    fn kinds(&self) -> Vec<(RayKind, Rays<'_>, &[Variant])> {
        let mut kinds: Vec<(RayKind, Rays<'_>, &[Variant])> = Vec::new();
        if let Some(frame) = self.frame {
            kinds.push((RayKind::Primary, Rays::Primary(frame), self.variants));
        }
        kinds.extend(
            self.kind_rays
                .iter()
                .map(|s| (s.kind, Rays::OfKind(s), self.kind_variants)),
        );
        kinds
    }

    /// The variants of `variants` that engine `e` traces for `kind`: only the
    /// kernels it traces as such, and only the queries it has (see `run`'s notes).
    fn traced(&self, e: usize, kind: RayKind, variants: &[Variant]) -> Vec<Variant> {
        let engine = self.engines[e].engine;
        let answers = kind.query() == Query::Nearest || engine.finds_any_hit().is_ok();
        variants
            .iter()
            .copied()
            .filter(|v| answers && engine.traces_lanes(v.kernel.lanes()).is_ok())
            .collect()
    }

    /// Per ray kind, the variants of every engine of `engines` interleaved in one set of rounds.
    fn measure<'x>(&'x self, engines: &[&UnitsOf<'x>]) -> Result<Vec<(usize, RayKind, Timing)>, String> {
        let mut out = Vec::new();
        for (kind, rays, variants) in self.kinds() {
            let mut all = Vec::new();
            for (e, units_of) in engines.iter().enumerate() {
                all.extend(units_of(rays, &self.traced(e, kind, variants), e)?);
            }
            let timings = interleave(&all, &self.engine_families(), self.runs, self.hooks, rays.count())?;
            out.extend(all.iter().zip(timings).map(|(u, t)| (u.engine, kind, t)));
        }
        Ok(out)
    }

    /// In the run under callgrind (`--instructions`): every engine's variants
    /// of every ray kind traced once on one thread, each between a reset of
    /// callgrind's counts and a dump named by [`count_label`] (a variant at
    /// several thread counts once).
    fn count_instructions<'x>(&'x self, engines: &[&UnitsOf<'x>]) -> Result<(), String> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .map_err(|e| e.to_string())?;
        Engine::prepare_threads(&self.engine_families(), &pool);
        let mut counted: Vec<String> = Vec::new();
        for (kind, rays, variants) in self.kinds() {
            for (e, units_of) in engines.iter().enumerate() {
                for unit in units_of(rays, &self.traced(e, kind, variants), e)? {
                    let label = count_label(self.engines[e], kind, unit.variant);
                    if counted.contains(&label) {
                        continue;
                    }
                    callgrind::zero_stats();
                    std::hint::black_box((unit.trace)(&pool));
                    callgrind::dump_stats_at(&label);
                    counted.push(label);
                }
            }
        }
        Ok(())
    }
}

/// The name of the count of `engine`'s `variant` on `kind` rays (its thread
/// count aside: counts are taken on one thread).
fn count_label(engine: EngineVariant, kind: RayKind, variant: Variant) -> String {
    format!(
        "{}/{}/{}/{}",
        engine.name(),
        kind.name(),
        variant.kernel.name(),
        variant.block.name()
    )
}

/// An engine's structure as a maker of timed units ([`units`]) for the plan.
struct UnitsJob;

impl<'s> WithAccel<'s> for UnitsJob {
    type Output = Box<UnitsOf<'s>>;

    fn run<A: crate::accel::Accel + 's>(self, accel: &'s A) -> Self::Output {
        Box::new(move |rays, variants, engine| units(accel, rays, variants, engine))
    }
}

/// Measure and report.
pub fn run(args: SceneArgs) -> CliResult {
    let run = Run::start(&args.output, "scene")?;
    // Where instructions cannot be counted, say why before measuring.
    let no_counts = args.instructions.then(callgrind::unavailable).flatten();
    if let Some(why) = &no_counts {
        eprintln!("note: instructions per ray n/a: {why}");
    }
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
    let kind_rays = if others.is_empty() {
        Vec::new()
    } else {
        let bounds = scene_bounds(&scene);
        RaySource {
            scene: &scene,
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
    let mut kind_variants: Vec<Variant> = Vec::new();
    for &kernel in &args.kernel {
        for &threads in &args.threads {
            kind_variants.push(Variant {
                kernel,
                block: Block::B4x4,
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
    // Every engine's structure is built first, so that their variants
    // interleave; an engine that cannot take the scene, or a kernel it does not
    // trace, is left out with a note (all of them out: the user's to change).
    let mut engines: Vec<Engine> = Vec::new();
    let mut left_out = Vec::new();
    for &engine in &args.engine {
        match engine.takes_scene(&scene) {
            _ if engines.contains(&engine) => {}
            Ok(()) => engines.push(engine),
            Err(na) => left_out.push(na.to_string()),
        }
    }
    if engines.is_empty() {
        return Err(CliError::BadInput(anyhow::anyhow!(left_out.join("; "))));
    }
    for &engine in &engines {
        for &kernel in &args.kernel {
            if let Err(na) = engine.traces_lanes(kernel.lanes()) {
                left_out.push(format!("{na}: no {engine} {} rows", kernel.name()));
            }
        }
    }
    for &engine in &engines {
        let any_hit: Vec<&str> = others
            .iter()
            .filter(|k| k.query() == Query::AnyHit)
            .map(|k| k.name())
            .collect();
        if let (Err(na), false) = (engine.finds_any_hit(), any_hit.is_empty()) {
            left_out.push(format!("{na}: no {engine} {} rows", any_hit.join(", ")));
        }
    }
    for note in &left_out {
        eprintln!("note: {note}");
    }
    // Embree once per ISA setting asked for.
    let engines = engine_variants(&engines, &args.embree_isa).map_err(CliError::BadInput)?;
    let plan = MeasurementPlan {
        frame: args.rays.contains(&RayKind::Primary).then_some(&frame),
        variants: &variants,
        kind_rays: &kind_rays,
        kind_variants: &kind_variants,
        runs: args.runs as usize,
        hooks: &run.hooks,
        engines: &engines,
    };
    // Embree's devices build on one thread (`threads=1`) at every ISA setting.
    let devices = engines
        .iter()
        .map(|v| {
            v.engine.device(&EngineOptions {
                accel: args.accel,
                ..v.options(1)
            })
        })
        .collect::<anyhow::Result<Vec<_>>>()
        .map_err(CliError::BadInput)?;
    let mut built = Vec::new();
    let mut setup_seconds = Vec::new();
    for device in &devices {
        let (structure, seconds) = device.build_timed(&scene).map_err(engine_error)?;
        built.push(structure);
        setup_seconds.push(seconds);
    }
    let structures: Vec<&'static str> = built.iter().map(|b| b.describe().structure).collect();
    let timings = {
        let makers: Vec<Box<UnitsOf<'_>>> = built.iter().map(|b| b.visit(UnitsJob)).collect();
        let makers: Vec<&UnitsOf<'_>> = makers.iter().map(|m| &**m).collect();
        let failed = |e: String| CliError::Failed(anyhow::anyhow!(e));
        if callgrind::is_counting_child() {
            return plan.count_instructions(&makers).map_err(failed);
        }
        plan.measure(&makers).map_err(failed)?
    };
    let counts = match &no_counts {
        None if args.instructions => Some(callgrind::count_this_command().map_err(CliError::Failed)?),
        _ => None,
    };
    let measured: Vec<Measured> = timings
        .into_iter()
        .map(|(e, kind, timing)| Measured {
            engine: engines[e],
            structure: structures[e],
            kind,
            mrays: timing.mrays(),
            timing,
            setup_seconds: setup_seconds[e],
        })
        .collect();
    let rows = measured
        .iter()
        .map(|m| {
            let Ratios {
                first: ratio,
                fewest_threads: vs_fewest_threads,
                vs_embree,
            } = ratios(m, &measured)?;
            let (vs_embree, vs_embree_engine) = vs_embree.unzip();
            Ok(SceneRow {
                scene: name.clone(),
                engine: m.engine.name(),
                kernel: m.timing.variant.kernel.name(),
                accel: m.structure,
                threads: m.timing.variant.threads,
                unit: "Mrays/s",
                mrays_per_s: m.timing.mrays_per_s(),
                ratio,
                vs_fewest_threads,
                vs_embree,
                vs_embree_engine,
                rays_kind: m.kind.name(),
                rays: m.timing.rays,
                hits: m.timing.hits,
                width: camera.width,
                height: camera.height,
                block: m.timing.variant.block.name(),
                tile: args.tile,
                runs: args.runs,
                primitives: scene.primitives.len(),
                setup_ms: 1e3 * m.setup_seconds,
                instructions_per_ray: counts.as_ref().and_then(|c| {
                    callgrind::per_ray(c, &count_label(m.engine, m.kind, m.timing.variant), m.timing.rays)
                }),
            })
        })
        .collect::<Result<Vec<_>, StatsError>>()
        .map_err(|e| CliError::Failed(e.into()))?;
    let figures = rows.iter().flat_map(SceneRow::figures).collect();
    // The environment names Embree's first setting (its build thread count and ISA).
    let embree = engines.iter().find_map(|v| v.embree_isa).map(|isa| isa.config(1));
    run.finish(rows, figures, embree.as_deref(), |rows| {
        outln!(
            "{}: {} primitives{}, {}x{} primary rays through pixel centres (other kinds from their hits), \
             accel {}, {}px tiles, {} runs per variant after a warm-up, interleaved",
            name,
            scene.id_count(),
            instanced_counts(&scene),
            camera.width,
            camera.height,
            args.accel.name(),
            args.tile,
            args.runs
        )?;
        print_table(rows)?;
        if rows.iter().any(|r| r.vs_embree.is_some()) {
            outln!(
                "(vs embree: over the faster of Embree's settings measured ({}) on the same kernel, block and threads, run by run)",
                args.embree_isa.iter().map(|isa| isa.name()).collect::<Vec<_>>().join(", ")
            )?;
        }
        if args.instructions {
            outln!(
                "(instructions per ray: {})",
                callgrind::counted_how(no_counts.as_deref())
            )?;
        }
        Ok(())
    })
}

/// One variant of one engine and ray kind, measured.
struct Measured {
    engine: EngineVariant,
    /// The engine's structure (`bvh`, `none`, `embree`).
    structure: &'static str,
    kind: RayKind,
    timing: Timing,
    /// Each run's Mrays/s.
    mrays: Vec<f64>,
    setup_seconds: f64,
}

/// What a scene with instances holds beside its primitive ids, for the
/// header line: " (U unique, I instances)", or nothing for a flat scene.
fn instanced_counts(scene: &Scene) -> String {
    if scene.instances.is_empty() {
        return String::new();
    }
    format!(
        " ({} unique, {} instances)",
        scene.unique_primitives(),
        scene.instances.list().len()
    )
}

/// The ratios of one row ([`ratios`]).
struct Ratios {
    /// Over the ray kind's first variant.
    first: Summary,
    /// Over the same engine and variant on the fewest threads.
    fewest_threads: Summary,
    /// raypack: over the faster Embree setting, and its name.
    vs_embree: Option<(Summary, String)>,
}

/// The ratios of `m` within its ray kind, from runs paired round by round:
/// over the kind's first variant, over the fewest threads of the same
/// variant, and (raypack) over the faster Embree setting on the same kernel, block
/// and threads.
/// The first two are over `m` itself at the latest. Every engine's variants
/// are interleaved in the same rounds, so run `i` of one pairs with run `i` of
/// another.
fn ratios(m: &Measured, all: &[Measured]) -> Result<Ratios, StatsError> {
    let v = m.timing.variant;
    let same_kind = || all.iter().filter(|o| o.kind == m.kind);
    let same_variant =
        |o: &&Measured| o.timing.variant.kernel == v.kernel && o.timing.variant.block == v.block;
    let over = |o: &Measured| Summary::paired_ratio(&m.mrays, &o.mrays);
    let first = same_kind().next().unwrap_or(m);
    let fewest = same_kind()
        .filter(|o| o.engine == m.engine && same_variant(o))
        .min_by_key(|o| o.timing.variant.threads)
        .unwrap_or(m);
    // Against the faster Embree setting: the hardest comparison.
    let median = |o: &Measured| o.timing.mrays_per_s().median;
    let embree = same_kind()
        .filter(|o| {
            m.engine.engine == Engine::Raypack
                && o.engine.engine == Engine::Embree
                && same_variant(o)
                && o.timing.variant.threads == v.threads
        })
        .max_by(|a, b| median(a).total_cmp(&median(b)));
    let vs_embree = match embree {
        Some(o) => Some((over(o)?, o.engine.name())),
        None => None,
    };
    Ok(Ratios {
        first: over(first)?,
        fewest_threads: over(fewest)?,
        vs_embree,
    })
}

fn print_table(rows: &[SceneRow]) -> CliResult {
    outln!(
        "{:<8} {:<15} {:<8} {:>5} {:>7} {:>20} {:>9} {:>15} {:>15} {:>15} {:>10}",
        "rays",
        "engine",
        "kernel",
        "block",
        "threads",
        "Mrays/s",
        "median ms",
        "vs first",
        "vs fewest t",
        "vs embree",
        "instr/ray"
    )?;
    for r in rows {
        let vs_embree = r.vs_embree.map_or(String::new(), |x| figure(&x, 2, "x"));
        let instructions = r
            .instructions_per_ray
            .map_or(String::new(), |n| format!("{n:.0}"));
        outln!(
            "{:<8} {:<15} {:<8} {:>5} {:>7} {:>20} {:>9.2} {:>15} {:>15} {:>15} {:>10}",
            r.rays_kind,
            r.engine,
            r.kernel,
            r.block,
            r.threads,
            figure(&r.mrays_per_s, 3, ""),
            r.rays as f64 / r.mrays_per_s.median / 1e3,
            figure(&r.ratio, 2, "x"),
            figure(&r.vs_fewest_threads, 2, "x"),
            vs_embree,
            instructions
        )?;
    }
    Ok(())
}
