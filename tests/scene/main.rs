//! The scene readers, one test crate: NFF, the native TOML format, OBJ, PLY,
//! and the files of `scenes/` and `tests/data/` (fuzz findings among them).

#[path = "../support/mod.rs"]
mod support;

mod files;
mod native;
mod nff;
mod obj;
mod ply;
