//! raypack and Embree agree hit by hit: on every generated scene (random
//! triangles, spheres, polygons, transformed objects, planes, a closed mesh, a
//! sphereflake, a mix) and every scene file in `scenes/`, on primary and random
//! rays, through the scalar (`rtcIntersect1`) and packet (`rtcIntersect8`) paths.
#![cfg(feature = "embree")]

use std::sync::Arc;

use raypack::accel::BruteForce;
use raypack::compare::test_scenes::{self, NAMES};
use raypack::compare::{Agreement, AgreementOptions, Kernel, primary_rays, random_rays, trace_rays};
use raypack::embree::{Device, EmbreeScene};
use raypack::scene::Scene;

/// The acceptance bars: hit/miss and primitive agreement, and the p99 relative t error.
const MIN_AGREEMENT: f64 = 0.9999;
const MAX_T_ERROR_P99: f64 = 1e-5;

fn device() -> Arc<Device> {
    Arc::new(Device::with_default_config().expect("Embree device"))
}

fn check_scene(device: &Arc<Device>, scene: &Scene, random: usize) {
    let embree = EmbreeScene::new(device.clone(), &scene.primitives).expect("Embree scene");
    let raypack = BruteForce::new(&scene.primitives);
    let camera = scene
        .camera
        .unwrap_or_else(|| scene.default_camera())
        .camera()
        .expect("camera");
    let sets = [
        ("primary", primary_rays(&camera)),
        ("random", random_rays(scene.bounds(), random, 5)),
    ];
    for (set, rays) in &sets {
        for kernel in [Kernel::Scalar, Kernel::Packet8] {
            let a = trace_rays(&raypack, rays, kernel);
            let b = trace_rays(&embree, rays, kernel);
            let g = Agreement::compare(rays, &a, &b, AgreementOptions::default());
            let what = format!("{} / {set} / {kernel:?}: {g:#?}", scene.source);
            eprintln!(
                "{} {set} {kernel:?}: hit {:.6} prim {:.6} (+ties {:.6}) ties {} diff {} only_raypack {} only_embree {} t_err p50 {:.2e} p99 {:.2e} max {:.2e}",
                scene.source,
                g.hit_agreement(),
                g.primitive_agreement(),
                g.primitive_agreement_with_ties(),
                g.ties,
                g.different_primitive,
                g.only_a,
                g.only_b,
                g.t_error.p50,
                g.t_error.p99,
                g.t_error.max
            );
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
fn generated_scenes_agree() {
    let device = device();
    for name in NAMES {
        let scene = test_scenes::by_name(name, 600, 11).unwrap();
        check_scene(&device, &scene, 100_000);
    }
}
