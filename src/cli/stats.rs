//! `raypack stats SCENE --spd`: a scene's ray counts under the SPD's test
//! procedure, as one JSON object on stdout; the time and the traversal work it
//! took go to stderr. (`--spd` names the procedure; it is the only one so far,
//! so the flag is required.) With `--compare`, stdout is instead a table of the
//! counts against the published ones ([`crate::render::spd_published`]).

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args as ClapArgs;

use crate::accel::{Accel, AccelKind, TraversalStats};
use crate::cli::args::{flat_primitives, load_scene, thread_pool};
use crate::cli::error::{CliError, CliResult};
use crate::cli::stdout::{out, outln};
use crate::engines::{Engine, EngineOptions, WithAccel, with_engine};
use crate::render::spd::spd_counts_with_traversal;
use crate::render::spd_published::{self, Published};
use crate::render::{KernelKind, RayCounts};
use crate::scene::Scene;

/// Options of `stats`.
#[derive(ClapArgs, Debug)]
pub struct Args {
    /// Scene file (.nff, .obj, .ply, .ply.gz, .toml), or `gen:NAME[:N[:SEED]]` for a generated scene.
    pub scene: PathBuf,
    /// Count rays the SPD way: 512x512, eye rays through pixel corners (513x513), depth 5.
    #[arg(long, required = true)]
    pub spd: bool,
    /// Kernel (the counts are the same for both).
    #[arg(long, value_enum, default_value_t = KernelKind::Packet8)]
    pub kernel: KernelKind,
    /// Worker threads (default: one per core).
    #[arg(long, value_parser = clap::value_parser!(u16).range(1..=1024))]
    pub threads: Option<u16>,
    /// Acceleration structure.
    #[arg(long, value_enum, default_value_t = AccelKind::Bvh)]
    pub accel: AccelKind,
    /// Print the counts against the SPD's published ones (Haines; Havran & Sixta
    /// where at hand) with the deviation of each, instead of JSON. The SPD scene is
    /// guessed from the file name (`spd_gears.nff`, `gen:gears`); `--compare=NAME`
    /// names it (balls, gears, mount, rings, teapot, tetra, tree).
    #[arg(long, num_args = 0..=1, require_equals = true, value_name = "NAME")]
    pub compare: Option<Option<String>>,
}

/// SPD counts with the setup and trace time and the traversal work they took
/// (reported on stderr, apart from the counts).
struct Spd<'a> {
    scene: &'a Scene,
    kernel: KernelKind,
    pool: &'a rayon::ThreadPool,
}

impl WithAccel<'_> for Spd<'_> {
    type Output = Result<(RayCounts, f64, Option<TraversalStats>), crate::camera::CameraError>;

    fn run<A: Accel>(self, accel: &A) -> Self::Output {
        let start = Instant::now();
        let (counts, traversal) = spd_counts_with_traversal(self.scene, accel, self.kernel, self.pool)?;
        Ok((counts, start.elapsed().as_secs_f64(), traversal))
    }
}

/// Run `stats`.
pub fn run(args: Args) -> CliResult {
    let (scene, _) = load_scene(&args.scene)?;
    let published = match &args.compare {
        Some(name) => Some(published_for(
            &args.scene,
            name.as_deref(),
            scene.id_count() as usize,
        )?),
        None => None,
    };
    let pool = thread_pool(args.threads)?;
    let job = Spd {
        scene: &scene,
        kernel: args.kernel,
        pool: &pool,
    };
    let options = EngineOptions {
        accel: args.accel,
        ..EngineOptions::default()
    };
    let (counted, setup) = with_engine(Engine::Raypack, &options, flat_primitives(&scene, "stats")?, job)
        .map_err(CliError::Failed)?;
    let (counts, trace, traversal) =
        counted.map_err(|e| CliError::BadInput(anyhow::anyhow!("{}: {e}", args.scene.display())))?;
    eprintln!(
        "spd: {} kernel, accel {}, {} threads: setup {:.1} ms, trace {:.1} ms",
        args.kernel.name(),
        args.accel.name(),
        pool.current_num_threads(),
        1e3 * setup,
        1e3 * trace
    );
    if let Some(t) = traversal {
        eprintln!("spd: traversal, counted in this run: {}", t.caption());
    }
    match published {
        Some(p) => out!("{}", spd_published::table(p, &p.compare(&counts)))?,
        None => outln!("{}", serde_json::to_string(&counts).map_err(anyhow::Error::from)?)?,
    }
    Ok(())
}

/// The published counts to compare `scene` (of `primitives` primitives) with:
/// those of the SPD scene `name`, or of the one its file name says. Counts are
/// comparable only at the published size, so the primitive count must match.
fn published_for(
    scene: &Path,
    name: Option<&str>,
    primitives: usize,
) -> Result<&'static Published, CliError> {
    let names = || {
        spd_published::PUBLISHED
            .iter()
            .map(|p| p.name)
            .collect::<Vec<_>>()
            .join(", ")
    };
    let published = match name {
        Some(name) => Published::find(name).ok_or_else(|| {
            CliError::BadInput(anyhow::anyhow!(
                "--compare={name}: not an SPD scene (one of {})",
                names()
            ))
        })?,
        None => Published::guess(&scene.to_string_lossy()).ok_or_else(|| {
            CliError::BadInput(anyhow::anyhow!(
                "--compare: cannot tell which SPD scene {} is from its name; say --compare=NAME (one of {})",
                scene.display(),
                names()
            ))
        })?,
    };
    if primitives as u64 != published.primitives {
        return Err(CliError::BadInput(anyhow::anyhow!(
            "--compare: {} has {primitives} primitives, the published SPD {} has {}: its counts apply only at the default size",
            scene.display(),
            published.name,
            published.primitives
        )));
    }
    Ok(published)
}
