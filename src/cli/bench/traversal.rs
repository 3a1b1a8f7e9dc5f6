//! `raypack bench traversal`: BVH build times and traversal throughput per
//! scene, engine, ray kind and thread count, single rays against 8- and 16-ray
//! packets.

use clap::Args;

use crate::bench::callgrind;
use crate::bench::rays::RayKind;
use crate::bench::traversal::EngineVariant;
use crate::bench::traversal::{
    Builder, KindRow, TraversalRow, TraversalSetup, count_instructions, instructions_per_ray, measure,
};
use crate::cli::args::{load_scene, parse_size};
use crate::cli::bench::output::{Output, Run, figure};
use crate::cli::error::{CliError, CliResult};
use crate::cli::stdout::outln;
use crate::embree_settings::EmbreeIsa;
use crate::engines::Engine;

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
    /// Timed rounds per variant, interleaved (a 95% interval needs 6 or more).
    #[arg(long, default_value_t = 10)]
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
    /// Also count the instructions per ray of every engine, kind and path, at
    /// one thread: the run repeats under callgrind (valgrind), which is slow,
    /// and executes AVX2 code there (valgrind has no AVX-512).
    #[arg(long)]
    pub instructions: bool,
    /// Output and baselines.
    #[command(flatten)]
    pub output: Output,
}

/// Measure and report (or, in the run under callgrind that `--instructions`
/// makes, count instructions and report nothing).
pub fn run(args: TraversalArgs) -> CliResult {
    if callgrind::is_counting_child() {
        let setups = setups(&args)?;
        return count_instructions(&setups, &args.engine, &args.embree_isa).map_err(CliError::Failed);
    }
    let run = Run::start(&args.output, "traversal")?;
    // Ask for the engines before generating scenes: Embree may be missing
    // (the devices go at the end of the statement: `measure` makes its own).
    let first_threads = args.threads.first().copied().unwrap_or(1);
    Builder::new(&args.engine, &args.embree_isa, first_threads).map_err(CliError::BadInput)?;
    // Where instructions cannot be counted, say why before measuring.
    let no_counts = args.instructions.then(callgrind::unavailable).flatten();
    if let Some(why) = &no_counts {
        eprintln!("note: instructions per ray n/a: {why}");
    }
    let setups = setups(&args)?;
    // The environment's Embree device (in `finish`) comes after the measuring ones.
    let mut rows = measure(
        &setups,
        &args.engine,
        &args.embree_isa,
        &args.threads,
        args.rounds.max(1),
        &run.hooks,
    )
    .map_err(CliError::Failed)?;
    if args.instructions && no_counts.is_none() {
        let counts = callgrind::count_this_command().map_err(CliError::Failed)?;
        instructions_per_ray(&mut rows, &setups, &counts);
    }
    let figures = rows.iter().flat_map(TraversalRow::figures).collect();
    let embree = args
        .engine
        .contains(&Engine::Embree)
        .then(|| args.embree_isa.first().map(|isa| isa.config(first_threads)))
        .flatten();
    run.finish(rows, figures, embree.as_deref(), |rows| {
        // The rows come per thread count in the order given (see `measure`).
        let mut thread_counts: Vec<usize> = rows.iter().map(|r| r.threads).collect();
        thread_counts.dedup();
        for threads in thread_counts {
            let of_threads: Vec<TraversalRow> =
                rows.iter().filter(|r| r.threads == threads).cloned().collect();
            print_traversal(&of_threads)?;
        }
        if args.instructions {
            outln!(
                "(instructions per ray: {})",
                callgrind::counted_how(no_counts.as_deref())
            )?;
        }
        outln!(
            "({} rounds after a warm-up, thread counts, scenes, engines, ray kinds and variants \
             interleaved round by round, backwards in odd rounds, builds too; ratios from the rounds \
             paired; random rays: {} from the scene box, uniform directions; secondary rays from the \
             primary hits; {}; transparent huge pages: {})",
            args.rounds,
            args.random,
            crate::bench::traversal::builds_how(),
            crate::huge_pages::system_mode().as_deref().unwrap_or("unknown")
        )
    })
}

/// The scenes of `args` with their rays: its SCENE, or the generated family.
fn setups(args: &TraversalArgs) -> Result<Vec<TraversalSetup>, CliError> {
    Ok(match &args.scene {
        Some(path) => {
            let (scene, _) = load_scene(path)?;
            let name = path
                .file_stem()
                .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
            let setup = TraversalSetup::of_scene(name, scene, args.size, args.random, &args.rays)
                .map_err(|e| CliError::BadInput(anyhow::anyhow!("{}: {e}", path.display())))?;
            vec![setup]
        }
        None => args
            .sizes
            .iter()
            .filter_map(|&n| {
                TraversalSetup::generated(&args.generated, n, args.size, args.random, &args.rays)
            })
            .collect(),
    })
}

/// The rows of one thread count as a table, then each engine's growth of time
/// per ray from the first scene, then raypack's speed over Embree's per scene.
fn print_traversal(rows: &[TraversalRow]) -> CliResult {
    for row in rows {
        let sah = row
            .sah_cost
            .map_or(String::new(), |c| format!("  SAH cost {c:.1}"));
        outln!(
            "{:<14} {:>8} prims {:<7} {}t  build {} ms{sah}  primary rays {}x{}",
            row.scene,
            row.primitives,
            row.variant().name(),
            row.threads,
            figure(&row.build_ms, 1, ""),
            row.resolution.0,
            row.resolution.1,
        )?;
        for k in &row.kinds {
            // Each path's Mrays/s; packets' with their speed over single rays'.
            let speeds: Vec<String> = k
                .paths
                .iter()
                .map(|p| match p.path {
                    "single" => format!("single {:>15}", figure(&p.mrays, 2, "")),
                    _ => format!(
                        "{} {:>15} ({})",
                        p.path,
                        figure(&p.mrays, 2, ""),
                        figure(&p.vs_single, 2, "x")
                    ),
                })
                .collect();
            let counted: Vec<String> = k
                .paths
                .iter()
                .filter_map(|p| Some(format!("{} {}", p.path, p.stats.as_ref()?.caption())))
                .collect();
            let mut counts = if counted.is_empty() {
                String::new()
            } else {
                format!("  [{}]", counted.join("; "))
            };
            if k.paths.iter().any(|p| p.instructions_per_ray.is_some()) {
                let per_ray: Vec<String> = k
                    .paths
                    .iter()
                    .map(|p| {
                        let n = p.instructions_per_ray.map_or("n/a".into(), |n| format!("{n:.0}"));
                        format!("{} {n}", p.path)
                    })
                    .collect();
                counts += &format!("  instructions/ray {}", per_ray.join(" "));
            }
            outln!(
                "  {:<8} {:>8} rays {:>5.1}% hit: {} Mrays/s{counts}",
                k.kind.name(),
                k.rays,
                100.0 * k.hits as f64 / k.rays.max(1) as f64,
                speeds.join(" "),
            )?;
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
                        let paths: Vec<String> = k
                            .paths
                            .iter()
                            .map(|p| format!("{} {}", p.path, figure(&p.growth_vs_first, 2, "x")))
                            .collect();
                        format!("{} {}", k.kind.name(), paths.join(" "))
                    })
                    .collect();
                outln!(
                    "time per ray, {}, {} -> {} ({}t, same rounds): {}",
                    variant.name(),
                    first.scene,
                    row.scene,
                    row.threads,
                    kinds.join(", "),
                )?;
            }
        }
    }
    print_growth_against_embree(rows)?;
    for ours in rows.iter().filter(|r| r.engine == Engine::Raypack) {
        let theirs = embree_rows(rows, &ours.scene);
        let Some(fastest_build) = theirs.iter().map(|r| r.build_ms.median).reduce(f64::min) else {
            continue;
        };
        outln!(
            "raypack / Embree, {} ({}t, same rounds): build time {:.2}x by medians against Embree's faster setting (both on {}t)",
            ours.scene,
            ours.threads,
            ours.build_ms.median / fastest_build,
            ours.threads,
        )?;
        for (k, a) in ours.kinds.iter().enumerate() {
            let ratios: Vec<String> = theirs
                .iter()
                .map(|r| format!("vs {}: {}", r.variant().name(), path_ratios(a, &r.kinds[k])))
                .collect();
            let paired: Vec<String> = a
                .paths
                .iter()
                .filter_map(|p| Some(format!("{} {}", p.path, figure(&p.vs_embree?, 2, "x"))))
                .collect();
            let paired = if paired.is_empty() {
                String::new()
            } else {
                format!("; paired vs {}: {}", theirs[0].variant().name(), paired.join(" "))
            };
            let ((best_a, path_a), (best_b, path_b)) = (a.best(), best_embree(&theirs, k));
            outln!(
                "  {:<8} Mrays/s {}{paired}; best by medians {:.2}x (raypack {path_a} {best_a:.2} vs {path_b} {best_b:.2})",
                a.kind.name(),
                ratios.join("; "),
                best_a / best_b,
            )?;
        }
    }
    Ok(())
}

/// Embree's rows on `scene`, one per ISA setting measured.
fn embree_rows<'a>(rows: &'a [TraversalRow], scene: &str) -> Vec<&'a TraversalRow> {
    rows.iter()
        .filter(|r| r.engine == Engine::Embree && r.scene == scene)
        .collect()
}

/// Embree's best path on kind `k` over the rows of its settings, by medians:
/// Mrays/s and which it was (`embree(avx2) packet8`…).
fn best_embree(rows: &[&TraversalRow], k: usize) -> (f64, String) {
    rows.iter()
        .map(|r| {
            let (mrays, path) = r.kinds[k].best();
            (mrays, format!("{} {path}", r.variant().name()))
        })
        .fold((0.0, String::new()), |a, b| if b.0 > a.0 { b } else { a })
}

/// Per ray kind, how the time per ray of each engine's best path (single rays
/// or packets, whichever is faster on each scene by medians; for Embree also
/// the faster of its ISA settings) grows from the first scene to each later
/// one, raypack's growth beside Embree's.
fn print_growth_against_embree(rows: &[TraversalRow]) -> CliResult {
    let ours: Vec<&TraversalRow> = rows.iter().filter(|r| r.engine == Engine::Raypack).collect();
    let Some(our_first) = ours.first() else {
        return Ok(());
    };
    let their_first = embree_rows(rows, &our_first.scene);
    if their_first.is_empty() {
        return Ok(());
    }
    for our_row in ours.iter().skip(1) {
        let theirs = embree_rows(rows, &our_row.scene);
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
        outln!(
            "growth of time per ray (best path), raypack vs Embree, {} -> {} ({}t): {}",
            our_first.scene,
            our_row.scene,
            our_row.threads,
            kinds.join(", ")
        )?;
    }
    Ok(())
}

/// raypack's throughput over another engine's on each path, by medians
/// (`single 1.02x packet8 n/a…`: n/a where either did not trace the path).
fn path_ratios(a: &KindRow, b: &KindRow) -> String {
    let ratios: Vec<String> = a
        .paths
        .iter()
        .map(|p| match b.path(p.path) {
            Some(q) => format!("{} {:.2}x", p.path, p.mrays.median / q.mrays.median),
            None => format!("{} n/a", p.path),
        })
        .collect();
    ratios.join(" ")
}
