//! What a single ray's unpredictability costs, raypack beside Embree: each
//! engine traces three sets of single rays on one thread, nearest and any hit:
//!
//! - `away`: rays that start outside the scene's box and point away from it,
//!   the fixed cost of a query (raypack's batch of 16 rays, Embree's `rtc*1`
//!   call per ray);
//! - `random`: rays from uniform points of the box in uniform directions (as
//!   `bench traversal --rays random`);
//! - `repeated`: 64 of those rays, each traced 4,096 times in a row, so that
//!   the branch predictor learns its path and its nodes stay in L1.
//!
//! `random − repeated` is what the rays' mispredicted branches and cache
//! misses cost; on a scene whose tree fits in L1 it is the branches alone.
//!
//! ```text
//! cargo run --release --features embree --example repeated_rays -- [--rounds 7] SCENE...
//! ```
//!
//! SCENE is a file or a `gen:` name, as `bench traversal` takes it. Each
//! figure is the best of `--rounds` timed passes, in ns a ray. Exit code 2 on
//! bad arguments or a scene that does not load.
//!
//! `--sets` and `--columns` trace only some sets and engines (the others
//! print `-`), so that a profiler or cachegrind sees one of them alone:
//! `valgrind --tool=cachegrind --branch-sim=yes … --sets random --columns
//! raypack --rounds 1` (then `--rounds 2`: the difference is the rays').

use std::process::ExitCode;
use std::sync::Arc;
use std::time::Instant;

use clap::Parser;
use raypack::accel::stats::NoStats;
use raypack::accel::{Accel, Bvh};
use raypack::embree::device::Device;
use raypack::embree::scene::EmbreeScene;
use raypack::ray::{Hit, Ray};
use raypack::render::batch::BATCH;
use raypack::rng::Rng;

/// Huge pages for the large blocks, as the `raypack` binary has them.
#[global_allocator]
static ALLOC: raypack::huge_pages::HugePageAlloc = raypack::huge_pages::HugePageAlloc;

/// Rays in each set.
const RAYS: usize = 1 << 18;

/// Times each ray of the repeated set is traced in a row.
const REPEATS: usize = 4096;

/// Options.
#[derive(Parser, Debug)]
struct Args {
    /// Scene files or `gen:` names.
    #[arg(required = true)]
    scenes: Vec<String>,
    /// Timed passes over each set (the best is kept).
    #[arg(long, default_value_t = 7, value_parser = clap::value_parser!(u32).range(1..=1000))]
    rounds: u32,
    /// The sets to trace.
    #[arg(long, value_delimiter = ',', default_values = ["away", "random", "repeated"])]
    sets: Vec<Set>,
    /// The engines and queries to trace them with.
    #[arg(long, value_delimiter = ',', default_values = ["raypack", "embree", "raypack-any", "embree-any"])]
    columns: Vec<Column>,
}

/// A set of rays (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum Set {
    Away,
    Random,
    Repeated,
}

/// An engine and query: a column of the table, in this order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum Column {
    Raypack,
    Embree,
    RaypackAny,
    EmbreeAny,
}

impl Column {
    /// Every column, in the table's order.
    const ALL: [Column; 4] = [
        Column::Raypack,
        Column::Embree,
        Column::RaypackAny,
        Column::EmbreeAny,
    ];
}

/// A cell: ns a ray, or `-` for one not traced (NaN).
fn cell(ns: f64) -> String {
    if ns.is_nan() {
        format!("{:>9}", "-")
    } else {
        format!("{ns:9.1}")
    }
}

/// ns a ray of the best of `rounds` passes of `accel` over `rays`, in batches
/// of [`BATCH`] as `bench traversal` hands single rays over.
fn ns_a_ray(accel: &impl Accel, rays: &[Ray], any_hit: bool, rounds: u32) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..rounds {
        let start = Instant::now();
        let mut hits = 0u32;
        for batch in rays.chunks(BATCH) {
            let all = u32::MAX >> (32 - batch.len());
            if any_hit {
                hits += accel.occluded_each_counted(batch, all, &mut NoStats).count_ones();
            } else {
                let mut records = [Hit::none(&batch[0]); BATCH];
                accel.intersect_each_counted(batch, all, &mut records, &mut NoStats);
                hits += records[..batch.len()].iter().filter(|h| h.is_hit()).count() as u32;
            }
        }
        std::hint::black_box(hits);
        best = best.min(start.elapsed().as_secs_f64() * 1e9 / rays.len() as f64);
    }
    best
}

/// The three sets of rays over `bvh`'s box: away, random, repeated.
fn ray_sets(bvh: &Bvh) -> [(Set, Vec<Ray>); 3] {
    let bounds = bvh.bounds();
    let (center, reach) = (bounds.center(), 2.0 * bounds.extent().length());
    let mut rng = Rng::new(54);
    let away = (0..RAYS)
        .map(|_| {
            let d = rng.unit_vector();
            Ray::unbounded(center + reach * d, d)
        })
        .collect();
    let random: Vec<Ray> = (0..RAYS)
        .map(|_| Ray::unbounded(rng.point_in(bounds.min, bounds.max), rng.unit_vector()))
        .collect();
    let repeated = (0..RAYS).map(|i| random[i / REPEATS * REPEATS]).collect();
    [
        (Set::Away, away),
        (Set::Random, random),
        (Set::Repeated, repeated),
    ]
}

fn main() -> ExitCode {
    let args = match Args::try_parse() {
        Ok(a) => a,
        Err(e) => {
            let _ = e.print();
            return ExitCode::from(if e.use_stderr() { 2 } else { 0 });
        }
    };
    let device = match Device::new("threads=1") {
        Ok(d) => Arc::new(d),
        Err(e) => {
            eprintln!("Embree: {e}");
            return ExitCode::FAILURE;
        }
    };
    println!("ns a single ray, best of {} passes, 1 thread", args.rounds);
    println!(
        "{:24} {:8} {:>9} {:>9} {:>9} {:>9}",
        "scene", "rays", "raypack", "Embree", "rp any", "Em any"
    );
    for name in &args.scenes {
        let scene = match raypack::scene::generate::test_scenes::load_spec(name) {
            Ok(s) => s,
            Err(e) => {
                eprintln!("{e}");
                return ExitCode::from(2);
            }
        };
        let bvh = Bvh::new(&scene.primitives);
        let embree = match EmbreeScene::new(device.clone(), &scene.primitives) {
            Ok(e) => e,
            Err(e) => {
                eprintln!("{name}: Embree: {e}");
                return ExitCode::FAILURE;
            }
        };
        // ns a ray per set (None: not traced) and column (NaN: not traced).
        let mut by_set: Vec<Option<[f64; 4]>> = Vec::new();
        for (set, rays) in ray_sets(&bvh) {
            if !args.sets.contains(&set) {
                by_set.push(None);
                continue;
            }
            let times = Column::ALL.map(|column| {
                if !args.columns.contains(&column) {
                    return f64::NAN;
                }
                match column {
                    Column::Raypack => ns_a_ray(&bvh, &rays, false, args.rounds),
                    Column::Embree => ns_a_ray(&embree, &rays, false, args.rounds),
                    Column::RaypackAny => ns_a_ray(&bvh, &rays, true, args.rounds),
                    Column::EmbreeAny => ns_a_ray(&embree, &rays, true, args.rounds),
                }
            });
            let set = format!("{set:?}").to_lowercase();
            println!("{name:24} {set:8} {}", times.map(cell).join(" "));
            by_set.push(Some(times));
        }
        if let (Some(random), Some(repeated)) = (by_set[1], by_set[2]) {
            let cost: [f64; 4] = std::array::from_fn(|k| random[k] - repeated[k]);
            println!("{name:24} {:8} {}", "rand−rep", cost.map(cell).join(" "));
        }
    }
    ExitCode::SUCCESS
}
