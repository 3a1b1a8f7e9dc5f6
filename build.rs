//! Build script. It acts only for the `embree` feature: it finds the directory
//! holding `libembree4.so`, adds it to the link search path, and records it as an
//! rpath so that binaries, tests and benches run without `LD_LIBRARY_PATH`.
//!
//! The directory is, in order: `$EMBREE4_LIB_DIR`; the cache that
//! `scripts/install-embree.sh` fills (`~/.cache/raypack/embree-4.4.0`); a system
//! library directory (Debian 13+ `libembree-dev`).

use std::env;
use std::path::{Path, PathBuf};

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

fn link_from(dir: &Path) {
    println!("cargo:rustc-link-search=native={}", dir.display());
    println!("cargo:rustc-link-arg=-Wl,-rpath,{}", dir.display());
}
