//! Build script. It records the build for `raypack env` (the compiler's
//! version, the profile, the flags and the git commit, as `RAYPACK_BUILD_*`
//! variables that `src/environment.rs` reads with `env!`; the optimisation
//! level too, for `tests/cli/inlining.rs`), and, for the `embree`
//! feature, finds the directory holding `libembree4.so`, adds it to the link
//! search path, and records it as an rpath so that binaries, tests and benches
//! run without `LD_LIBRARY_PATH`.
//!
//! The directory is, in order: `$EMBREE4_LIB_DIR`; the cache that
//! `scripts/install-embree.sh` fills (`~/.cache/raypack/embree-4.4.0`); a system
//! library directory (Debian 13+ `libembree-dev`).

use std::env;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Where `scripts/install-embree.sh` unpacks the Embree wheel (keep the two in step).
const CACHE_SUBDIR: &str = "raypack/embree-4.4.0";

/// System directories the linker searches anyway (no rpath needed there).
const SYSTEM_DIRS: [&str; 4] = [
    "/usr/lib/x86_64-linux-gnu",
    "/usr/lib64",
    "/usr/lib",
    "/usr/local/lib",
];

fn has_embree(dir: &Path) -> bool {
    dir.join("libembree4.so").exists()
}

fn cache_dir() -> Option<PathBuf> {
    let base = env::var_os("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .or_else(|| env::var_os("HOME").map(|home| PathBuf::from(home).join(".cache")))?;
    Some(base.join(CACHE_SUBDIR))
}

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=EMBREE4_LIB_DIR");
    println!("cargo:rerun-if-env-changed=XDG_CACHE_HOME");
    record_build();
    if env::var_os("CARGO_FEATURE_EMBREE").is_none() {
        return;
    }
    // Step 1: an explicit directory wins, and must be right.
    if let Some(dir) = env::var_os("EMBREE4_LIB_DIR").map(PathBuf::from) {
        if !has_embree(&dir) {
            panic!(
                "EMBREE4_LIB_DIR={} holds no libembree4.so (run scripts/install-embree.sh)",
                dir.display()
            );
        }
        link_from(&dir);
        return;
    }
    // Step 2: the installer's cache.
    if let Some(dir) = cache_dir() {
        println!("cargo:rerun-if-changed={}", dir.display());
        if has_embree(&dir) {
            link_from(&dir);
            return;
        }
    }
    // Step 3: the system's Embree 4, found by the linker on its own.
    if SYSTEM_DIRS.iter().any(|d| has_embree(Path::new(d))) {
        return;
    }
    panic!(
        "the `embree` feature needs Embree 4: run scripts/install-embree.sh \
         (or set EMBREE4_LIB_DIR to the directory holding libembree4.so)"
    );
}

/// The output of `program args…`, trimmed, if it ran and succeeded.
fn output_of(program: &str, args: &[&str]) -> Option<String> {
    let out = Command::new(program).args(args).output().ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

/// The build, for `raypack env`: rustc's version, the profile, the flags
/// (`CARGO_ENCODED_RUSTFLAGS`, separated by spaces) and the git commit
/// ("unknown" outside a git checkout), and whether the sources differ from it.
/// The script runs again when HEAD moves, so the commit stays current.
fn record_build() {
    let rustc = env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let version = output_of(&rustc, &["--version"]).unwrap_or_else(|| "unknown".into());
    let profile = env::var("PROFILE").unwrap_or_else(|_| "unknown".into());
    let flags = env::var("CARGO_ENCODED_RUSTFLAGS")
        .unwrap_or_default()
        .replace('\x1f', " ");
    let commit = output_of("git", &["rev-parse", "HEAD"]).unwrap_or_else(|| "unknown".into());
    // Sources that differ from the commit (edited, or new and untracked) make
    // a figure measured with this build not the commit's: say so beside it.
    // The script runs again when they change, so the mark stays current.
    let sources = ["src", "build.rs", "Cargo.toml", "Cargo.lock"];
    let status = [&["status", "--porcelain", "--"][..], &sources[..]].concat();
    let modified = output_of("git", &status).is_some_and(|s| !s.is_empty());
    for path in sources {
        println!("cargo:rerun-if-changed={path}");
    }
    // HEAD, and the branch it points to (in a worktree, both live in the common dir).
    for path in ["HEAD", "packed-refs"]
        .into_iter()
        .filter_map(|p| output_of("git", &["rev-parse", "--git-path", p]))
        .chain(
            output_of("git", &["symbolic-ref", "-q", "HEAD"])
                .and_then(|r| output_of("git", &["rev-parse", "--git-path", &r])),
        )
        .filter(|p| Path::new(p).exists())
    {
        // (A missing file would rerun the script on every build.)
        println!("cargo:rerun-if-changed={path}");
    }
    println!("cargo:rustc-env=RAYPACK_BUILD_RUSTC={version}");
    println!("cargo:rustc-env=RAYPACK_BUILD_PROFILE={profile}");
    // The optimisation level (the profile name does not say it: `cargo test`
    // builds `debug` at the test profile's level), for checks that only mean
    // something in an optimised build.
    let opt_level = env::var("OPT_LEVEL").unwrap_or_else(|_| "unknown".into());
    println!("cargo:rustc-env=RAYPACK_BUILD_OPT_LEVEL={opt_level}");
    println!("cargo:rustc-env=RAYPACK_BUILD_RUSTFLAGS={flags}");
    println!("cargo:rustc-env=RAYPACK_BUILD_COMMIT={commit}");
    println!("cargo:rustc-env=RAYPACK_BUILD_MODIFIED={modified}");
    println!("cargo:rustc-env=RAYPACK_LOCKED_VERSIONS={}", locked_versions());
    println!("cargo:rustc-env=RAYPACK_BUILD_FEATURES={}", enabled_features());
}

/// The cargo features this build has, `a,b` (cargo sets `CARGO_FEATURE_A`
/// for each), so that `raypack env` lists them without a list of its own.
fn enabled_features() -> String {
    let mut features: Vec<String> = env::vars()
        .filter_map(|(k, _)| Some(k.strip_prefix("CARGO_FEATURE_")?.to_lowercase().replace('_', "-")))
        .filter(|f| f != "default")
        .collect();
    features.sort();
    features.join(",")
}

/// The peer engines' versions locked in `Cargo.lock`, `name=version,…`, for
/// their captions (`engines::peer_version`).
fn locked_versions() -> String {
    const PEERS: [&str; 4] = ["embree4-sys", "obvhs", "bvh", "tinybvh-rs"];
    let lock = std::fs::read_to_string("Cargo.lock").unwrap_or_default();
    let mut found = Vec::new();
    let mut name = None;
    for line in lock.lines() {
        if let Some(n) = line.strip_prefix("name = ") {
            name = Some(n.trim_matches('"'));
        } else if let (Some(n), Some(v)) = (name, line.strip_prefix("version = ")) {
            if PEERS.contains(&n) {
                found.push(format!("{n}={}", v.trim_matches('"')));
            }
            name = None;
        }
    }
    found.join(",")
}

fn link_from(dir: &Path) {
    println!("cargo:rustc-link-search=native={}", dir.display());
    println!("cargo:rustc-link-arg=-Wl,-rpath,{}", dir.display());
}
