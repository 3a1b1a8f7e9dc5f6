//! `raypack robustness [--shape S …] [--json] [--crack-images DIR]`: the robustness oracle
//! ([`crate::compare::robustness`]): rays whose right answer is known by
//! construction, through the shared edges and vertices of closed meshes,
//! grazing, spawned from the surface, far from the origin and tiny, and
//! against a double-precision reference; leaks, false hits, self-hits and t
//! error per category and engine. The engines: raypack's BVH with each
//! triangle test, in single rays and 8- and 16-wide packets, then every other
//! engine of the registry this build links, single rays (Embree with its
//! default flags and with `RTC_SCENE_FLAG_ROBUST`). Then the all-hits and inside/outside queries
//! under each triangle test. With `--crack-images`, a picture per mesh and
//! engine of where its edge and vertex rays leaked
//! ([`crate::compare::crack_image`]). Exits 1 if an engine of raypack's
//! default triangle test leaks or hits itself, or a query under it goes wrong.

use std::path::{Path, PathBuf};

use clap::Args;
use glam::Vec3;

use crate::atomic_file::AtomicFile;
use crate::cli::args::{arguments, environment, thread_pool};
use crate::cli::error::{CliError, CliResult};
use crate::cli::stdout::outln;
use crate::compare::crack_image::crack_image;
use crate::compare::robustness::{self, Engine as RobustnessEngine, Row, Sizes, edge_outcomes};
use crate::compare::robustness_result::RobustnessResult;
use crate::compare::{Kernel, NearestHits};
use crate::embree_settings::EmbreeMode;
use crate::engines::{Engine, EngineOptions};
use crate::environment::Environment;
use crate::geometry::triangle::TriangleTest;
use crate::geometry::{Primitive, Triangle};
use crate::picture::output::png_bytes;
use crate::scene::generate::closed_mesh::ClosedShape;

/// Options of `robustness`.
#[derive(Args, Debug)]
pub struct RobustnessArgs {
    /// Meshes to aim at (default: all).
    #[arg(long, value_enum)]
    pub shape: Vec<ClosedShape>,
    /// Primary rays per mesh and placement whose hits spawn secondary rays.
    #[arg(long, default_value_t = Sizes::default().spawn_points)]
    pub spawn_points: usize,
    /// Random rays per mesh against the f64 reference.
    #[arg(long, default_value_t = Sizes::default().random_rays)]
    pub random_rays: usize,
    /// Points (and rays from them) per mesh for the all-hits and
    /// inside/outside queries, against answers known by construction.
    #[arg(long, default_value_t = 10_000)]
    pub query_points: usize,
    /// Seed of the sampled rays.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Print every row (each mesh and placement), not only the totals.
    #[arg(long)]
    pub all_rows: bool,
    /// Print one JSON object instead of the tables (`raypack report` reads it).
    #[arg(long)]
    pub json: bool,
    /// Write into DIR (made if missing) a PNG per mesh and engine of where
    /// its edge and vertex rays leaked: `SHAPE-ENGINE.png`.
    #[arg(long, value_name = "DIR")]
    pub crack_images: Option<PathBuf>,
}

/// `engine` of the registry, its device made with `options`, over the
/// triangles of each mesh under `test`, traced with `kernel`; `name` in the table.
fn registered(
    name: String,
    engine: Engine,
    options: &EngineOptions,
    test: TriangleTest,
    kernel: Kernel,
) -> Result<RobustnessEngine<'static>, CliError> {
    let device = engine.device(options).map_err(CliError::BadInput)?;
    Ok(RobustnessEngine {
        name,
        trace: Box::new(move |triangles: &[[Vec3; 3]], rays| {
            let prims: Vec<Primitive> = triangles
                .iter()
                .map(|&[a, b, c]| Primitive::Triangle(Triangle::new(a, b, c).with_test(test)))
                .collect();
            let built = device
                .build(&prims)
                .expect("every engine builds a mesh of triangles");
            built.visit(NearestHits { rays, kernel })
        }),
    })
}

/// The engines measured: raypack under each triangle test with each kernel,
/// then every other engine this build has, single rays (Embree with its
/// default flags and robust).
fn engines() -> Result<Vec<RobustnessEngine<'static>>, CliError> {
    let mut engines = Vec::new();
    let defaults = EngineOptions::default();
    for test in [TriangleTest::Watertight, TriangleTest::Barycentric] {
        for kernel in [Kernel::Scalar, Kernel::Packet8, Kernel::Packet16] {
            let name = format!("raypack {} {}", test.name(), kernel.name());
            engines.push(registered(name, Engine::Raypack, &defaults, test, kernel)?);
        }
    }
    let test = TriangleTest::default();
    for &engine in Engine::ALL
        .iter()
        .filter(|e| **e != Engine::Raypack && e.linked())
    {
        let modes: &[(EmbreeMode, &str)] = match engine {
            Engine::Embree => &[(EmbreeMode::Fast, " default"), (EmbreeMode::Robust, " robust")],
            _ => &[(EmbreeMode::Fast, "")],
        };
        for &(embree_mode, suffix) in modes {
            let options = EngineOptions {
                embree_mode,
                ..defaults.clone()
            };
            let name = format!("{engine}{suffix}");
            engines.push(registered(name, engine, &options, test, Kernel::Scalar)?);
        }
    }
    Ok(engines)
}

/// The crack picture of `shape` under `engine` in `dir`: no spaces in its name.
fn crack_path(dir: &Path, shape: ClosedShape, engine: &RobustnessEngine) -> PathBuf {
    dir.join(format!("{}-{}.png", shape.name(), engine.name.replace(' ', "-")))
}

/// Claim a crack picture in `dir` (made if missing) for every shape and
/// engine, before any work.
fn claim_crack_images<'e, 'a>(
    dir: &Path,
    shapes: &[ClosedShape],
    engines: &'e [RobustnessEngine<'a>],
) -> Result<Vec<(ClosedShape, &'e RobustnessEngine<'a>, AtomicFile)>, CliError> {
    std::fs::create_dir_all(dir)
        .map_err(|e| CliError::BadInput(anyhow::anyhow!("cannot make {}: {e}", dir.display())))?;
    let mut files = Vec::new();
    for &shape in shapes {
        for engine in engines {
            files.push((
                shape,
                engine,
                AtomicFile::create(&crack_path(dir, shape, engine))?,
            ));
        }
    }
    Ok(files)
}

/// Run `robustness`.
pub fn run(args: RobustnessArgs) -> CliResult {
    let engines = engines()?;
    let pool = thread_pool(None)?;
    Engine::prepare_threads(Engine::ALL, &pool);
    let shapes = if args.shape.is_empty() {
        ClosedShape::ALL.to_vec()
    } else {
        args.shape.clone()
    };
    let crack_files = match &args.crack_images {
        Some(dir) => claim_crack_images(dir, &shapes, &engines)?,
        None => Vec::new(),
    };
    // Every triangle test runs here: no one test is the run's.
    let env = Environment {
        triangle_test: String::new(),
        ..environment(Some(crate::embree_settings::DEFAULT_EMBREE_CONFIG))?
    };
    let sizes = Sizes {
        spawn_points: args.spawn_points,
        random_rays: args.random_rays,
    };
    let tests = [TriangleTest::Watertight, TriangleTest::Barycentric];
    let (rows, queries) = pool.install(|| {
        (
            robustness::run(&shapes, &engines, sizes, args.seed),
            robustness::queries(&shapes, &tests, args.query_points, args.seed),
        )
    });
    let result = RobustnessResult::new(arguments(), env, shapes.clone(), rows, queries);
    let (rows, totals, queries) = (&result.rows, &result.totals, &result.queries);
    // The pictures before the verdict: a failing run is when they are wanted.
    for (shape, engine, file) in crack_files {
        let rays = pool.install(|| edge_outcomes(shape, engine, args.seed));
        let title = format!("{}: {}, edges and vertices", shape.name(), engine.name);
        let img = crack_image(&rays, title).map_err(anyhow::Error::from)?;
        file.commit(&png_bytes(&img))?;
    }
    if args.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&result).map_err(anyhow::Error::from)?
        )?;
    } else {
        let env = &result.environment;
        outln!("{} · kernels {}", env.cpu_model, env.isa)?;
        print_table(if args.all_rows { rows } else { totals })?;
        outln!("")?;
        outln!(
            "{:<14} {:<12} {:>8} {:>13} {:>8} {:>16}",
            "queries",
            "test",
            "points",
            "wrong inside",
            "rays",
            "wrong crossings"
        )?;
        for q in queries {
            outln!(
                "{:<14} {:<12} {:>8} {:>13} {:>8} {:>16}",
                q.shape.name(),
                q.test.name(),
                q.points,
                q.wrong_inside,
                q.rays,
                q.wrong_crossings
            )?;
        }
    }
    // raypack's default test must neither leak nor hit itself.
    let default = format!("raypack {} ", TriangleTest::default().name());
    let failing: Vec<&Row> = totals
        .iter()
        .filter(|r| r.engine.starts_with(&default) && (r.leaks > 0 || r.self_hits > 0))
        .collect();
    let wrong_queries = queries
        .iter()
        .filter(|q| q.test == TriangleTest::default() && q.wrong_inside + q.wrong_crossings > 0)
        .count();
    if wrong_queries > 0 {
        return Err(CliError::Failed(anyhow::anyhow!(
            "the queries under raypack's default triangle test went wrong on {wrong_queries} meshes"
        )));
    }
    if !failing.is_empty() {
        return Err(CliError::Failed(anyhow::anyhow!(
            "raypack's default triangle test leaked or hit itself: {}",
            failing
                .iter()
                .map(|r| format!(
                    "{} {} ({} leaks, {} self-hits)",
                    r.category.name(),
                    r.engine,
                    r.leaks,
                    r.self_hits
                ))
                .collect::<Vec<_>>()
                .join("; ")
        )));
    }
    Ok(())
}

/// The rows as a text table.
fn print_table(rows: &[Row]) -> CliResult {
    outln!(
        "{:<15} {:<14} {:<9} {:<29} {:>8} {:>6} {:>6} {:>6} {:>7} {:>7} {:>9}",
        "category",
        "shape",
        "placement",
        "engine",
        "rays",
        "leaks",
        "false",
        "self",
        "t p50",
        "t p99",
        "t max"
    )?;
    for r in rows {
        let shape = if r.placement == "all" {
            "all"
        } else {
            r.shape.name()
        };
        outln!(
            "{:<15} {:<14} {:<9} {:<29} {:>8} {:>6} {:>6} {:>6} {:>7.1} {:>7.1} {:>9.1}",
            r.category.name(),
            shape,
            r.placement,
            r.engine,
            r.rays,
            r.leaks,
            r.false_hits,
            r.self_hits,
            r.t_ulps.p50,
            r.t_ulps.p99,
            r.t_ulps.max
        )?;
    }
    Ok(())
}
