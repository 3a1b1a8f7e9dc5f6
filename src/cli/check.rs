//! `raypack check SCENE [--rays primary|random|both] [--n N]`: trace the same
//! rays with raypack and with Embree and report how well they agree: hit/miss,
//! same primitive, ties on shared edges, relative t error (p50, p99, max), and
//! the first disagreeing rays with their coordinates. Exits 1 below the bars.
//! Both engines trace the same rays on the same rayon threads, with FTZ/DAZ set;
//! raypack's side uses `--accel` (the BVH by default, brute force as the reference).

use std::path::PathBuf;

use clap::Args;

use crate::accel::AccelKind;
use crate::cli::CliResult;
use crate::cli::args::parse_size;
use crate::compare::Kernel;
use crate::engine::{DEFAULT_EMBREE_CONFIG, EmbreeMode};

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
    /// Single rays (rtcIntersect1) or 8-wide packets (rtcIntersect8).
    #[arg(long, value_enum, default_value_t = Kernel::Packet8)]
    pub kernel: Kernel,
    /// Fail (exit 1) when hit/miss or primitive agreement (ties counted as agreeing) is lower.
    #[arg(long, default_value_t = 0.9999)]
    pub min_agreement: f64,
    /// Fail (exit 1) when the p99 relative t error is higher.
    #[arg(long, default_value_t = 1e-5)]
    pub max_t_error: f64,
    /// Disagreeing rays to list.
    #[arg(long, default_value_t = 10)]
    pub show: usize,
    /// Embree device configuration.
    #[arg(long, default_value = DEFAULT_EMBREE_CONFIG)]
    pub embree_config: String,
    /// Embree scene mode.
    #[arg(long, value_enum, default_value_t = EmbreeMode::Robust)]
    pub embree_mode: EmbreeMode,
    /// Print one JSON object instead of the text report.
    #[arg(long)]
    pub json: bool,
}

/// Run `check`.
pub fn run(args: CheckArgs) -> CliResult {
    #[cfg(feature = "embree")]
    return with_embree::run(args);
    #[cfg(not(feature = "embree"))]
    {
        let _ = args;
        Err(crate::cli::CliError::BadInput(anyhow::anyhow!(
            crate::engine::EMBREE_MISSING
        )))
    }
}

/// The comparison itself, built with the `embree` feature only.
#[cfg(feature = "embree")]
mod with_embree {

    use anyhow::anyhow;

    use super::{CheckArgs, RayChoice};
    use crate::accel::Accel;
    use crate::cli::args::{embree_scene, load_scene};
    use crate::cli::{CliError, CliResult};
    use crate::compare::{
        Agreement, AgreementOptions, Kernel, RaySet, primary_rays, random_rays, trace_rays,
    };
    use crate::embree::{EmbreeScene, flush_denormals};
    use crate::ray::Ray;
    use crate::scene::Scene;

    /// The comparison on one ray set, for the JSON report.
    #[derive(serde::Serialize)]
    struct SetReport {
        rays: RaySet,
        count: usize,
        hit_agreement: f64,
        primitive_agreement: f64,
        primitive_agreement_with_ties: f64,
        agreement: Agreement,
    }

    /// Run `check`.
    pub fn run(args: CheckArgs) -> CliResult {
        // Both engines run with FTZ/DAZ, as Embree wants, on every worker thread.
        rayon::broadcast(|_| flush_denormals());
        let (scene, _) = load_scene(&args.scene)?;
        let embree = embree_scene(&scene, &args.embree_config, args.embree_mode)?;
        let raypack = args.accel.build(&scene.primitives);
        let spec = scene.camera.unwrap_or_else(|| scene.default_camera());
        let (width, height) = args.size.unwrap_or((spec.width, spec.height));
        let camera = spec
            .camera_at(width, height)
            .map_err(|e| CliError::BadInput(anyhow!("{}: camera: {e}", scene.source)))?;
        let mut sets = Vec::new();
        if args.rays != RayChoice::Random {
            sets.push((RaySet::Primary, primary_rays(&camera)));
        }
        if args.rays != RayChoice::Primary {
            sets.push((RaySet::Random, random_rays(scene.bounds(), args.n, args.seed)));
        }
        let options = AgreementOptions {
            keep: args.show,
            ..Default::default()
        };
        let reports: Vec<SetReport> = sets
            .into_iter()
            .map(|(set, rays)| {
                let agreement = compare(&raypack, &embree, &rays, args.kernel, options);
                SetReport {
                    rays: set,
                    count: rays.len(),
                    hit_agreement: agreement.hit_agreement(),
                    primitive_agreement: agreement.primitive_agreement(),
                    primitive_agreement_with_ties: agreement.primitive_agreement_with_ties(),
                    agreement,
                }
            })
            .collect();

        if args.json {
            let json = serde_json::json!({
                "scene": scene.source,
                "primitives": scene.primitives.len(),
                "kernel": args.kernel,
                "embree": {
                    "version": embree.device().version_string(),
                    "config": embree.device().config(),
                    "mode": args.embree_mode,
                    "translation": embree.stats(),
                },
                "sets": reports,
            });
            println!(
                "{}",
                serde_json::to_string_pretty(&json).map_err(anyhow::Error::from)?
            );
        } else {
            print_report(&scene, &embree, &args, (width, height), &reports);
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

    /// Trace `rays` through both engines and compare, raypack as engine A.
    fn compare<A: Accel, B: Accel>(
        a: &A,
        b: &B,
        rays: &[Ray],
        kernel: Kernel,
        options: AgreementOptions,
    ) -> Agreement {
        let hits_a = trace_rays(a, rays, kernel);
        let hits_b = trace_rays(b, rays, kernel);
        Agreement::compare(rays, &hits_a, &hits_b, options)
    }

    fn print_report(
        scene: &Scene,
        embree: &EmbreeScene,
        args: &CheckArgs,
        size: (u32, u32),
        reports: &[SetReport],
    ) {
        let counts: Vec<String> = scene
            .counts()
            .iter()
            .map(|(k, n)| format!("{n} {k:?}").to_lowercase())
            .collect();
        println!(
            "scene    {} ({} primitives: {})",
            scene.source,
            scene.primitives.len(),
            counts.join(", ")
        );
        let s = embree.stats();
        println!(
            "embree   {} \"{}\", {:?} mode: {} triangles ({} polygons ear-clipped), {} spheres, {} instances, {} user, {} empty",
            embree.device().version_string(),
            embree.device().config(),
            args.embree_mode,
            s.triangles,
            s.polygons_triangulated,
            s.spheres,
            s.instances,
            s.user,
            s.empty
        );
        let embree_call = match args.kernel {
            Kernel::Scalar => "rtcIntersect1",
            Kernel::Packet8 => "rtcIntersect8",
        };
        println!(
            "raypack  {}, {:?} kernel; Embree {embree_call}",
            args.accel.name(),
            args.kernel
        );
        for r in reports {
            let g = &r.agreement;
            let what = match r.rays {
                RaySet::Primary => format!("primary rays, {}x{} pixel centres", size.0, size.1),
                RaySet::Random => format!("random rays, seed {}", args.seed),
            };
            println!("\n{} {what}", r.count);
            println!(
                "  hit/miss agreement    {:>10.6}%   ({} both hit, {} both miss, {} only raypack, {} only embree)",
                100.0 * r.hit_agreement,
                g.same_primitive + g.ties + g.different_primitive,
                g.both_miss,
                g.only_a,
                g.only_b
            );
            println!(
                "  same primitive        {:>10.6}%   ({:.6}% counting {} ties on shared edges/vertices)",
                100.0 * r.primitive_agreement,
                100.0 * r.primitive_agreement_with_ties,
                g.ties
            );
            println!("  different primitive   {:>10}", g.different_primitive);
            println!(
                "  relative t error      p50 {:.2e}  p99 {:.2e}  max {:.2e}  (over {} same-primitive hits)",
                g.t_error.p50, g.t_error.p99, g.t_error.max, g.same_primitive
            );
            if !g.disagreements.is_empty() {
                println!(
                    "  first disagreements (ray #, kind, origin, direction, [tmin, tmax], raypack t/prim, embree t/prim):"
                );
                for d in &g.disagreements {
                    println!(
                        "    #{:<8} {:<19} o=({:.9}, {:.9}, {:.9}) d=({:.9}, {:.9}, {:.9}) [{}, {}]  raypack {}/{}  embree {}/{}",
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
                    );
                }
            }
        }
    }
}
