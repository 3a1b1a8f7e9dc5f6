//! `raypack bench matrix`: the triangle-scene matrix in one command. Every scene of
//! `--scenes` is measured as `bench traversal` measures one (raypack and
//! Embree at each ISA setting on the same rays, every thread count, rounds
//! interleaved), one scene at a time so that only one scene's structures and
//! rays are held; each scene's rows are printed as soon as it is done.

use std::path::{Path, PathBuf};

use clap::Args;

use crate::atomic_file::AtomicFile;
use crate::bench::matrix::{Headline, MatrixRow, PASS, PASS_WITHIN_INTERVAL};
use crate::bench::rays::RayKind;
use crate::bench::traversal::{Builder, TraversalRow, TraversalSetup, measure};
use crate::cli::args::{environment, load_scene, parse_size};
use crate::cli::bench::output::{Baselines, JsonTo, Run};
use crate::cli::error::{CliError, CliResult};
use crate::cli::stdout::outln;
use crate::embree_settings::EmbreeIsa;
use crate::engines::Engine;
use crate::scene::Scene;
use crate::statistics::Summary;

/// The engines every cell compares.
const ENGINES: [Engine; 2] = [Engine::Raypack, Engine::Embree];

/// Where the mesh assets are, relative to the working directory.
const ASSETS: &str = "assets";

/// The command that fills [`ASSETS`].
const FETCH_ASSETS: &str = "scripts/fetch-assets.sh";

/// Options of `bench matrix`.
#[derive(Args, Debug)]
#[command(after_long_help = "\
Each cell is raypack's fastest path (single rays, 8- or 16-ray packets) over Embree's fastest path \
and ISA setting, in Mrays/s of the same rays, taken round by round: its median and 95% interval. \
A cell whose median is below 1.00 passes only if its interval reaches 1.05 (✗ marks a failing \
cell). The build column is raypack's build time over Embree's faster setting's (✗ above 1.00). \
The headline is the geometric mean of the incoherent cells (shadow, ao, diffuse, random), \
target 1.15.

The ratios need Embree: a raypack built without the `embree` feature refuses the command \
(exit code 2) rather than print a table of raypack alone; `bench traversal` measures raypack \
by itself.

With the defaults, the whole matrix takes minutes on two cores (about 5 on an AMD EPYC Zen 5), \
most of it on the 10^6 and 10^7 meshes. `raypack report` draws the JSON result as one table.")]
pub struct MatrixArgs {
    /// Scenes, comma-separated: `gen:NAME[:N[:SEED]]` (as every SCENE),
    /// `mesh:N` (the bumpy-sphere mesh of about N triangles of `bench
    /// traversal --sizes`), `dragon` and `bunny` (assets/dragon.ply and
    /// assets/bunny.ply, skipped with a note where scripts/fetch-assets.sh
    /// has not fetched them), or a scene file.
    #[arg(
        long,
        value_delimiter = ',',
        value_parser = parse_scene,
        default_values = [
            "gen:gears", "gen:tetra", "gen:teapot", "gen:mount", "dragon", "bunny",
            "mesh:1000", "mesh:10000", "mesh:100000", "mesh:1000000", "mesh:10000000",
        ],
    )]
    pub scenes: Vec<MatrixScene>,
    /// Ray kinds, comma-separated: `primary`, `shadow`, `ao`, `diffuse`,
    /// `random` (as `bench traversal --rays`).
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = RayKind::ALL)]
    pub rays: Vec<RayKind>,
    /// Thread counts, comma-separated: a row per scene and count.
    #[arg(long, value_delimiter = ',', default_value = "1,2")]
    pub threads: Vec<usize>,
    /// Image size of the primary rays, WIDTHxHEIGHT (the secondary rays start
    /// at their hits).
    #[arg(long, value_parser = parse_size, default_value = "512x512")]
    pub size: (u32, u32),
    /// Random rays per scene.
    #[arg(long, default_value_t = 1 << 18)]
    pub random: usize,
    /// Timed rounds per scene, interleaved (a 95% interval needs 6 or more).
    #[arg(long, default_value_t = 10)]
    pub rounds: usize,
    /// Embree's kernels, comma-separated, its fastest taken per cell: `avx2`
    /// and `default` (Embree's own choice for the CPU).
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = [EmbreeIsa::Avx2, EmbreeIsa::Default])]
    pub embree_isa: Vec<EmbreeIsa>,
    /// Write the result as JSON (environment, rows, figures, comparison) to
    /// FILE, the table still printed; without FILE (or with `-`), to stdout,
    /// the table then going to stderr.
    #[arg(long, value_name = "FILE", num_args = 0..=1, default_missing_value = "-")]
    pub json: Option<PathBuf>,
    /// Baselines.
    #[command(flatten)]
    pub baselines: Baselines,
}

/// A scene of the matrix as `--scenes` names it.
#[derive(Clone, Debug)]
pub enum MatrixScene {
    /// `mesh:N`: the generated mesh of about N triangles.
    Mesh(usize),
    /// `dragon`, `bunny`: a mesh of [`ASSETS`], which may not be fetched.
    Asset(&'static str),
    /// `gen:…` or a scene file.
    Scene(PathBuf),
}

/// The mesh assets `--scenes` names by name alone.
const ASSET_NAMES: [&str; 2] = ["dragon", "bunny"];

impl MatrixScene {
    /// The name in the table and the figures: as `--scenes` spells it.
    fn name(&self) -> String {
        match self {
            Self::Mesh(n) => format!("mesh:{n}"),
            Self::Asset(name) => (*name).to_string(),
            Self::Scene(path) => path.display().to_string(),
        }
    }
}

/// Parse one `--scenes` entry (see [`MatrixArgs::scenes`]); a file must exist.
fn parse_scene(s: &str) -> Result<MatrixScene, String> {
    if let Some(n) = s.strip_prefix("mesh:") {
        return match n.parse::<usize>() {
            Ok(n) if n > 0 => Ok(MatrixScene::Mesh(n)),
            _ => Err(format!(
                "{s}: expected mesh:N, N a whole number of triangles above 0"
            )),
        };
    }
    if let Some(name) = ASSET_NAMES.into_iter().find(|a| *a == s) {
        return Ok(MatrixScene::Asset(name));
    }
    let path = PathBuf::from(s);
    if s.starts_with("gen:") || path.is_file() {
        return Ok(MatrixScene::Scene(path));
    }
    Err(format!(
        "{s}: no such scene file (a scene is gen:NAME[:N[:SEED]], mesh:N, {}, or a scene file)",
        ASSET_NAMES.join(", ")
    ))
}

/// A scene of the matrix ready to measure: loaded, or a mesh to generate.
enum Ready {
    /// A scene read or generated, under its name (boxed: a scene is large).
    Loaded(String, Box<Scene>),
    /// `mesh:N`, generated when its turn comes.
    Mesh(usize),
}

/// Measure the matrix, printing each scene's rows as it is done.
pub fn run(args: MatrixArgs) -> CliResult {
    let bad = |e: String| CliError::BadInput(anyhow::anyhow!(e));
    if args.rounds == 0 {
        return Err(bad("--rounds 0: expected 1 or more".into()));
    }
    if args.threads.contains(&0) {
        return Err(bad("--threads: expected counts of 1 or more".into()));
    }
    // Claim the JSON file first: an unwritable path fails before any work.
    let json = match args.json.as_deref() {
        None => JsonTo::Nowhere,
        Some(path) if path == Path::new("-") => JsonTo::Stdout,
        Some(path) => JsonTo::File(AtomicFile::create(path)?),
    };
    let table = Table {
        to_stderr: matches!(json, JsonTo::Stdout),
        kinds: args.rays.clone(),
    };
    let run = Run::with(&args.baselines, json, "matrix")?.without_noise_marks();
    // Without Embree there is no ratio: say so before loading any scene (the
    // devices go at the end of the statement: `measure` makes its own).
    let first_threads = args.threads.first().copied().unwrap_or(1);
    Builder::new(&ENGINES, &args.embree_isa, first_threads)
        .map_err(|e| CliError::BadInput(e.context("bench matrix sets raypack against Embree")))?;
    let scenes = ready(&args.scenes)?;
    if scenes.is_empty() {
        return Err(bad(format!(
            "no scene to measure: fetch the assets with {FETCH_ASSETS} or name other --scenes"
        )));
    }
    table.header(&environment(None)?)?;
    let mut rows: Vec<MatrixRow> = Vec::new();
    for scene in scenes {
        let (name, setup) = match scene {
            Ready::Loaded(name, scene) => {
                let setup = TraversalSetup::of_scene(&name, *scene, args.size, args.random, &args.rays)
                    .map_err(|e| bad(format!("{name}: {e}")))?;
                (name, setup)
            }
            Ready::Mesh(n) => {
                let setup = TraversalSetup::generated("mesh", n, args.size, args.random, &args.rays)
                    .ok_or_else(|| CliError::Failed(anyhow::anyhow!("no generated mesh family")))?;
                (format!("mesh:{n}"), setup)
            }
        };
        let measured = measure(
            std::slice::from_ref(&setup),
            &ENGINES,
            &args.embree_isa,
            &args.threads,
            args.rounds,
            &run.hooks,
        )
        .map_err(CliError::Failed)?;
        for row in matrix_rows(&name, &measured)? {
            table.row(&row)?;
            rows.push(row);
        }
    }
    let figures: Vec<_> = rows.iter().flat_map(MatrixRow::figures).collect();
    table.footer(&Headline::of(&figures), &args)?;
    let embree = args.embree_isa.first().map(|isa| isa.config(first_threads));
    run.finish(rows, figures, embree.as_deref(), |_| Ok(()))
}

/// The scenes of `scenes`, files and generated scenes loaded (so a bad one
/// fails before any measuring), meshes left to generate when measured;
/// missing assets left out, with a note.
fn ready(scenes: &[MatrixScene]) -> Result<Vec<Ready>, CliError> {
    let mut ready = Vec::with_capacity(scenes.len());
    for scene in scenes {
        let path = match scene {
            MatrixScene::Mesh(n) => {
                ready.push(Ready::Mesh(*n));
                continue;
            }
            MatrixScene::Asset(name) => {
                let path = Path::new(ASSETS).join(format!("{name}.ply"));
                if !path.is_file() {
                    eprintln!(
                        "note: {} is missing: no {name} rows (run {FETCH_ASSETS} to fetch it)",
                        path.display()
                    );
                    continue;
                }
                path
            }
            MatrixScene::Scene(path) => path.clone(),
        };
        let (loaded, _) = load_scene(&path)?;
        ready.push(Ready::Loaded(scene.name(), Box::new(loaded)));
    }
    Ok(ready)
}

/// The matrix rows of one scene's traversal rows `measured` (raypack and
/// Embree's settings, per thread count), named `scene`.
fn matrix_rows(scene: &str, measured: &[TraversalRow]) -> Result<Vec<MatrixRow>, CliError> {
    measured
        .iter()
        .filter(|r| r.engine == Engine::Raypack)
        .map(|ours| {
            let embree: Vec<&TraversalRow> = measured
                .iter()
                .filter(|r| r.engine == Engine::Embree && r.threads == ours.threads)
                .collect();
            MatrixRow::of(scene, ours, &embree).ok_or_else(|| {
                CliError::Failed(anyhow::anyhow!(
                    "{scene}, {} threads: Embree was not measured on every ray kind",
                    ours.threads
                ))
            })
        })
        .collect()
}

/// The table printed while the matrix is measured: to stdout, or to stderr
/// where the JSON goes to stdout.
struct Table {
    to_stderr: bool,
    kinds: Vec<RayKind>,
}

/// Characters of a cell, `0.97 [0.93, 1.02]✗`.
const CELL: usize = 19;

impl Table {
    /// Print one line.
    fn line(&self, text: &str) -> CliResult {
        if self.to_stderr {
            eprintln!("{text}");
            Ok(())
        } else {
            outln!("{text}")
        }
    }

    /// The machine, what a cell is, and the column heads.
    fn header(&self, env: &crate::environment::Environment) -> CliResult {
        self.line(&format!(
            "raypack / Embree, best path against best path, on {} (kernels {}); median [95% interval], \
             ✗ fails (below {PASS:.2} and the interval short of {PASS_WITHIN_INTERVAL:.2}; build: time, above 1.00)",
            env.cpu_model,
            env.isa_label()
        ))?;
        let mut head = format!("{:<16} {:>9} {:>3}", "scene", "prims", "thr");
        for kind in &self.kinds {
            head += &format!(" {:<CELL$}", kind.name());
        }
        self.line(&format!("{head} build"))
    }

    /// One scene at one thread count.
    fn row(&self, row: &MatrixRow) -> CliResult {
        let mut text = format!("{:<16} {:>9} {:>2}t", row.scene, row.primitives, row.threads);
        for cell in &row.cells {
            text += &format!(" {:<CELL$}", cell_text(&cell.best.ratio, cell.passes));
        }
        text += &format!(" {}", cell_text(&row.build.ratio, row.build.passes));
        self.line(&text)
    }

    /// The headline, and how the rows were measured.
    fn footer(&self, headline: &Headline, args: &MatrixArgs) -> CliResult {
        self.line(&headline.words())?;
        self.line(&format!(
            "({} rounds per scene after a warm-up, thread counts, engines, ray kinds and paths interleaved; \
             primary rays {}x{}, secondary rays from their hits, {} random rays; Embree at {}; {})",
            args.rounds,
            args.size.0,
            args.size.1,
            args.random,
            args.embree_isa
                .iter()
                .map(|i| i.name())
                .collect::<Vec<_>>()
                .join(" and "),
            crate::bench::traversal::builds_how()
        ))
    }
}

/// A ratio as `median [low, high]`, marked ✗ where it fails.
fn cell_text(ratio: &Summary, passes: bool) -> String {
    format!(
        "{:.2} [{:.2}, {:.2}]{}",
        ratio.median,
        ratio.ci_low,
        ratio.ci_high,
        if passes { "" } else { "✗" }
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scenes_parse_and_bad_ones_say_what_a_scene_is() {
        assert!(matches!(parse_scene("mesh:1000"), Ok(MatrixScene::Mesh(1000))));
        assert!(matches!(parse_scene("dragon"), Ok(MatrixScene::Asset("dragon"))));
        assert!(matches!(parse_scene("gen:tetra"), Ok(MatrixScene::Scene(_))));
        for bad in ["mesh:0", "mesh:ten", "no-such-file.ply"] {
            let e = parse_scene(bad).unwrap_err();
            assert!(e.starts_with(bad) && e.contains("mesh:N"), "{bad}: {e}");
        }
        assert_eq!(parse_scene("mesh:10").unwrap().name(), "mesh:10");
        assert_eq!(
            cell_text(&Summary::of(&[0.9]).unwrap(), false),
            "0.90 [0.90, 0.90]✗"
        );
    }
}
