//! `stats --spd` on the SPD files generated into `scenes/` (by `raypack gen`):
//! identical counts for the scalar and packet kernels and for the BVH and
//! brute force, and the published
//! counts within their stated 10% (tetra at size factor 4; the other
//! full-size scenes take too long by brute force for a test, see the README).

use std::path::PathBuf;

use raypack::accel::{Accel, BruteForce, Bvh};
use raypack::render::spd::spd_counts;
use raypack::render::{KernelKind, RayCounts};

fn scene_path(name: &str) -> Option<PathBuf> {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name);
    p.is_file().then_some(p)
}

fn counts(path: &std::path::Path, kernel: KernelKind) -> RayCounts {
    let scene = raypack::scene::load(path).unwrap_or_else(|e| panic!("{e}"));
    counts_with(&scene, &BruteForce::new(&scene.primitives), kernel)
}

fn counts_with(scene: &raypack::scene::Scene, accel: &impl Accel, kernel: KernelKind) -> RayCounts {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    spd_counts(scene, accel, kernel, &pool).unwrap()
}

#[test]
fn small_spd_scenes_count_the_same_with_the_bvh_and_brute_force() {
    for name in [
        "spd_tetra_small.nff",
        "spd_balls_small.nff",
        "spd_mount_small.nff",
    ] {
        let path = scene_path(name).expect("the SPD scenes are in scenes/");
        let scene = raypack::scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let bvh = Bvh::new(&scene.primitives);
        for kernel in [KernelKind::Scalar, KernelKind::Packet8] {
            let brute = counts_with(&scene, &BruteForce::new(&scene.primitives), kernel);
            assert_eq!(counts_with(&scene, &bvh, kernel), brute, "{name} {kernel:?}");
            assert!(brute.eye_hits > 0 && brute.shadow_rays > 0, "{name}: {brute:?}");
        }
    }
}

#[test]
fn small_spd_scenes_count_the_same_with_both_kernels() {
    for name in [
        "spd_tetra_small.nff",
        "spd_balls_small.nff",
        "spd_mount_small.nff",
    ] {
        let Some(path) = scene_path(name) else {
            continue;
        };
        let scalar = counts(&path, KernelKind::Scalar);
        assert_eq!(scalar, counts(&path, KernelKind::Packet8), "{name}");
        assert_eq!(scalar.eye_rays, 513 * 513);
        assert!(
            scalar.eye_hits > 0 && scalar.shadow_rays > 0,
            "{name}: {scalar:?}"
        );
    }
}

#[test]
fn tetra_matches_the_published_counts_within_ten_percent() {
    let Some(path) = scene_path("spd_tetra.nff") else {
        return;
    };
    let c = counts(&path, KernelKind::Packet8);
    // Published (NFF.md): eye hits 49788, reflect 0, refract 0, shadow 46112.
    let within = |got: u64, published: u64| (got as f64 - published as f64).abs() <= 0.1 * published as f64;
    assert!(within(c.eye_hits, 49_788), "{c:?}");
    assert!(within(c.shadow_rays, 46_112), "{c:?}");
    assert_eq!((c.reflect_rays, c.refract_rays), (0, 0));
}
