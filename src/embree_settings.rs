//! How Embree is configured: its scene mode, its kernels, its device string,
//! as command-line choices. The bottom floor: it imports nothing, so the
//! `embree` wrapper below the engine registry and the commands above it agree.

/// How Embree builds its scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum EmbreeMode {
    /// `RTC_SCENE_FLAG_ROBUST`: watertight triangles, the reference for checks.
    Robust,
    /// Embree's default flags: its fastest mode, the one benchmarks compare with.
    Fast,
}

/// The device configuration the comparisons use by default: Embree's 8-wide
/// AVX2 kernels, matching raypack's 8-wide packets, and one BVH build thread
/// ([`embree_config`] of 1).
pub const DEFAULT_EMBREE_CONFIG: &str = "threads=1,isa=avx2";

/// The device configuration of [`DEFAULT_EMBREE_CONFIG`] with `threads` BVH
/// build threads, for build times compared at raypack's thread count.
pub fn embree_config(threads: usize) -> String {
    EmbreeIsa::Avx2.config(threads)
}

/// Which of Embree's kernels a benchmark runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum EmbreeIsa {
    /// `isa=avx2`: Embree's 8-wide kernels, matching raypack's 8-wide packets.
    Avx2,
    /// No `isa` given: Embree picks its best kernels for the CPU (AVX-512
    /// where there is one), the fastest Embree a user gets.
    Default,
}

impl EmbreeIsa {
    /// The device configuration with `threads` BVH build threads.
    pub fn config(self, threads: usize) -> String {
        match self {
            EmbreeIsa::Avx2 => format!("threads={threads},isa=avx2"),
            EmbreeIsa::Default => format!("threads={threads}"),
        }
    }

    /// The name in tables and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            EmbreeIsa::Avx2 => "avx2",
            EmbreeIsa::Default => "default",
        }
    }
}

/// What to tell a user who asks for Embree in a build without it.
pub const EMBREE_MISSING: &str = "this raypack was built without the `embree` feature: run \
     scripts/install-embree.sh, then build with `cargo build --release --features embree`";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_config_is_the_one_thread_config() {
        assert_eq!(DEFAULT_EMBREE_CONFIG, embree_config(1));
        assert_eq!(embree_config(2), "threads=2,isa=avx2");
        assert_eq!(EmbreeIsa::Default.config(2), "threads=2");
    }
}
