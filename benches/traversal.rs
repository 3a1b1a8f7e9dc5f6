//! Criterion bench of the BVH: build time, and single-ray vs 8-ray packet
//! traversal of each standard ray kind (primary rays through 1024×1024 pixel
//! centres in 4×2-pixel packets, shadow, ambient-occlusion and diffuse rays
//! from their hits, and random rays), on generated scenes of 10³…10⁶ triangles and spheres, and on the
//! Stanford dragon when `assets/dragon.ply` is present
//! (`scripts/fetch-assets.sh`). Run one group at a time on a shared machine,
//! e.g. `cargo bench --bench traversal -- mesh-100000`.

use std::path::Path;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use raypack::accel::Bvh;
use raypack::bench::rays::RayKind;
use raypack::bench::traversal::{TraversalSetup, scene_bounds, trace_packets, trace_single};
use raypack::scene::generate::random::framing_camera;

// The BVH of a large scene on huge pages, as the `raypack` binary has it.
#[global_allocator]
static ALLOC: raypack::huge_pages::HugePageAlloc = raypack::huge_pages::HugePageAlloc;

const RESOLUTION: u32 = 1024;
const RANDOM_RAYS: usize = 1 << 18;

fn bench_setup(c: &mut Criterion, setup: &TraversalSetup) {
    let mut group = c.benchmark_group(&setup.name);
    group.sample_size(10);
    group.bench_function("build", |b| b.iter(|| Bvh::new(&setup.scene.primitives)));
    let bvh = Bvh::new(&setup.scene.primitives);
    for set in &setup.kinds {
        group.throughput(Throughput::Elements(set.rays.len() as u64));
        group.bench_function(BenchmarkId::new(set.kind.name(), "single"), |b| {
            b.iter(|| trace_single(&bvh, set))
        });
        group.bench_function(BenchmarkId::new(set.kind.name(), "packet8"), |b| {
            b.iter(|| trace_packets(&bvh, set))
        });
    }
    group.finish();
}

fn generated(c: &mut Criterion) {
    // Builds one after another reuse warm pages, as in the binary.
    raypack::huge_pages::keep_freed_memory();
    for kind in ["mesh", "spheres"] {
        for n in [1_000, 10_000, 100_000, 1_000_000] {
            let setup =
                TraversalSetup::generated(kind, n, (RESOLUTION, RESOLUTION), RANDOM_RAYS, &RayKind::ALL)
                    .expect("a known scene kind");
            bench_setup(c, &setup);
        }
    }
}

fn dragon(c: &mut Criterion) {
    let path = Path::new("assets/dragon.ply");
    if !path.exists() {
        eprintln!(
            "dragon: skipped, {} is missing (run scripts/fetch-assets.sh)",
            path.display()
        );
        return;
    }
    let scene = raypack::scene::load(path).unwrap_or_else(|e| panic!("{e}"));
    let camera = match scene.camera {
        Some(spec) => spec.camera_at(RESOLUTION, RESOLUTION).expect("a valid camera"),
        None => framing_camera(scene_bounds(&scene), RESOLUTION, RESOLUTION),
    };
    let light = scene.lights.first().map(|l| l.position);
    bench_setup(
        c,
        &TraversalSetup::new("dragon", scene, &camera, light, RANDOM_RAYS, &RayKind::ALL),
    );
}

criterion_group!(benches, generated, dragon);
criterion_main!(benches);
