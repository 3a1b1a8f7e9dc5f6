//! Every traversal path of both engines on one ray kind, interleaved round by
//! round in one process (so drift of a shared machine hits them alike): raypack's
//! single rays, 8-ray and 16-ray packets, and Embree's `rtc*1`, `rtc*8` and
//! `rtc*16` at `isa=avx2` and at its default ISA; medians in Mrays/s, on a
//! framing camera's rays (`bench traversal` times the same paths, with
//! intervals and ratios, on a scene's own camera).
//!
//! ```text
//! cargo run --release --features embree --example paths_side_by_side -- [--rounds 7] [--size 1024] [--threads 1] [--cold-warm] SCENE KIND
//! ```
//!
//! SCENE is a file or a `gen:` name, as `bench traversal` takes it; the
//! primary rays come from a camera framing its box. KIND is a `bench
//! traversal` ray kind (`primary`, `shadow`, `ao`, `diffuse`,
//! `random`). With `--cold-warm` it times single rays instead, each batch of 16
//! traced twice in a row: the first pass finds what the batch before it left in
//! the caches, the second finds the batch's own nodes and leaves in L1, so the
//! difference is what the batch's loads from L2 and beyond cost a ray.
//! Exit code 2 on bad arguments or a scene that does not load.

use std::process::ExitCode;
use std::time::Instant;

use clap::Parser;
use raypack::accel::Accel;
use raypack::bench::rays::{KindRays, RayKind};
use raypack::bench::traversal::{
    Builder, EngineVariant, PATHS, TraversalSetup, path_name, scene_bounds, trace_batch, trace_path,
};
use raypack::embree_settings::EmbreeIsa;
use raypack::engines::{Engine, WithAccel};
use raypack::render::batch::BATCH;
use raypack::render::settings::KernelKind;
use raypack::scene::generate::random::framing_camera;

// The arrays a traversal reads go on huge pages, as in `raypack` and the benches.
#[global_allocator]
static ALLOC: raypack::huge_pages::HugePageAlloc = raypack::huge_pages::HugePageAlloc;

/// Options.
#[derive(Parser, Debug)]
struct Args {
    /// Scene file, or `gen:NAME[:N[:SEED]]` for a generated scene.
    scene: String,
    /// Ray kind.
    #[arg(value_enum)]
    kind: RayKind,
    /// Timed rounds (each traces every path once), after one untimed round.
    #[arg(long, default_value_t = 7, value_parser = clap::value_parser!(u32).range(1..=1000))]
    rounds: u32,
    /// Square image edge of the primary rays, in pixels.
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(16..=16384))]
    size: u32,
    /// Threads of the rayon pool (and of Embree's builds).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=1024))]
    threads: u32,
    /// Time each 16-ray batch of single rays twice in a row instead (on one
    /// thread: `--threads` then sets the builds' threads only).
    #[arg(long)]
    cold_warm: bool,
}

/// Trace a kind's rays by `path`, one of [`PATHS`].
struct Path<'r> {
    set: &'r KindRays,
    path: KernelKind,
}

impl WithAccel<'_> for Path<'_> {
    type Output = u64;

    fn run<A: Accel>(self, accel: &A) -> u64 {
        trace_path(accel, self.set, self.path)
    }
}

/// Nanoseconds a ray of `set` takes cold and warm (see the module doc), over `rounds` passes.
struct ColdWarm<'r> {
    set: &'r KindRays,
    rounds: u32,
}

impl WithAccel<'_> for ColdWarm<'_> {
    type Output = (f64, f64);

    fn run<A: Accel>(self, accel: &A) -> (f64, f64) {
        let query = self.set.kind.query();
        let (mut cold, mut warm) = (0.0, 0.0);
        for _ in 0..self.rounds {
            for rays in self.set.rays.chunks(BATCH) {
                for seconds in [&mut cold, &mut warm] {
                    let start = Instant::now();
                    std::hint::black_box(trace_batch(accel, rays, query));
                    *seconds += start.elapsed().as_secs_f64();
                }
            }
        }
        let rays = f64::from(self.rounds) * self.set.rays.len() as f64;
        (cold / rays * 1e9, warm / rays * 1e9)
    }
}

fn run(args: &Args) -> anyhow::Result<()> {
    let scene = raypack::scene::generate::test_scenes::load_spec(&args.scene).map_err(anyhow::Error::msg)?;
    let camera = framing_camera(scene_bounds(&scene), args.size, args.size);
    // 2¹⁸ random rays, as `scripts/report.sh` measures them.
    let setup = TraversalSetup::new("scene", scene, &camera, None, 262_144, &[args.kind]);
    let set = setup
        .rays_of(args.kind)
        .ok_or_else(|| anyhow::anyhow!("no rays of kind {}", args.kind.name()))?;
    let threads = args.threads as usize;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
    Engine::prepare_threads(&[Engine::Raypack, Engine::Embree], &pool);
    let builder = Builder::new(
        &[Engine::Raypack, Engine::Embree],
        &[EmbreeIsa::Avx2, EmbreeIsa::Default],
        threads,
    )?;
    let variants = [
        EngineVariant {
            engine: Engine::Raypack,
            embree_isa: None,
        },
        EngineVariant {
            engine: Engine::Embree,
            embree_isa: Some(EmbreeIsa::Avx2),
        },
        EngineVariant {
            engine: Engine::Embree,
            embree_isa: Some(EmbreeIsa::Default),
        },
    ];
    let structures = variants
        .iter()
        .map(|&v| pool.install(|| builder.build(v, &setup.scene)))
        .collect::<anyhow::Result<Vec<_>>>()?;
    println!(
        "{} rays of kind {}, {threads} thread(s)",
        set.rays.len(),
        args.kind.name()
    );
    if args.cold_warm {
        for (variant, structure) in variants.iter().zip(&structures) {
            let job = ColdWarm {
                set,
                rounds: args.rounds,
            };
            let (cold, warm) = pool.install(|| structure.visit(job));
            println!(
                "{:16} single rays: cold {cold:6.1} ns, warm {warm:6.1} ns a ray",
                variant.name()
            );
        }
        return Ok(());
    }
    // Every (structure, path) pair once a round, backwards in odd rounds.
    let cases: Vec<(usize, usize)> = (0..structures.len())
        .flat_map(|s| (0..PATHS.len()).map(move |p| (s, p)))
        .collect();
    let mut samples = vec![Vec::new(); cases.len()];
    for round in 0..=args.rounds {
        let mut order: Vec<usize> = (0..cases.len()).collect();
        if round % 2 == 1 {
            order.reverse();
        }
        for i in order {
            let (s, p) = cases[i];
            let start = Instant::now();
            let path = PATHS[p];
            std::hint::black_box(pool.install(|| structures[s].visit(Path { set, path })));
            if round > 0 {
                samples[i].push(set.rays.len() as f64 / start.elapsed().as_secs_f64() / 1e6);
            }
        }
    }
    for ((s, p), mut mrays) in cases.into_iter().zip(samples) {
        mrays.sort_by(f64::total_cmp);
        let name = format!("{} {}", variants[s].name(), path_name(PATHS[p]));
        println!("{name:26} {:7.2} Mrays/s", mrays[mrays.len() / 2]);
    }
    Ok(())
}

fn main() -> ExitCode {
    let args = match Args::try_parse() {
        Ok(args) => args,
        Err(e) if !e.use_stderr() => {
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
        Err(e) => {
            let _ = e.print();
            return ExitCode::from(2);
        }
    };
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}
