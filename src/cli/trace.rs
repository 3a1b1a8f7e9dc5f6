//! `raypack trace SCENE --rays RAYS.csv --out HITS.csv [--engine raypack|embree]`:
//! trace rays from a CSV file and write the nearest hit of each, so raypack can
//! be compared with any engine (formats in [`crate::compare::csv`]); with
//! `--diff OTHER.csv`, classify the rays on which another engine's hits differ.
//! `--query all` writes every crossing of each ray instead (`ray,t,prim`, a
//! hit at a shared edge or vertex once), `--query inside` whether each ray's
//! origin lies inside the scene's closed meshes (`inside`, 1 or 0), both from
//! [`crate::accel::queries`].

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;

use rayon::prelude::*;

use crate::accel::queries::{all_hits, is_inside};
use crate::accel::{Accel, AccelKind};
use crate::atomic_file::AtomicFile;
use crate::cli::args::{engine_error, flat_primitives, load_scene, thread_pool};
use crate::cli::error::{CliError, CliResult};
use crate::cli::stdout::outln;
use crate::compare::csv::{format_hits, read_hits, read_rays};
use crate::compare::diff_image::class_name;
use crate::compare::{Agreement, AgreementOptions, DisagreementKind, classify_rays};
use crate::compare::{Kernel, trace_rays};
use crate::embree_settings::{DEFAULT_EMBREE_CONFIG, EmbreeMode};
use crate::engines::{Engine, EngineOptions, WithAccel};
use crate::geometry::Primitive;
use crate::plural;
use crate::ray::{Hit, Ray};
use crate::scene::Scene;

/// Options of `trace`.
#[derive(Args, Debug)]
pub struct TraceArgs {
    /// Scene file (.nff, .obj, .ply, .ply.gz, .toml), or `gen:NAME[:N[:SEED]]` for a generated scene.
    pub scene: PathBuf,
    /// Rays: CSV with header `ox,oy,oz,dx,dy,dz,tmin,tmax`.
    #[arg(long)]
    pub rays: PathBuf,
    /// Hits: CSV with header `t,prim` (`inf,-1` on a miss), written whole or not at all.
    #[arg(long)]
    pub out: PathBuf,
    /// Engine that traces.
    #[arg(long, value_enum, default_value_t = Engine::Raypack)]
    pub engine: Engine,
    /// raypack's acceleration structure (brute force is the reference).
    #[arg(long, value_enum, default_value_t = AccelKind::Bvh)]
    pub accel: AccelKind,
    /// Single rays or 8-wide packets (Embree: rtcIntersect1 or rtcIntersect8).
    #[arg(long, value_enum, default_value_t = Kernel::Packet8)]
    pub kernel: Kernel,
    /// Embree device configuration.
    #[arg(long, default_value = DEFAULT_EMBREE_CONFIG)]
    pub embree_config: String,
    /// Embree scene mode.
    #[arg(long, value_enum, default_value_t = EmbreeMode::Robust)]
    pub embree_mode: EmbreeMode,
    /// What to ask of each ray: its nearest hit, all its crossings, or
    /// whether its origin is inside the closed meshes.
    #[arg(long, value_enum, default_value_t = Query::Nearest)]
    pub query: Query,
    /// Another engine's hits on the same rays (`t,prim` CSV): classify every
    /// ray on which they differ from these, as `check` does, and print the counts.
    #[arg(long)]
    pub diff: Option<PathBuf>,
}

/// What `trace` asks of each ray.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Query {
    /// The nearest hit (`t,prim`).
    Nearest,
    /// Every crossing, nearest first (`ray,t,prim`).
    All,
    /// Whether the ray's origin is inside the closed meshes (`inside`).
    Inside,
}

/// What `trace` asks of an engine's structure: the nearest hits of `rays`, or
/// the answers of another query.
struct TraceJob<'a> {
    prims: &'a [Primitive],
    rays: &'a [Ray],
    query: Query,
    kernel: Kernel,
}

/// What a [`TraceJob`] found.
enum Traced {
    /// Nearest hits, one per ray.
    Hits(Vec<Hit>),
    /// The answers of another query, as CSV text.
    Answers(String),
}

impl WithAccel<'_> for TraceJob<'_> {
    type Output = Traced;

    fn run<A: Accel>(self, accel: &A) -> Traced {
        match self.query {
            Query::Nearest => Traced::Hits(trace_rays(accel, self.rays, self.kernel)),
            query => Traced::Answers(answers(accel, self.prims, self.rays, query)),
        }
    }
}

/// The answers of `query` for every ray, as CSV text.
fn answers<A: Accel>(accel: &A, prims: &[Primitive], rays: &[Ray], query: Query) -> String {
    let mut csv = String::new();
    match query {
        Query::Nearest => unreachable!("nearest hits go through trace_rays"),
        Query::All => {
            let all: Vec<Vec<Hit>> = rays.par_iter().map(|r| all_hits(accel, prims, r)).collect();
            csv.push_str("ray,t,prim\n");
            for (i, hits) in all.iter().enumerate() {
                for h in hits {
                    csv.push_str(&format!("{i},{},{}\n", h.t, h.prim));
                }
            }
        }
        Query::Inside => {
            let inside: Vec<bool> = rays
                .par_iter()
                .map(|r| is_inside(accel, prims, r.origin))
                .collect();
            csv.push_str("inside\n");
            for i in inside {
                csv.push_str(if i { "1\n" } else { "0\n" });
            }
        }
    }
    csv
}

/// Run `trace`.
pub fn run(args: TraceArgs) -> CliResult {
    if args.query != Query::Nearest && args.diff.is_some() {
        return Err(CliError::BadInput(anyhow::anyhow!(
            "--diff compares nearest hits: it cannot go with --query {:?}",
            args.query
        )));
    }
    args.engine
        .traces_lanes(args.kernel.lanes())
        .map_err(|e| CliError::BadInput(e.into()))?;
    let (scene, _) = load_scene(&args.scene)?;
    let rays = read_rays(&args.rays).map_err(|e| CliError::BadInput(e.into()))?;
    let theirs = match &args.diff {
        Some(path) => {
            let hits = read_hits(path).map_err(|e| CliError::BadInput(e.into()))?;
            if hits.len() != rays.len() {
                return Err(CliError::BadInput(anyhow::anyhow!(
                    "{}: {} for {}: expected one line per ray of {}",
                    path.display(),
                    plural::count(hits.len() as u64, "hit", "hits"),
                    plural::count(rays.len() as u64, "ray", "rays"),
                    args.rays.display()
                )));
            }
            Some(hits)
        }
        None => None,
    };
    // Claim the output before tracing, so an unwritable path fails at once.
    let out = AtomicFile::create(&args.out)?;
    let start = Instant::now();
    let options = EngineOptions {
        accel: args.accel,
        embree_config: args.embree_config.clone(),
        embree_mode: args.embree_mode,
    };
    let device = args.engine.device(&options).map_err(CliError::BadInput)?;
    let built = device.build_scene(&scene).map_err(engine_error)?;
    let pool = thread_pool(None)?;
    Engine::prepare_threads(&[args.engine], &pool);
    // Nearest hits come from the engine's own structure, instances and all;
    // only the other queries read the primitives, flattened.
    let prims = match args.query {
        Query::Nearest => &[],
        _ => {
            let query = clap::ValueEnum::to_possible_value(&args.query).expect("every query is named");
            flat_primitives(&scene, &format!("trace --query {}", query.get_name()))?
        }
    };
    let job = TraceJob {
        prims,
        rays: &rays,
        query: args.query,
        kernel: args.kernel,
    };
    let hits = match pool.install(|| built.visit(job)) {
        Traced::Hits(hits) => hits,
        Traced::Answers(csv) => {
            out.commit(csv.as_bytes())?;
            eprintln!(
                "answered {:?} for {} in {:.3} s (with build); wrote {}",
                args.query,
                plural::count(rays.len() as u64, "ray", "rays"),
                start.elapsed().as_secs_f64(),
                args.out.display()
            );
            return Ok(());
        }
    };
    let seconds = start.elapsed().as_secs_f64();
    out.commit(format_hits(&hits).as_bytes())?;
    eprintln!(
        "traced {} through {} with {:?} ({:?}): {}, {:.3} s (with build); wrote {}",
        plural::count(rays.len() as u64, "ray", "rays"),
        plural::count(scene.id_count(), "primitive", "primitives"),
        args.engine,
        args.kernel,
        plural::count(hits.iter().filter(|h| h.is_hit()).count() as u64, "hit", "hits"),
        seconds,
        args.out.display()
    );
    if let Some(theirs) = theirs {
        print_diff(&scene, &rays, &hits, &theirs, &args)?;
    }
    Ok(())
}

/// The classes of the rays on which `ours` and `theirs` differ, counted.
fn print_diff(scene: &Scene, rays: &[Ray], ours: &[Hit], theirs: &[Hit], args: &TraceArgs) -> CliResult {
    let options = AgreementOptions::default();
    let classes = classify_rays(scene, rays, ours, theirs, &options);
    let agreement = Agreement::from_classes(rays, ours, theirs, &classes, options.keep);
    let (a, b) = (args.engine.name(), "the --diff file");
    outln!(
        "{} compared with {}: {} both miss, {} same primitive",
        plural::count(rays.len() as u64, "ray", "rays"),
        args.diff
            .as_deref()
            .map_or(String::new(), |p| p.display().to_string()),
        agreement.both_miss,
        agreement.same_primitive
    )?;
    for (kind, n) in [
        (DisagreementKind::OnlyA, agreement.only_a),
        (DisagreementKind::OnlyB, agreement.only_b),
        (
            DisagreementKind::DifferentPrimitive,
            agreement.different_primitive,
        ),
        (DisagreementKind::Tie, agreement.ties),
        (DisagreementKind::Coincident, agreement.coincident),
        (DisagreementKind::TBeyondUlps, agreement.t_beyond_ulps),
    ] {
        outln!("  {:<40} {n}", class_name(kind, a, b, options.max_ulps))?;
    }
    Ok(())
}
