//! The scene readers, one test crate: NFF, the native TOML format, OBJ, PLY,
//! and the files of `scenes/` and `tests/data/` (fuzz findings among them).

#[path = "../support/mod.rs"]
mod support;

use std::path::{Path, PathBuf};

use raypack::geometry::{Primitive, PrimitiveKind};
use raypack::scene::Scene;

mod files;
mod gltf;
mod native;
mod nff;
mod obj;
mod ply;

/// A file of `tests/data/`.
pub fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// Assert `result` is an error whose message starts with `prefix` and contains `needle`.
#[track_caller]
pub fn assert_error(result: Result<Scene, String>, prefix: &str, needle: &str) {
    match result {
        Ok(_) => panic!("expected an error starting with {prefix:?}"),
        Err(e) => assert!(
            e.starts_with(prefix) && e.contains(needle),
            "got {e:?}, wanted {prefix:?} … {needle:?}"
        ),
    }
}

/// The kind of each primitive of `scene`, in order.
pub fn kinds(scene: &Scene) -> Vec<PrimitiveKind> {
    scene.primitives.iter().map(Primitive::kind).collect()
}

/// The pyramid of `tests/data/pyramid.*`: a quad base, then its 4 sides.
pub const PYRAMID_KINDS: [PrimitiveKind; 5] = [
    PrimitiveKind::Polygon,
    PrimitiveKind::Triangle,
    PrimitiveKind::Triangle,
    PrimitiveKind::Triangle,
    PrimitiveKind::Triangle,
];
