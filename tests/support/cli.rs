//! Running the `raypack` binary from integration tests.

use std::path::PathBuf;
use std::process::{Command, Output};

/// Run `raypack` with `args` and wait for it.
pub fn raypack(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_raypack"))
        .args(args)
        .output()
        .unwrap()
}

/// A `bench traversal` small enough for a test: two tiny generated meshes,
/// 32×16 primary rays, 256 random rays, one round.
pub const TINY_TRAVERSAL: [&str; 10] = [
    "bench",
    "traversal",
    "--sizes",
    "200,400",
    "--size",
    "32x16",
    "--random",
    "256",
    "--rounds",
    "1",
];

/// A fresh, empty directory for test `name` of this process.
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("raypack-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// What the command wrote to stderr.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}
