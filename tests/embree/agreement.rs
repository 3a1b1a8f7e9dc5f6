//! raypack and Embree agree hit by hit: on every generated scene (random
//! triangles, spheres, polygons, transformed objects, planes, a closed mesh, a
//! sphereflake, a mix) and every scene file in `scenes/`, on primary and random
//! rays, through the scalar (`rtcIntersect1`) and packet (`rtcIntersect8`) paths.
//!
//! The bars: at least 99.99% hit/miss agreement and 99.99% same-primitive
//! agreement, p99 t error (the hit points' distance over their scale) at most
//! 1e-5. The disagreements these bars allow are examined in
//! `edge_cases.rs` (ties where surfaces share or cross a point, leaks
//! through shared edges); the rare "different primitive" on random rays is a ray
//! passing within float precision of a polygon's or triangle's outline, which
//! one engine counts as inside and the other as outside.

use std::path::Path;
use std::sync::Arc;

use raypack::accel::Bvh;
use raypack::compare::{Agreement, AgreementOptions, Kernel, primary_rays, random_rays, trace_rays};
use raypack::embree::{Device, EmbreeScene};
use raypack::scene::Scene;
use raypack::scene::generate::test_scenes::{self, NAMES};

const MIN_AGREEMENT: f64 = 0.9999;
/// One bar for every scene, instances included. Measured as the relative
/// `|Δt| / t` it had to be 2e-5 for a scene of instances: p99 0.9–1.4·10⁻⁵ over
/// seeds, all of it from random rays that start near a surface (t < 0.5),
/// where both engines' absolute rounding of about 10⁻⁶ (coordinates up to 5
/// taken through their f32 transforms) is a large part of t. The t error is
/// now that distance over the hit point's scale (`compare::agreement`), which
/// that rounding does not inflate.
const MAX_T_ERROR_P99: f64 = 1e-5;

fn device() -> Arc<Device> {
    Arc::new(Device::with_default_config().expect("Embree device"))
}

/// Compare on the scene camera's primary rays (at most `side` pixels a side)
/// and `random` random rays, both kernels. raypack's side is its BVH, which
/// answers bit for bit as brute force does (`tests/bvh`).
fn check_scene(scene: &Scene, embree: &EmbreeScene, side: u32, random: usize) {
    let raypack = Bvh::new(&scene.primitives);
    let spec = scene.camera.unwrap_or_else(|| scene.default_camera());
    let scale = (side as f32 / spec.width.max(spec.height) as f32).min(1.0);
    let size = |n: u32| ((n as f32 * scale).round() as u32).max(1);
    let camera = spec
        .camera_at(size(spec.width), size(spec.height))
        .expect("camera");
    let sets = [
        ("primary", primary_rays(&camera)),
        ("random", random_rays(scene.bounds(), random, 5)),
    ];
    for (set, rays) in &sets {
        for kernel in [Kernel::Scalar, Kernel::Packet8] {
            let a = trace_rays(&raypack, rays, kernel);
            let b = trace_rays(embree, rays, kernel);
            let g = Agreement::compare(&scene.primitives, rays, &a, &b, AgreementOptions::default());
            eprintln!(
                "{} ({}) {set} {kernel:?}: hit {:.6} prim {:.6} ties {} different {} only raypack {} only embree {} t error p50 {:.1e} p99 {:.1e} max {:.1e}",
                scene.source,
                if embree.is_robust() { "robust" } else { "fast" },
                g.hit_agreement(),
                g.primitive_agreement(),
                g.ties,
                g.different_primitive,
                g.only_a,
                g.only_b,
                g.t_error.p50,
                g.t_error.p99,
                g.t_error.max
            );
            let what = format!("{} / {set} / {kernel:?}: {g:#?}", scene.source);
            assert!(
                g.same_primitive > rays.len() / 20,
                "too few hits to compare: {what}"
            );
            assert!(g.hit_agreement() >= MIN_AGREEMENT, "{what}");
            assert!(g.primitive_agreement() >= MIN_AGREEMENT, "{what}");
            assert!(g.t_error.p99 <= MAX_T_ERROR_P99, "{what}");
        }
    }
}

#[test]
fn generated_scenes_agree_with_robust_embree() {
    let device = device();
    for name in NAMES {
        let scene = test_scenes::by_name(name, 600, 11).unwrap();
        let embree = EmbreeScene::robust(device.clone(), &scene.primitives).expect("Embree scene");
        check_scene(&scene, &embree, 256, 100_000);
    }
    // The SPD sphereflake, 91 spheres on a floor polygon.
    let flake = test_scenes::from_spec("gen:sphereflake:2").unwrap().unwrap();
    let embree = EmbreeScene::robust(device.clone(), &flake.primitives).expect("Embree scene");
    check_scene(&flake, &embree, 256, 100_000);
}

#[test]
fn fast_mode_embree_meets_the_same_bars() {
    let scene = test_scenes::by_name("mixed", 600, 12).unwrap();
    let embree = EmbreeScene::new(device(), &scene.primitives).expect("Embree scene");
    check_scene(&scene, &embree, 256, 100_000);
}

#[test]
fn scene_files_agree_with_robust_embree() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    files.retain(|p| {
        let name = p.to_string_lossy().to_lowercase();
        [".nff", ".obj", ".ply", ".ply.gz", ".toml"]
            .iter()
            .any(|ext| name.ends_with(ext))
    });
    files.sort();
    assert!(!files.is_empty(), "no scene files in {}", dir.display());
    let device = device();
    for path in &files {
        let scene = raypack::scene::load(path).unwrap_or_else(|e| panic!("{e}"));
        let embree = EmbreeScene::robust(device.clone(), &scene.primitives).expect("Embree scene");
        check_scene(&scene, &embree, 512, 100_000);
    }
    eprintln!("{} scene files checked in {}", files.len(), dir.display());
}
