//! What counting traversal statistics costs a render: the plain render, the
//! render counting totals (`raypack render`'s default) and the one counting
//! each pixel's cost (`--heatmap cost`), alternated round by round in one
//! process on one thread, so drift of a shared machine hits all three alike.
//!
//! ```text
//! cargo run --release --example count_overhead -- [--rounds 8] [--size 1024] [--kernel packet8] SCENE
//! ```
//!
//! Times are the tiles' summed CPU time (robust to preemption); best and
//! median of the rounds after a warm-up, each against the plain render.
//! Exit code 2 on bad arguments or a scene that does not load.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;
use raypack::accel::Bvh;
use raypack::render::{Counting, KernelKind, RenderSettings, render, render_counted};

/// Options.
#[derive(Parser, Debug)]
struct Args {
    /// Scene file.
    scene: PathBuf,
    /// Timed rounds (each renders all three variants once).
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..=1000))]
    rounds: u32,
    /// Square image edge in pixels.
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(1..=16384))]
    size: u32,
    /// Kernel.
    #[arg(long, value_enum, default_value_t = KernelKind::Packet8)]
    kernel: KernelKind,
}

/// Best and median of `samples` (sorted in place).
fn best_and_median(samples: &mut [f64]) -> (f64, f64) {
    samples.sort_by(f64::total_cmp);
    (samples[0], samples[samples.len() / 2])
}

fn main() -> ExitCode {
    let args = match Args::try_parse() {
        Ok(a) => a,
        Err(e) => {
            let _ = e.print();
            return ExitCode::from(if e.use_stderr() { 2 } else { 0 });
        }
    };
    let scene = match raypack::scene::load(&args.scene) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::from(2);
        }
    };
    let spec = scene.camera.unwrap_or_else(|| scene.default_camera());
    let camera = match spec.camera_at(args.size, args.size) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("{}: {e}", args.scene.display());
            return ExitCode::from(2);
        }
    };
    let bvh = Bvh::new(&scene.primitives);
    let settings = RenderSettings {
        kernel: args.kernel,
        ..RenderSettings::default()
    };
    let pool = match rayon::ThreadPoolBuilder::new().num_threads(1).build() {
        Ok(p) => p,
        Err(e) => {
            eprintln!("cannot start a worker thread: {e}");
            return ExitCode::FAILURE;
        }
    };
    let variants = [
        ("plain", None),
        ("totals", Some(Counting::Totals)),
        ("per-pixel", Some(Counting::PerPixel)),
    ];
    let mut ms = vec![Vec::new(); variants.len()];
    // Round 0 warms up caches and page tables and is not kept.
    for round in 0..=args.rounds {
        for (k, (_, counting)) in variants.iter().enumerate() {
            let out = match counting {
                None => render(&scene, &bvh, &camera, &settings, &pool, &|| {}),
                Some(c) => render_counted(&scene, &bvh, &camera, &settings, *c, &pool, &|| {}),
            };
            if round > 0 {
                ms[k].push(1e3 * out.tile_seconds.iter().sum::<f64>());
            }
        }
    }
    let (plain_best, plain_median) = best_and_median(&mut ms[0].clone());
    println!(
        "{} {}x{} whitted, {} kernel, 1 thread, {} rounds (tiles' CPU ms)",
        args.scene.display(),
        args.size,
        args.size,
        args.kernel.name(),
        args.rounds
    );
    for ((name, _), samples) in variants.iter().zip(&mut ms) {
        let (best, median) = best_and_median(samples);
        println!(
            "{name:<10} best {best:8.1} ({:+5.1}%)  median {median:8.1} ({:+5.1}%)",
            100.0 * (best / plain_best - 1.0),
            100.0 * (median / plain_median - 1.0)
        );
    }
    ExitCode::SUCCESS
}
