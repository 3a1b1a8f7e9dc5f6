//! Running the `raypack` binary from integration tests.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Run `raypack` with `args` and wait for it.
pub fn raypack(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_raypack"))
        .args(args)
        .output()
        .unwrap()
}

/// `raypack trace SCENE --rays RAYS --out OUT`, then `extra` (`--engine`,
/// `--kernel`, `--diff` …).
pub fn trace(scene: &str, rays: &Path, out: &Path, extra: &[&str]) -> Output {
    let (rays, out) = (rays.to_str().unwrap(), out.to_str().unwrap());
    raypack(&[&["trace", scene, "--rays", rays, "--out", out], extra].concat())
}

/// `scenes/spd_balls_small.nff`: 92 primitives, the scene the bench tests time.
pub const SMALL_SCENE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/spd_balls_small.nff");

/// `raypack bench scene` on [`SMALL_SCENE`] with `args` and `--json`: the
/// result it printed.
pub fn bench_scene_json(args: &[&str]) -> serde_json::Value {
    let o = raypack(&[&["bench", "scene", SMALL_SCENE], args, &["--json"]].concat());
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    serde_json::from_slice(&o.stdout).expect("JSON on stdout")
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
