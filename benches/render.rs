//! Criterion: primary-ray throughput of whole frames through the tile
//! scheduler (the measurement of `raypack bench scene`), per kernel and thread
//! count, and a Whitted frame per kernel, on scenes built in code.
//! `cargo bench --bench render -- primary` runs one group.

// The test crates' scenes built in code (this bench uses some of them).
#[path = "../tests/support/render.rs"]
#[allow(dead_code)]
mod render_support;

use std::time::Duration;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use raypack::accel::BruteForce;
use raypack::bench::scene::PrimaryFrame;
use raypack::render::{Block, KernelKind, Mode, RenderSettings, Sampling, render};

// The BVH of a large scene on huge pages, as the `raypack` binary has it.
#[global_allocator]
static ALLOC: raypack::huge_pages::HugePageAlloc = raypack::huge_pages::HugePageAlloc;

const KERNELS: [KernelKind; 3] = [KernelKind::Scalar, KernelKind::Packet8, KernelKind::Packet16];

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
}

/// Primary rays, brute force: the sphere-heavy scene and the mixed scene.
fn primary(c: &mut Criterion) {
    let scenes = [
        ("spheres-256", render_support::sphere_cloud(256, 1, 256)),
        ("mixed-60", render_support::mixed_scene(60, 5)),
    ];
    let mut group = c.benchmark_group("primary");
    group.sample_size(10).measurement_time(Duration::from_secs(3));
    for (name, scene) in &scenes {
        let camera = scene.camera.unwrap().camera_at(256, 256).unwrap();
        let accel = BruteForce::new(&scene.primitives);
        let frame = PrimaryFrame::new(&camera, 16);
        group.throughput(Throughput::Elements(frame.rays()));
        for block in [Block::B4x4, Block::B8x2] {
            for kernel in KERNELS {
                for threads in [1, 2] {
                    let pool = pool(threads);
                    let id = format!("{name}/{}/{}/{threads}t", kernel.name(), block.name());
                    group.bench_function(BenchmarkId::from_parameter(id), |b| {
                        b.iter(|| frame.trace(&accel, kernel, block, &pool))
                    });
                }
            }
        }
    }
    group.finish();
}

/// A whole Whitted frame (shadow, reflection and refraction batches included).
fn whitted(c: &mut Criterion) {
    let scene = render_support::mixed_scene(60, 5);
    let camera = scene.camera.unwrap().camera_at(128, 128).unwrap();
    let accel = BruteForce::new(&scene.primitives);
    let pool = pool(2);
    let mut group = c.benchmark_group("whitted");
    group.sample_size(10).measurement_time(Duration::from_secs(3));
    for kernel in KERNELS {
        let settings = RenderSettings {
            mode: Mode::Whitted,
            kernel,
            block: Block::B4x4,
            tile_size: 16,
            max_depth: 5,
            sampling: Sampling::PixelCentres,
        };
        group.bench_function(
            BenchmarkId::from_parameter(format!("mixed-60/{}/2t", kernel.name())),
            |b| b.iter(|| render(&scene, &accel, &camera, &settings, &pool, &|| {}).counts),
        );
    }
    group.finish();
}

criterion_group!(benches, primary, whitted);
criterion_main!(benches);
