//! `raypack check SCENE [--engine NAME] [--reference NAME] [--rays primary|random|both]`:
//! trace the same rays with a reference engine (raypack by default) and another
//! engine of the registry (Embree by default) and report how well they agree: hit/miss,
//! same primitive, ties on shared edges, t error (p50, p99, max), and
//! the first disagreeing rays with their coordinates. Every disagreement is
//! classified (hit/miss flip, tie at a shared edge or vertex, coincident
//! surfaces, different primitive, same primitive with t beyond `--max-ulps`;
//! see [`crate::compare::agreement`]) and counted per class; `--diff-image`
//! draws the primary rays with the disagreeing pixels coloured by class.
//! Exits 1 below the bars.
//! Both engines trace the same rays on the same rayon threads, each thread set
//! up for both (FTZ/DAZ where Embree is one);
//! raypack's side uses `--accel` (the BVH by default, brute force as the reference).
//! `--reference embree --engine obvhs` compares a peer with Embree.

use std::path::PathBuf;

use clap::Args;

use anyhow::anyhow;

use crate::accel::AccelKind;
use crate::atomic_file::AtomicFile;
use crate::cli::args::{engine_error, environment, load_scene, parse_size, thread_pool};
use crate::cli::error::{CliError, CliResult};
use crate::cli::stdout::outln;
use crate::compare::diff_image::diff_image;
use crate::compare::{
    Agreement, AgreementOptions, CheckRays, Kernel, NearestHits, classify_rays, primary_rays, random_rays,
};
use crate::embree_settings::{DEFAULT_EMBREE_CONFIG, EmbreeMode};
use crate::engines::{Description, Engine, EngineOptions};
use crate::picture::output::png_bytes;
use crate::scene::Scene;

/// Which ray sets to compare on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum RayChoice {
    /// One ray per pixel centre of the scene's camera.
    Primary,
    /// Seeded random rays in and around the scene.
    Random,
    /// Both sets, one after the other.
    Both,
}

/// Options of `check`.
#[derive(Args, Debug)]
pub struct CheckArgs {
    /// Scene file (.nff, .obj, .ply, .ply.gz, .toml), or `gen:NAME[:N[:SEED]]` for a generated scene.
    pub scene: PathBuf,
    /// Ray sets.
    #[arg(long, value_enum, default_value_t = RayChoice::Both)]
    pub rays: RayChoice,
    /// raypack's acceleration structure (brute force is the reference).
    #[arg(long, value_enum, default_value_t = AccelKind::Bvh)]
    pub accel: AccelKind,
    /// Number of random rays.
    #[arg(long, default_value_t = 100_000)]
    pub n: usize,
    /// Seed of the random rays.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Image size of the primary rays, `WIDTHxHEIGHT` (default: the scene camera's).
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Single rays (rtcIntersect1), 8-wide packets (rtcIntersect8) or 16-wide (rtcIntersect16).
    #[arg(long, value_enum, default_value_t = Kernel::Packet8)]
    pub kernel: Kernel,
    /// Fail (exit 1) when hit/miss or primitive agreement (ties counted as agreeing) is lower.
    #[arg(long, default_value_t = 0.9999)]
    pub min_agreement: f64,
    /// Fail (exit 1) when the p99 t error is higher (the distance between the
    /// two hit points over the size of their coordinates or of t, the larger).
    #[arg(long, default_value_t = 1e-5)]
    pub max_t_error: f64,
    /// Disagreeing rays to list.
    #[arg(long, default_value_t = 10)]
    pub show: usize,
    /// The engine compared with the reference (`embree` needs the `embree` feature).
    #[arg(long, value_enum, default_value_t = Engine::Embree)]
    pub engine: Engine,
    /// The engine it is compared with (engine A): raypack, with `--accel`, by default.
    #[arg(long, value_enum, default_value_t = Engine::Raypack)]
    pub reference: Engine,
    /// Embree device configuration.
    #[arg(long, default_value = DEFAULT_EMBREE_CONFIG)]
    pub embree_config: String,
    /// Embree scene mode.
    #[arg(long, value_enum, default_value_t = EmbreeMode::Robust)]
    pub embree_mode: EmbreeMode,
    /// Ulps of t beyond which two hits on the same primitive are counted as a disagreement.
    #[arg(long, default_value_t = 16)]
    pub max_ulps: u32,
    /// Write the primary rays' picture with disagreeing pixels coloured by class (a .png).
    #[arg(long, value_name = "PNG")]
    pub diff_image: Option<PathBuf>,
    /// Print one JSON object instead of the text report.
    #[arg(long)]
    pub json: bool,
}

/// The disagreements of one ray set, counted per class.
#[derive(serde::Serialize)]
struct ClassCounts {
    /// One engine hit, the other missed (both ways).
    hit_miss: usize,
    /// Different primitives at the same t, at a shared edge or vertex.
    edge_tie: usize,
    /// Different primitives at the same t, away from their edges.
    coincident: usize,
    /// Different primitives at different t.
    different_primitive: usize,
    /// The same primitive, t beyond `max_ulps`.
    t_beyond_ulps: usize,
}

impl From<&Agreement> for ClassCounts {
    fn from(g: &Agreement) -> Self {
        Self {
            hit_miss: g.only_a + g.only_b,
            edge_tie: g.ties,
            coincident: g.coincident,
            different_primitive: g.different_primitive,
            t_beyond_ulps: g.t_beyond_ulps,
        }
    }
}

/// The comparison on one ray set, for the JSON report.
#[derive(serde::Serialize)]
struct SetReport {
    rays: CheckRays,
    count: usize,
    hit_agreement: f64,
    primitive_agreement: f64,
    primitive_agreement_with_ties: f64,
    classes: ClassCounts,
    agreement: Agreement,
}

/// Run `check`.
pub fn run(args: CheckArgs) -> CliResult {
    let engines = [args.reference, args.engine];
    for engine in engines {
        engine
            .traces_lanes(args.kernel.lanes())
            .map_err(|e| CliError::BadInput(e.into()))?;
    }
    let (a, b) = (engines[0].name(), engines[1].name());
    // Both engines' devices before any work: an engine missing from this build is the user's to fix.
    let options = EngineOptions {
        accel: args.accel,
        embree_config: args.embree_config.clone(),
        embree_mode: args.embree_mode,
    };
    let devices = engines
        .map(|e| e.device(&options))
        .into_iter()
        .collect::<anyhow::Result<Vec<_>>>()
        .map_err(CliError::BadInput)?;
    // Both engines trace on the same threads, each set up for both (Embree's FTZ/DAZ).
    let pool = thread_pool(None)?;
    Engine::prepare_threads(&engines, &pool);
    // The diff image: primary rays only, a .png, claimed before any work.
    let diff_file = match &args.diff_image {
        None => None,
        Some(_) if args.rays == RayChoice::Random => {
            return Err(CliError::BadInput(anyhow!(
                "--diff-image draws the primary rays: use --rays primary or both"
            )));
        }
        Some(path) if !path.extension().is_some_and(|e| e.eq_ignore_ascii_case("png")) => {
            return Err(CliError::BadInput(anyhow!(
                "cannot write {}: the diff image must be a .png file",
                path.display()
            )));
        }
        Some(path) => Some(AtomicFile::create(path)?),
    };
    let (scene, _) = load_scene(&args.scene)?;
    let built = devices
        .iter()
        .map(|d| d.build_scene(&scene))
        .collect::<anyhow::Result<Vec<_>>>()
        .map_err(engine_error)?;
    let descriptions: Vec<Description> = built.iter().map(|b| b.describe()).collect();
    let spec = scene.camera.unwrap_or_else(|| scene.default_camera());
    let (width, height) = args.size.unwrap_or((spec.width, spec.height));
    let camera = spec
        .camera_at(width, height)
        .map_err(|e| CliError::BadInput(anyhow!("{}: camera: {e}", scene.source)))?;
    let mut sets = Vec::new();
    if args.rays != RayChoice::Random {
        sets.push((CheckRays::Primary, primary_rays(&camera)));
    }
    if args.rays != RayChoice::Primary {
        sets.push((CheckRays::Random, random_rays(scene.bounds(), args.n, args.seed)));
    }
    let options = AgreementOptions {
        keep: args.show,
        max_ulps: args.max_ulps,
        ..Default::default()
    };
    let mut picture = None;
    let mut reports = Vec::new();
    for (set, rays) in sets {
        // Both engines on the same rays, the reference as engine A; then each ray classified.
        let [hits_a, hits_b] = [&built[0], &built[1]].map(|b| {
            let job = NearestHits {
                rays: &rays,
                kernel: args.kernel,
            };
            pool.install(|| b.visit(job))
        });
        let classes = classify_rays(&scene, &rays, &hits_a, &hits_b, &options);
        let agreement = Agreement::from_classes(&rays, &hits_a, &hits_b, &classes, options.keep);
        if set == CheckRays::Primary && diff_file.is_some() {
            let caption = vec![
                format!("{} ({} primitives)", scene.source, scene.id_count()),
                format!(
                    "{a} {} {:?}  vs  {}",
                    descriptions[0].structure, args.kernel, descriptions[1].settings
                ),
                format!(
                    "{width}x{height} primary rays  {} disagree",
                    rays.len() - agreement.both_miss - agreement.same_primitive + agreement.t_beyond_ulps
                ),
            ];
            picture = Some(diff_image(
                &scene,
                &camera,
                &hits_a,
                &classes,
                caption,
                (a, b),
                args.max_ulps,
            ));
        }
        reports.push(SetReport {
            rays: set,
            count: rays.len(),
            hit_agreement: agreement.hit_agreement(),
            primitive_agreement: agreement.primitive_agreement(),
            primitive_agreement_with_ties: agreement.primitive_agreement_with_ties(),
            classes: ClassCounts::from(&agreement),
            agreement,
        });
    }
    if let (Some(file), Some(img)) = (diff_file, picture) {
        file.commit(&png_bytes(&img))?;
    }

    if args.json {
        let json = serde_json::json!({
            "scene": scene.source,
            "primitives": scene.id_count(),
            "kernel": args.kernel,
            "max_ulps": args.max_ulps,
            "environment": environment(engines.contains(&Engine::Embree).then_some(&*args.embree_config))?,
            "engines": [a, b],
            "reference": descriptions[0],
            "engine": descriptions[1],
            "sets": reports,
        });
        outln!(
            "{}",
            serde_json::to_string_pretty(&json).map_err(anyhow::Error::from)?
        )?;
    } else {
        print_report(&scene, &descriptions, &args, (width, height), &reports)?;
    }

    let failing: Vec<String> = reports
        .iter()
        .filter(|r| {
            r.hit_agreement < args.min_agreement
                || r.primitive_agreement_with_ties < args.min_agreement
                || r.agreement.t_error.p99 > args.max_t_error
        })
        .map(|r| format!("{:?}", r.rays).to_lowercase())
        .collect();
    if failing.is_empty() {
        Ok(())
    } else {
        Err(CliError::Failed(anyhow!(
            "agreement below the bars (min agreement {}, max p99 t error {:e}) on {} rays",
            args.min_agreement,
            args.max_t_error,
            failing.join(" and ")
        )))
    }
}

fn print_report(
    scene: &Scene,
    descriptions: &[Description],
    args: &CheckArgs,
    size: (u32, u32),
    reports: &[SetReport],
) -> CliResult {
    let (a, b) = (args.reference.name(), args.engine.name());
    let counts: Vec<String> = scene
        .counts()
        .iter()
        .map(|(k, n)| format!("{n} {k:?}").to_lowercase())
        .collect();
    outln!(
        "scene    {} ({} primitives: {})",
        scene.source,
        scene.id_count(),
        counts.join(", ")
    )?;
    for (name, d) in [a, b].iter().zip(descriptions) {
        let translation = d.translation.as_ref().map_or(String::new(), |t| format!(": {t}"));
        outln!("{name:<8} {}{translation}", d.settings)?;
    }
    let call = match args.engine {
        Engine::Embree => format!(" (Embree: {})", embree_call(args.kernel)),
        _ => String::new(),
    };
    outln!("both     {:?} kernel{call}", args.kernel)?;
    for r in reports {
        let g = &r.agreement;
        let what = match r.rays {
            CheckRays::Primary => format!("primary rays, {}x{} pixel centres", size.0, size.1),
            CheckRays::Random => format!("random rays, seed {}", args.seed),
        };
        outln!("\n{} {what}", r.count)?;
        outln!(
            "  hit/miss agreement    {:>10.6}%   ({} both hit, {} both miss, {} only {a}, {} only {b})",
            100.0 * r.hit_agreement,
            g.same_primitive + g.ties + g.different_primitive,
            g.both_miss,
            g.only_a,
            g.only_b
        )?;
        outln!(
            "  same primitive        {:>10.6}%   ({:.6}% counting {} ties on shared edges/vertices and {} coincident surfaces)",
            100.0 * r.primitive_agreement,
            100.0 * r.primitive_agreement_with_ties,
            g.ties,
            g.coincident
        )?;
        let c = &r.classes;
        outln!(
            "  disagreements         hit/miss {}, different primitive {}, same primitive t > {} ulps {}, edge/vertex ties {}, coincident {}",
            c.hit_miss,
            c.different_primitive,
            args.max_ulps,
            c.t_beyond_ulps,
            c.edge_tie,
            c.coincident
        )?;
        outln!(
            "  t error               p50 {:.2e}  p99 {:.2e}  max {:.2e}  (over {} same-primitive hits; hit points' distance over their coordinates' scale)",
            g.t_error.p50,
            g.t_error.p99,
            g.t_error.max,
            g.same_primitive
        )?;
        if !g.disagreements.is_empty() {
            outln!(
                "  first disagreements (ray #, kind, origin, direction, [tmin, tmax], {a} t/prim, {b} t/prim):"
            )?;
            for d in &g.disagreements {
                outln!(
                    "    #{:<8} {:<19} o=({:.9}, {:.9}, {:.9}) d=({:.9}, {:.9}, {:.9}) [{}, {}]  {a} {}/{}  {b} {}/{}",
                    d.index,
                    format!("{:?}", d.kind),
                    d.origin[0],
                    d.origin[1],
                    d.origin[2],
                    d.dir[0],
                    d.dir[1],
                    d.dir[2],
                    d.interval[0],
                    d.interval[1],
                    d.a.0,
                    d.a.1,
                    d.b.0,
                    d.b.1
                )?;
            }
        }
    }
    Ok(())
}

/// The Embree call of `kernel`.
fn embree_call(kernel: Kernel) -> &'static str {
    match kernel {
        Kernel::Scalar => "rtcIntersect1",
        Kernel::Packet8 => "rtcIntersect8",
        Kernel::Packet16 => "rtcIntersect16",
    }
}
