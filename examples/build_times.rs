//! Build times of raypack's BVH beside Embree's, over many builds: what
//! `bench traversal` and `bench matrix` report from three builds each, with
//! enough of them that a change of a few percent shows.
//!
//! ```text
//! cargo run --release --features embree --example build_times -- [--rounds 200] [--threads 1,2] SCENE...
//! ```
//!
//! SCENE is a file or a `gen:` name, as `bench traversal` takes it. For each
//! thread count (a rayon pool of that many threads for raypack, an Embree
//! device of as many), the two engines build in turn, `--rounds` times after
//! an untimed build each; every build is dropped before the next. Both are
//! built through the engine registry as `bench` builds them
//! ([`EngineDevice::build_scene`]): a scene with instances builds a
//! structure per distinct mesh and one over the instances (raypack's
//! two-level tree, Embree's instance geometries), not its own primitives
//! alone. Printed: the best and median milliseconds of each, and raypack's
//! median over Embree's. Embree's time includes translating the primitives
//! into its geometries, as `bench` counts it. Exit code 2 on bad arguments or
//! a scene that does not load.

use std::process::ExitCode;

use clap::Parser;
use raypack::embree_settings::EmbreeIsa;
use raypack::engines::{Engine, EngineDevice, EngineOptions};
use raypack::scene::Scene;

/// Huge pages for the large blocks, as the `raypack` binary has them.
#[global_allocator]
static ALLOC: raypack::huge_pages::HugePageAlloc = raypack::huge_pages::HugePageAlloc;

/// Options.
#[derive(Parser, Debug)]
struct Args {
    /// Scene files or `gen:` names.
    #[arg(required = true)]
    scenes: Vec<String>,
    /// Timed builds of each engine per scene and thread count.
    #[arg(long, default_value_t = 200, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    rounds: u32,
    /// Thread counts, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = vec![1usize, 2])]
    threads: Vec<usize>,
}

/// Best and median of `ms`.
fn best_and_median(ms: &mut [f64]) -> (f64, f64) {
    ms.sort_by(f64::total_cmp);
    (ms[0], ms[ms.len() / 2])
}

/// Milliseconds `device` takes to build its structure over `scene`
/// ([`EngineDevice::build_timed`]), which is dropped (untimed) before this
/// returns.
fn build_ms(device: &EngineDevice, scene: &Scene) -> anyhow::Result<f64> {
    let (built, seconds) = device.build_timed(scene)?;
    drop(built);
    Ok(1e3 * seconds)
}

fn main() -> ExitCode {
    // Freed blocks reused warm, as in the `raypack` binary.
    raypack::huge_pages::keep_freed_memory();
    let args = match Args::try_parse() {
        Ok(a) => a,
        Err(e) => {
            let _ = e.print();
            return ExitCode::from(if e.use_stderr() { 2 } else { 0 });
        }
    };
    let mut scenes = Vec::new();
    for name in &args.scenes {
        match raypack::scene::generate::test_scenes::load_spec(name) {
            Ok(s) => scenes.push((name, s)),
            Err(e) => {
                eprintln!("{e}");
                return ExitCode::from(2);
            }
        }
    }
    let mut threads = args.threads.clone();
    threads.sort_unstable();
    threads.dedup();
    println!(
        "ms a build, {} builds of each engine after one untimed",
        args.rounds
    );
    println!(
        "{:24} {:>3} {:>9} {:>9} {:>9} {:>9} {:>7}",
        "scene", "thr", "rp best", "rp med", "Em best", "Em med", "rp/Em"
    );
    // Fewest threads first: a TBB worker of an earlier, larger device would
    // spin beside a smaller one's builds.
    for &t in threads.iter().filter(|&&t| t > 0) {
        let pool = match rayon::ThreadPoolBuilder::new().num_threads(t).build() {
            Ok(p) => p,
            Err(e) => {
                eprintln!("{t} threads: {e}");
                return ExitCode::FAILURE;
            }
        };
        // Embree's default-quality build at its default ISA setting, on as
        // many threads as the pool has (`bench matrix` times both settings
        // and takes the faster).
        let embree_options = EngineOptions {
            embree_config: EmbreeIsa::Default.config(t),
            ..EngineOptions::default()
        };
        let devices = Engine::Raypack
            .device(&EngineOptions::default())
            .and_then(|ours| Ok((ours, Engine::Embree.device(&embree_options)?)));
        let (ours_device, embree_device) = match devices {
            Ok(d) => d,
            Err(e) => {
                eprintln!("{e:#}");
                return ExitCode::FAILURE;
            }
        };
        for (name, scene) in &scenes {
            // Every build runs on the pool, as `bench` runs them: no build
            // waits for a sleeping worker to wake up.
            let timed = pool.install(|| {
                let (mut ours, mut theirs) = (Vec::new(), Vec::new());
                for round in 0..=args.rounds {
                    let ms = build_ms(&ours_device, scene)?;
                    let embree_ms = build_ms(&embree_device, scene)?;
                    if round > 0 {
                        ours.push(ms);
                        theirs.push(embree_ms);
                    }
                }
                anyhow::Ok((ours, theirs))
            });
            let (mut ours, mut theirs) = match timed {
                Ok(t) => t,
                Err(e) => {
                    eprintln!("{name}: {e:#}");
                    return ExitCode::FAILURE;
                }
            };
            let ((rp_best, rp_med), (em_best, em_med)) =
                (best_and_median(&mut ours), best_and_median(&mut theirs));
            println!(
                "{:24} {t:>3} {rp_best:9.3} {rp_med:9.3} {em_best:9.3} {em_med:9.3} {:7.3}",
                name,
                rp_med / em_med
            );
        }
    }
    ExitCode::SUCCESS
}
