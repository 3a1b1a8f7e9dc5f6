//! raypack against Embree on the same rays and the same threads.
//!
//! First a side-by-side table, measured the way `BENCHMARKING.md` asks: the four
//! variants (raypack scalar, raypack packet8, Embree `rtcIntersect1`, Embree
//! `rtcIntersect8`) interleaved inside one run, best of 5 after a warm-up, on 1
//! and 2 rayon threads with FTZ/DAZ set on every thread, and the ratios
//! raypack/Embree. Then a criterion group of the same four variants on one scene.
//!
//! Primary rays through pixel centres in 4×2-pixel packets. Embree: device
//! `threads=1,isa=avx2` (its 8-wide AVX2 kernels, like raypack's f32x8 packets),
//! default (fast) scene flags. raypack: its BVH. `RAYPACK_BENCH_SIZE` sets the
//! image side (default 256). Growth with scene size, primary and random rays,
//! is `raypack bench traversal --engine raypack,embree`.
//!
//! Run: `cargo bench --features embree --bench embree`.

use std::hint::black_box;
use std::sync::Arc;
use std::time::{Duration, Instant};

use criterion::{BenchmarkId, Criterion, Throughput};
use raypack::accel::{Accel, Bvh};
use raypack::compare::{Kernel, primary_rays_in_blocks, trace_rays};
use raypack::embree::{DEFAULT_CONFIG, Device, EmbreeScene, flush_denormals};
use raypack::ray::Ray;
use raypack::scene::Scene;
use raypack::scene::generate::test_scenes;

// The BVH of a large scene on huge pages, as the `raypack` binary has it.
#[global_allocator]
static ALLOC: raypack::huge_pages::HugePageAlloc = raypack::huge_pages::HugePageAlloc;

/// A rayon pool of `threads` threads, each with FTZ/DAZ set.
fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .start_handler(|_| flush_denormals())
        .build()
        .expect("thread pool")
}

/// Trace every ray once; returns a checksum so nothing is optimised away.
fn trace_all<A: Accel>(accel: &A, rays: &[Ray], kernel: Kernel) -> f32 {
    trace_rays(accel, rays, kernel)
        .iter()
        .filter(|h| h.is_hit())
        .map(|h| h.t)
        .sum()
}

/// The scene's primary rays at `size`×`size`.
fn rays_of(scene: &Scene, size: u32) -> Vec<Ray> {
    let spec = scene.camera.unwrap_or_else(|| scene.default_camera());
    primary_rays_in_blocks(&spec.camera_at(size, size).expect("camera"))
}

/// The bench scenes: the SPD sphereflake (7381 spheres and a floor), a closed
/// triangle mesh, and the mixed scene (triangles, spheres, polygons, instances,
/// a mesh, planes as user geometry).
fn scenes() -> Vec<Scene> {
    ["gen:sphereflake:4", "gen:mesh:100000", "gen:mixed:5000"]
        .into_iter()
        .map(|spec| {
            test_scenes::from_spec(spec)
                .expect("a gen: spec")
                .expect("generated scene")
        })
        .collect()
}

fn side_by_side(size: u32) {
    let device = Arc::new(Device::new(DEFAULT_CONFIG).expect("Embree device"));
    println!(
        "raypack (BVH) vs Embree {} (\"{}\", fast mode): primary rays {size}x{size}, 4x2 packets, \
         best of 5, Mrays/s",
        device.version_string(),
        device.config()
    );
    println!(
        "{:<28} {:>3} {:>14} {:>14} {:>14} {:>14} {:>14} {:>14}",
        "scene",
        "thr",
        "raypack 1",
        "raypack 8",
        "rtcIntersect1",
        "rtcIntersect8",
        "scalar ratio",
        "packet ratio"
    );
    for scene in scenes() {
        let raypack = Bvh::new(&scene.primitives);
        let embree = EmbreeScene::new(device.clone(), &scene.primitives).expect("Embree scene");
        let rays = rays_of(&scene, size);
        for threads in [1, 2] {
            let pool = pool(threads);
            let mut best = [f64::MAX; 4];
            pool.install(|| {
                // Warm up, then interleave the variants so drift hits them all alike.
                trace_all(&raypack, &rays, Kernel::Packet8);
                trace_all(&embree, &rays, Kernel::Packet8);
                for _ in 0..5 {
                    let runs: [&(dyn Fn() -> f32 + Sync); 4] = [
                        &|| trace_all(&raypack, &rays, Kernel::Scalar),
                        &|| trace_all(&raypack, &rays, Kernel::Packet8),
                        &|| trace_all(&embree, &rays, Kernel::Scalar),
                        &|| trace_all(&embree, &rays, Kernel::Packet8),
                    ];
                    for (slot, run) in best.iter_mut().zip(runs) {
                        let start = Instant::now();
                        black_box(run());
                        *slot = slot.min(start.elapsed().as_secs_f64());
                    }
                }
            });
            let mrays = best.map(|s| rays.len() as f64 / s / 1e6);
            println!(
                "{:<28} {:>3} {:>14.2} {:>14.2} {:>14.2} {:>14.2} {:>13.3}x {:>13.3}x",
                format!(
                    "{} ({})",
                    scene.source.trim_start_matches("generated:"),
                    scene.primitives.len()
                ),
                threads,
                mrays[0],
                mrays[1],
                mrays[2],
                mrays[3],
                mrays[0] / mrays[2],
                mrays[1] / mrays[3]
            );
        }
    }
    println!("(ratio = raypack / Embree Mrays/s; above 1 means raypack is faster)\n");
}

fn criterion_group(c: &mut Criterion, size: u32) {
    let device = Arc::new(Device::new(DEFAULT_CONFIG).expect("Embree device"));
    let scene = test_scenes::by_name("mixed", 5000, 1).expect("generated scene");
    let raypack = Bvh::new(&scene.primitives);
    let embree = EmbreeScene::new(device, &scene.primitives).expect("Embree scene");
    let rays = rays_of(&scene, size);
    let pool = pool(1);
    let mut group = c.benchmark_group("embree_vs_raypack_mixed_1_thread");
    group
        .throughput(Throughput::Elements(rays.len() as u64))
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    let variants: [(&str, &(dyn Fn() -> f32 + Sync)); 4] = [
        ("raypack_scalar", &|| trace_all(&raypack, &rays, Kernel::Scalar)),
        ("raypack_packet8", &|| trace_all(&raypack, &rays, Kernel::Packet8)),
        ("embree_rtcIntersect1", &|| {
            trace_all(&embree, &rays, Kernel::Scalar)
        }),
        ("embree_rtcIntersect8", &|| {
            trace_all(&embree, &rays, Kernel::Packet8)
        }),
    ];
    for (name, run) in variants {
        group.bench_function(BenchmarkId::new(name, format!("{size}x{size}")), |b| {
            b.iter(|| pool.install(run))
        });
    }
    group.finish();
}

fn main() {
    // Builds one after another reuse warm pages, as in the binary.
    raypack::huge_pages::keep_freed_memory();
    let size = std::env::var("RAYPACK_BENCH_SIZE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(256);
    side_by_side(size);
    let mut c = Criterion::default().configure_from_args();
    criterion_group(&mut c, size.min(128));
    c.final_summary();
}
