//! `raypack render SCENE -o out.png`: render a scene into a timing-annotated PNG
//! (and optionally a JSON sidecar with the same numbers).

use std::path::PathBuf;
use std::time::Instant;

use clap::Args as ClapArgs;

use crate::accel::{Accel, AccelKind};
use crate::atomic_file::AtomicFile;
use crate::camera::Camera;
use crate::cli::args::{check_image_memory, engine_error, load_scene, parse_size, scene_camera, thread_pool};
use crate::cli::error::{CliError, CliResult};
use crate::cli::stdout::outln;
use crate::embree_settings::{DEFAULT_EMBREE_CONFIG, EmbreeMode};
use crate::engines::{Engine, EngineOptions, WithAccel};
use crate::picture::annotate::annotate_render;
use crate::picture::heat_map::{HeatMapKind, NoPixelCosts};
use crate::picture::output::png_bytes;
use crate::picture::progress::Progress;
use crate::picture::render_report::{RenderReport, RunInfo};
use crate::render::{Block, Counting, KernelKind, Mode, Render, RenderSettings, Sampling, render_counted};
use crate::scene::{Light, Scene};
use glam::Vec3;

/// Options of `render`.
#[derive(ClapArgs, Debug)]
pub struct Args {
    /// Scene file (.nff, .obj, .ply, .ply.gz, .toml), or `gen:NAME[:N[:SEED]]` for a generated scene.
    pub scene: PathBuf,
    /// Output PNG (written atomically: complete or not at all).
    #[arg(short, long, default_value = "out.png")]
    pub output: PathBuf,
    /// What a pixel shows.
    #[arg(long, value_enum, default_value_t = Mode::Whitted)]
    pub mode: Mode,
    /// Trace rays one at a time or in 8-wide packets.
    #[arg(long, value_enum, default_value_t = KernelKind::Packet8)]
    pub kernel: KernelKind,
    /// Pixel block traced as one batch (one 16-wide packet, or two 8-wide ones).
    #[arg(long, value_enum, default_value_t = Block::B4x4)]
    pub block: Block,
    /// Tile edge in pixels (tiles are scheduled with rayon's work stealing).
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub tile: u32,
    /// Worker threads (default: one per core).
    #[arg(long, value_parser = clap::value_parser!(u16).range(1..=1024))]
    pub threads: Option<u16>,
    /// Acceleration structure.
    #[arg(long, value_enum, default_value_t = AccelKind::Bvh)]
    pub accel: AccelKind,
    /// Engine that traces: raypack, or Embree (needs the `embree` feature).
    #[arg(long, value_enum, default_value_t = Engine::Raypack)]
    pub engine: Engine,
    /// Embree device configuration (`--engine embree`): its kernels' ISA
    /// (`isa=avx2`, or none for the best this CPU has) and BVH build threads.
    #[arg(long, default_value = DEFAULT_EMBREE_CONFIG)]
    pub embree_config: String,
    /// Embree scene mode (`--engine embree`).
    #[arg(long, value_enum, default_value_t = EmbreeMode::Fast)]
    pub embree_mode: EmbreeMode,
    /// Maximum ray depth in whitted mode (the eye ray is depth 1).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub depth: u32,
    /// Image size WxH (default: the scene camera's; the fields of view stay the scene's).
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Put a heat map beside the image: `time`, the CPU time per pixel of each
    /// tile (`--heatmap` alone), or `cost`, each pixel's traversal cost (node
    /// visits + primitive tests of all its rays). Written before the scene,
    /// it needs its kind (`--heatmap time scene.nff`): a bare `--heatmap`
    /// would take the scene's path for one.
    #[arg(long, value_enum, num_args = 0..=1, default_missing_value = "time")]
    pub heatmap: Option<HeatMapKind>,
    /// Leave out the caption band (and heat map): the bare render.
    #[arg(long, conflicts_with = "heatmap")]
    pub no_caption: bool,
    /// Also write the numbers as JSON to this file.
    #[arg(long)]
    pub stats_json: Option<PathBuf>,
    /// Keep a scene without lights unlit in whitted mode (ambient only)
    /// instead of lighting it with a headlight, a white light at the eye.
    #[arg(long)]
    pub no_headlight: bool,
    /// Do not count traversal statistics (nodes, primitive tests and SIMD lanes
    /// per ray) during the render, for the last few percent of speed.
    #[arg(long)]
    pub no_traversal_stats: bool,
}

/// Render with whichever acceleration structure was chosen, counting its
/// traversal as `counting` says where the structure can be counted.
struct RenderRequest<'a> {
    scene: &'a Scene,
    camera: &'a Camera,
    settings: &'a RenderSettings,
    counting: Counting,
    pool: &'a rayon::ThreadPool,
}

impl RenderRequest<'_> {
    /// Run `trace` with a progress bar ticked by its tiles.
    fn with_progress(&self, trace: impl FnOnce(&(dyn Fn() + Sync)) -> Render) -> Render {
        let tiles = self.camera.width.div_ceil(self.settings.tile_size)
            * self.camera.height.div_ceil(self.settings.tile_size);
        let progress = Progress::new(tiles as usize);
        let out = trace(&|| progress.tile_done());
        progress.finish();
        out
    }
}

impl WithAccel<'_> for RenderRequest<'_> {
    type Output = Render;

    fn run<A: Accel>(self, accel: &A) -> Self::Output {
        self.with_progress(|tick| {
            let (scene, camera, settings) = (self.scene, self.camera, self.settings);
            render_counted(scene, accel, camera, settings, self.counting, self.pool, tick)
        })
    }
}

/// Run `render`.
pub fn run(args: Args) -> CliResult {
    // Claim the outputs first: an unwritable path fails before any work is done.
    let is_png = args
        .output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if !is_png {
        return Err(CliError::BadInput(anyhow::anyhow!(
            "cannot write {}: the output must be a .png file",
            args.output.display()
        )));
    }
    // A cost heat map needs per-pixel counts, which only raypack's structures give.
    let counting = match args.heatmap {
        Some(HeatMapKind::Cost) if args.no_traversal_stats || !args.engine.capabilities().counts_work => {
            return Err(CliError::BadInput(NoPixelCosts.into()));
        }
        Some(HeatMapKind::Cost) => Counting::PerPixel,
        _ if args.no_traversal_stats => Counting::Off,
        _ => Counting::Totals,
    };
    args.engine
        .traces_lanes(args.kernel.lanes())
        .map_err(|e| CliError::BadInput(e.into()))?;
    if args.mode == Mode::Whitted {
        args.engine.finds_any_hit().map_err(|e| {
            CliError::BadInput(anyhow::Error::from(e).context(format!(
                "{} cannot render `--mode whitted` (its shadow rays); `--mode cast` needs no any-hit query",
                args.engine
            )))
        })?;
    }
    let image_file = AtomicFile::create(&args.output)?;
    let json_file = args.stats_json.as_deref().map(AtomicFile::create).transpose()?;

    let (mut scene, load_seconds) = load_scene(&args.scene)?;
    let camera = scene_camera(&scene, &args.scene, args.size)?;
    check_image_memory(camera.width, camera.height)?;
    // PLY and OBJ meshes carry no lights, and an NFF file may have none; in
    // whitted mode such a scene would show flat ambient grey.
    let headlight = args.mode == Mode::Whitted && scene.lights.is_empty() && !args.no_headlight;
    if headlight {
        eprintln!(
            "note: {} has no lights: lighting it with a headlight at the eye (--no-headlight to keep it unlit)",
            args.scene.display()
        );
        scene.lights.push(Light {
            position: camera.eye,
            color: Vec3::ONE,
        });
    }
    let pool = thread_pool(args.threads)?;
    let settings = RenderSettings {
        mode: args.mode,
        kernel: args.kernel,
        block: args.block,
        tile_size: args.tile,
        max_depth: args.depth,
        sampling: Sampling::PixelCentres,
    };
    let request = RenderRequest {
        scene: &scene,
        camera: &camera,
        settings: &settings,
        counting,
        pool: &pool,
    };
    let options = EngineOptions {
        accel: args.accel,
        embree_config: args.embree_config.clone(),
        embree_mode: args.embree_mode,
    };
    let device_start = Instant::now();
    let device = args.engine.device(&options).map_err(CliError::BadInput)?;
    Engine::prepare_threads(&[args.engine], &pool);
    let built = device.build_scene(&scene).map_err(engine_error)?;
    let setup_seconds = device_start.elapsed().as_secs_f64();
    let description = built.describe();
    let out = built.visit(request);

    let report = RenderReport::new(
        &scene,
        &out,
        &RunInfo {
            engine: args.engine,
            kernel: args.kernel,
            block: args.block,
            mode: args.mode,
            accel: description.structure,
            settings: description.settings,
            threads: pool.current_num_threads(),
            tile_size: args.tile,
            max_depth: args.depth,
            load_seconds,
            setup_seconds,
            headlight,
        },
    );
    let image = if args.no_caption {
        out.frame.to_rgb8()
    } else {
        annotate_render(&out, &report, args.heatmap).map_err(|e| CliError::BadInput(e.into()))?
    };
    image_file.commit(&png_bytes(&image))?;
    if let Some(file) = json_file {
        let json = serde_json::to_string_pretty(&report).map_err(anyhow::Error::from)?;
        file.commit(json.as_bytes())?;
    }
    outln!(
        "wrote {} ({}x{} {}, {} {}, {} threads): trace {:.1} ms, {:.2} Mrays/s, {} rays",
        args.output.display(),
        report.width,
        report.height,
        report.mode.name(),
        report.kernel.name(),
        report.block.name(),
        report.threads,
        report.trace_ms,
        report.mrays_per_s,
        report.rays_total
    )?;
    Ok(())
}
