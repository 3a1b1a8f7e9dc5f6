//! `stats --spd` on the SPD files generated into `scenes/` (by `raypack gen`):
//! identical counts for the scalar and packet kernels and for the BVH and
//! brute force on the small variants, and the published counts within their
//! stated 10% on the generated full-size scenes (with the BVH: brute force
//! takes too long on them for a test).

use std::path::{Path, PathBuf};

use clap::ValueEnum;

use raypack::accel::{Accel, BruteForce, Bvh};
use raypack::render::spd::spd_counts;
use raypack::render::spd_published::{Published, table};
use raypack::render::{KernelKind, RayCounts};
use raypack::scene::generate::{Kind, Params};

/// The small variants of the SPD scenes in `scenes/`.
const SMALL_SPD_SCENES: [&str; 7] = [
    "spd_tetra_small.nff",
    "spd_balls_small.nff",
    "spd_mount_small.nff",
    "spd_gears_small.nff",
    "spd_rings_small.nff",
    "spd_tree_small.nff",
    "spd_teapot_small.nff",
];

/// The bundled scene `name`, which must be there.
fn scene_path(name: &str) -> PathBuf {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name);
    assert!(p.is_file(), "{} is bundled in scenes/", p.display());
    p
}

fn counts_with(scene: &raypack::scene::Scene, accel: &impl Accel, kernel: KernelKind) -> RayCounts {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    spd_counts(scene, accel, kernel, &pool).unwrap()
}

/// The BVH's counts, under the scalar and the 8-wide packet kernel, equal
/// brute force's (the reference, traced once, with the scalar kernel: its
/// packet paths agree with its single rays in `tests/bvh/brute_force.rs`).
#[test]
fn small_spd_scenes_count_the_same_with_the_bvh_and_brute_force() {
    for name in SMALL_SPD_SCENES {
        let path = scene_path(name);
        let scene = raypack::scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let brute = counts_with(&scene, &BruteForce::new(&scene.primitives), KernelKind::Scalar);
        assert!(brute.eye_hits > 0 && brute.shadow_rays > 0, "{name}: {brute:?}");
        let bvh = Bvh::new(&scene.primitives);
        for kernel in [KernelKind::Scalar, KernelKind::Packet8] {
            assert_eq!(counts_with(&scene, &bvh, kernel), brute, "{name} {kernel:?}");
        }
    }
}

/// The scalar, 8-wide and 16-wide packet kernels count the same rays, through
/// the BVH (which matches brute force, above).
#[test]
fn small_spd_scenes_count_the_same_with_both_kernels() {
    for name in SMALL_SPD_SCENES {
        let path = scene_path(name);
        let scene = raypack::scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let bvh = Bvh::new(&scene.primitives);
        let scalar = counts_with(&scene, &bvh, KernelKind::Scalar);
        assert_eq!(scalar, counts_with(&scene, &bvh, KernelKind::Packet8), "{name}");
        assert_eq!(scalar, counts_with(&scene, &bvh, KernelKind::Packet16), "{name}");
        assert_eq!(scalar.eye_rays, 513 * 513);
        assert!(
            scalar.eye_hits > 0 && scalar.shadow_rays > 0,
            "{name}: {scalar:?}"
        );
    }
}

/// Every SPD scene `raypack gen` writes, at its default size, counts its rays
/// within the SPD's stated 10% of Haines' published table, count by count.
#[test]
fn generated_spd_scenes_match_the_published_counts_within_ten_percent() {
    for name in ["balls", "gears", "mount", "rings", "teapot", "tetra", "tree"] {
        let published = Published::find(name).unwrap();
        let kind = Kind::from_str(name, true).unwrap_or_else(|e| panic!("no generator for {name}: {e}"));
        let params = Params::new(kind, None, None).unwrap();
        let scene = raypack::scene::nff::parse(Path::new(name), params.to_nff().as_bytes()).unwrap();
        assert_eq!(scene.primitives.len() as u64, published.primitives, "{name}");
        let c = counts_with(&scene, &Bvh::new(&scene.primitives), KernelKind::Packet8);
        let rows = published.compare(&c);
        println!("{}", table(published, &rows));
        for row in rows {
            assert!(row.within_tolerance(), "{name}: {row:?}");
        }
    }
}
