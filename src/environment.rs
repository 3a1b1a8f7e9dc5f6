//! The machine and the build a measurement ran on, for every result that
//! carries figures: a figure without its machine is not a result.
//!
//! The CPU comes from `/proc/cpuinfo`, the transparent-huge-page mode from
//! `/sys/kernel/mm/transparent_hugepage/enabled`; the compiler, the profile, the
//! flags and the git commit are recorded by `build.rs` when raypack is built.
//! Embree's version and device configuration are filled in by the caller that
//! made an Embree device ([`Environment::with_embree`]), since this module sits
//! below the Embree layer.

use std::sync::OnceLock;
use std::time::{SystemTime, UNIX_EPOCH};

use serde::{Deserialize, Serialize};

use crate::simd::Isa;

/// The ISA extensions raypack's kernels care about, by `target_feature` name.
pub const ISA_FEATURES: [&str; 5] = ["sse4.2", "avx", "avx2", "fma", "avx512f"];

/// Embree's side of the environment.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct EmbreeInfo {
    /// The library's version, `major.minor.patch`.
    pub version: String,
    /// The device configuration string.
    pub config: String,
}

/// The machine and the build.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Environment {
    /// CPU model name ("unknown" without `/proc/cpuinfo`).
    pub cpu_model: String,
    /// Logical CPUs this process may run on.
    pub threads: usize,
    /// Physical cores (distinct `physical id`/`core id` pairs), if the kernel says.
    pub physical_cores: Option<usize>,
    /// ISA extensions of [`ISA_FEATURES`] the build compiled in (`target_feature`).
    pub isa_build: Vec<String>,
    /// ISA extensions of [`ISA_FEATURES`] the CPU has.
    pub isa_cpu: Vec<String>,
    /// The instruction set raypack's BVH queries ran on
    /// ([`Isa::default_level`]: the best the CPU has, or `--isa`); empty in
    /// results stored before it was recorded.
    #[serde(default)]
    pub isa: String,
    /// The ray/triangle test of the run's scenes (`--triangle`); empty where
    /// the command does not load scenes, and in results stored before it was recorded.
    #[serde(default)]
    pub triangle_test: String,
    /// Transparent huge pages: the selected mode (`always`, `madvise`, `never`) or "unavailable".
    pub thp: String,
    /// The largest cache level of the CPU ([`last_level_cache`]), if the
    /// kernel says (none in results stored before it was recorded).
    #[serde(default)]
    pub last_level_cache: Option<CacheLevel>,
    /// Target architecture and operating system.
    pub target: String,
    /// `rustc --version` of the build.
    pub rustc: String,
    /// Cargo profile (`debug` or `release`; benches and tests report their base profile).
    pub profile: String,
    /// `RUSTFLAGS` of the build, space-separated.
    pub rustflags: String,
    /// Cargo features enabled.
    pub features: Vec<String>,
    /// Git commit the build was made from, or "unknown".
    pub git_commit: String,
    /// Whether the build's sources (`src`, `build.rs`, `Cargo.toml`,
    /// `Cargo.lock`) differed from that commit: uncommitted changes, or new
    /// files (false in results stored before this was recorded).
    #[serde(default)]
    pub git_modified: bool,
    /// Embree, when the build has it and a device was made.
    pub embree: Option<EmbreeInfo>,
    /// When this was collected: UTC, `YYYY-MM-DDTHH:MM:SSZ`.
    pub date: String,
}

impl Environment {
    /// The environment of this process now (without Embree).
    pub fn collect() -> Self {
        let cpuinfo = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
        let thp = std::fs::read_to_string("/sys/kernel/mm/transparent_hugepage/enabled").ok();
        let seconds = SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .map_or(0, |d| d.as_secs());
        Self {
            cpu_model: cpu_model(&cpuinfo).unwrap_or_else(|| "unknown".into()),
            threads: std::thread::available_parallelism().map_or(1, |n| n.get()),
            physical_cores: physical_cores(&cpuinfo),
            isa_build: isa_build(),
            isa_cpu: isa_cpu(),
            isa: Isa::default_level().name().to_string(),
            triangle_test: String::new(),
            thp: thp
                .as_deref()
                .and_then(thp_mode)
                .unwrap_or("unavailable")
                .to_string(),
            last_level_cache: last_level_cache(),
            target: format!("{}-{}", std::env::consts::ARCH, std::env::consts::OS),
            rustc: env!("RAYPACK_BUILD_RUSTC").to_string(),
            profile: env!("RAYPACK_BUILD_PROFILE").to_string(),
            rustflags: env!("RAYPACK_BUILD_RUSTFLAGS").to_string(),
            features: env!("RAYPACK_BUILD_FEATURES")
                .split(',')
                .filter(|f| !f.is_empty())
                .map(String::from)
                .collect(),
            git_commit: env!("RAYPACK_BUILD_COMMIT").to_string(),
            git_modified: env!("RAYPACK_BUILD_MODIFIED") == "true",
            embree: None,
            date: utc_date(seconds),
        }
    }

    /// The same, with Embree's version and device configuration.
    pub fn with_embree(self, embree: EmbreeInfo) -> Self {
        Self {
            embree: Some(embree),
            ..self
        }
    }

    /// The kernels' instruction set, "unknown" where not recorded.
    pub fn isa_label(&self) -> &str {
        if self.isa.is_empty() { "unknown" } else { &self.isa }
    }

    /// The commit, marked when the build's sources differed from it
    /// (`58e706d… with uncommitted changes`).
    pub fn commit_label(&self) -> String {
        if self.git_modified {
            format!("{} with uncommitted changes", self.git_commit)
        } else {
            self.git_commit.clone()
        }
    }

    /// Name and value of each field, for a text table.
    pub fn rows(&self) -> Vec<(&'static str, String)> {
        let list = |v: &[String]| {
            if v.is_empty() {
                "none".to_string()
            } else {
                v.join(" ")
            }
        };
        let mut rows = vec![
            ("cpu", self.cpu_model.clone()),
            ("threads", self.threads.to_string()),
            (
                "cores",
                self.physical_cores.map_or("unknown".into(), |n| n.to_string()),
            ),
            ("isa (build)", list(&self.isa_build)),
            ("isa (cpu)", list(&self.isa_cpu)),
            ("isa (kernels)", self.isa_label().to_string()),
            ("thp", self.thp.clone()),
            (
                "cache",
                self.last_level_cache.map_or("unknown".into(), |c| {
                    format!("{} KiB, level {} (the last)", c.bytes >> 10, c.level)
                }),
            ),
            ("target", self.target.clone()),
            ("rustc", self.rustc.clone()),
            ("profile", self.profile.clone()),
            (
                "rustflags",
                if self.rustflags.is_empty() {
                    "none".into()
                } else {
                    self.rustflags.clone()
                },
            ),
            ("features", list(&self.features)),
            ("commit", self.commit_label()),
        ];
        if let Some(e) = &self.embree {
            rows.push(("embree", format!("{} \"{}\"", e.version, e.config)));
        }
        rows.push(("date", self.date.clone()));
        rows
    }
}

/// One level of the CPU's caches: its level (1, 2, 3 …) and its bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct CacheLevel {
    /// 1 for L1, 2 for L2, …
    pub level: u32,
    /// Its size in bytes (per instance: one core's L2, one complex's L3).
    pub bytes: usize,
}

/// The largest data or unified cache of CPU 0
/// (`/sys/devices/system/cpu/cpu0/cache/index*/`: the highest `level`, its
/// `size`), read once; None where the kernel does not say. (Some virtual
/// machines show no L3: then this is their L2.)
pub fn last_level_cache() -> Option<CacheLevel> {
    static LAST: OnceLock<Option<CacheLevel>> = OnceLock::new();
    *LAST.get_or_init(|| {
        let dir = std::fs::read_dir("/sys/devices/system/cpu/cpu0/cache").ok()?;
        let read = |path: std::path::PathBuf| std::fs::read_to_string(path).ok();
        dir.flatten()
            .filter(|e| e.file_name().to_string_lossy().starts_with("index"))
            .filter_map(|e| {
                let kind = read(e.path().join("type"))?;
                let level = read(e.path().join("level"))?.trim().parse().ok()?;
                let bytes = cache_size(&read(e.path().join("size"))?)?;
                (kind.trim() != "Instruction").then_some(CacheLevel { level, bytes })
            })
            .max_by_key(|c| (c.level, c.bytes))
    })
}

/// A cache `size` as sysfs writes it (`32768K`, `1M`, or bytes), in bytes.
fn cache_size(text: &str) -> Option<usize> {
    let text = text.trim();
    let (digits, unit) = match text.char_indices().find(|(_, c)| !c.is_ascii_digit()) {
        Some((at, _)) => text.split_at(at),
        None => (text, ""),
    };
    let scale = match unit {
        "" => 1,
        "K" => 1 << 10,
        "M" => 1 << 20,
        "G" => 1 << 30,
        _ => return None,
    };
    digits.parse::<usize>().ok()?.checked_mul(scale)
}

/// The first `model name` of `/proc/cpuinfo`.
fn cpu_model(cpuinfo: &str) -> Option<String> {
    cpuinfo.lines().find_map(|l| {
        l.strip_prefix("model name")?
            .split_once(':')
            .map(|(_, v)| v.trim().to_string())
    })
}

/// The number of distinct `(physical id, core id)` pairs of `/proc/cpuinfo`.
fn physical_cores(cpuinfo: &str) -> Option<usize> {
    let field = |block: &str, name: &str| {
        block.lines().find_map(|l| {
            let (k, v) = l.split_once(':')?;
            (k.trim() == name).then(|| v.trim().to_string())
        })
    };
    let cores: std::collections::BTreeSet<_> = cpuinfo
        .split("\n\n")
        .filter_map(|block| Some((field(block, "physical id")?, field(block, "core id")?)))
        .collect();
    (!cores.is_empty()).then_some(cores.len())
}

/// The bracketed mode of the THP `enabled` file: `always [madvise] never` → `madvise`.
fn thp_mode(text: &str) -> Option<&str> {
    let start = text.find('[')? + 1;
    let end = start + text[start..].find(']')?;
    Some(&text[start..end])
}

/// The extensions of [`ISA_FEATURES`] compiled in.
fn isa_build() -> Vec<String> {
    let on = [
        cfg!(target_feature = "sse4.2"),
        cfg!(target_feature = "avx"),
        cfg!(target_feature = "avx2"),
        cfg!(target_feature = "fma"),
        cfg!(target_feature = "avx512f"),
    ];
    named(on)
}

/// The extensions of [`ISA_FEATURES`] the CPU has.
#[cfg(target_arch = "x86_64")]
fn isa_cpu() -> Vec<String> {
    let on = [
        is_x86_feature_detected!("sse4.2"),
        is_x86_feature_detected!("avx"),
        is_x86_feature_detected!("avx2"),
        is_x86_feature_detected!("fma"),
        is_x86_feature_detected!("avx512f"),
    ];
    named(on)
}

/// None of [`ISA_FEATURES`] exist off x86-64.
#[cfg(not(target_arch = "x86_64"))]
fn isa_cpu() -> Vec<String> {
    Vec::new()
}

fn named(on: [bool; 5]) -> Vec<String> {
    ISA_FEATURES
        .iter()
        .zip(on)
        .filter(|(_, on)| *on)
        .map(|(name, _)| name.to_string())
        .collect()
}

/// `seconds` since the Unix epoch as UTC `YYYY-MM-DDTHH:MM:SSZ` (the civil
/// calendar from a day count: H. Hinnant's `civil_from_days`).
fn utc_date(seconds: u64) -> String {
    let days = (seconds / 86_400) as i64;
    let s = seconds % 86_400;
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097; // day of the era, [0, 146096]
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365; // [0, 399]
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100); // [0, 365], from 1 March
    let mp = (5 * doy + 2) / 153; // month from March, [0, 11]
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}Z",
        s / 3600,
        s / 60 % 60,
        s % 60
    )
}

/// The version of dependency `name` this build locked (from `Cargo.lock`,
/// recorded by the build script), or `?`.
pub fn peer_version(name: &str) -> &'static str {
    env!("RAYPACK_LOCKED_VERSIONS")
        .split(',')
        .find_map(|entry| entry.strip_prefix(name)?.strip_prefix('='))
        .unwrap_or("?")
}

#[cfg(test)]
mod tests {
    use super::*;

    const CPUINFO: &str = "processor\t: 0\nmodel name\t: AMD EPYC 9B45\nphysical id\t: 0\ncore id\t\t: 0\n\n\
processor\t: 1\nmodel name\t: AMD EPYC 9B45\nphysical id\t: 0\ncore id\t\t: 0\n\n\
processor\t: 2\nmodel name\t: AMD EPYC 9B45\nphysical id\t: 0\ncore id\t\t: 1\n";

    #[test]
    fn reads_cpuinfo() {
        assert_eq!(cpu_model(CPUINFO).as_deref(), Some("AMD EPYC 9B45"));
        assert_eq!(physical_cores(CPUINFO), Some(2));
        assert_eq!(cpu_model(""), None);
        assert_eq!(physical_cores("processor : 0\n"), None);
    }

    #[test]
    fn reads_the_thp_mode() {
        assert_eq!(thp_mode("always [madvise] never\n"), Some("madvise"));
        assert_eq!(thp_mode("[always] madvise never"), Some("always"));
        assert_eq!(thp_mode("garbage"), None);
    }

    #[test]
    fn reads_cache_sizes() {
        assert_eq!(cache_size("32768K\n"), Some(32 << 20));
        assert_eq!(cache_size("1M"), Some(1 << 20));
        assert_eq!(cache_size("4096"), Some(4096));
        assert_eq!(cache_size("12 KB"), None);
        assert_eq!(cache_size(""), None);
    }

    #[test]
    fn formats_utc_dates() {
        assert_eq!(utc_date(0), "1970-01-01T00:00:00Z");
        assert_eq!(utc_date(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(utc_date(1_709_251_199), "2024-02-29T23:59:59Z");
        assert_eq!(utc_date(4_102_444_800), "2100-01-01T00:00:00Z");
    }

    /// A build of modified sources says so beside its commit; results stored
    /// before the mark was recorded read as unmodified.
    #[test]
    fn marks_a_build_of_modified_sources() {
        let mut env = Environment::collect();
        env.git_commit = "abc".into();
        env.git_modified = false;
        assert_eq!(env.commit_label(), "abc");
        assert!(env.rows().contains(&("commit", "abc".to_string())));
        env.git_modified = true;
        assert_eq!(env.commit_label(), "abc with uncommitted changes");
        assert!(
            env.rows()
                .contains(&("commit", "abc with uncommitted changes".to_string()))
        );
        let mut json = serde_json::to_value(&env).unwrap();
        json.as_object_mut().unwrap().remove("git_modified");
        assert!(!serde_json::from_value::<Environment>(json).unwrap().git_modified);
    }

    #[test]
    fn collects_and_serialises() {
        let env = Environment::collect().with_embree(EmbreeInfo {
            version: "4.4.0".into(),
            config: "threads=1".into(),
        });
        assert!(env.threads >= 1);
        assert!(env.rustc.starts_with("rustc "), "{}", env.rustc);
        // What the build compiled in, the CPU running it has.
        assert!(env.isa_build.iter().all(|f| env.isa_cpu.contains(f)), "{env:?}");
        let json = serde_json::to_value(&env).unwrap();
        for key in [
            "cpu_model",
            "isa_build",
            "isa_cpu",
            "isa",
            "thp",
            "rustc",
            "profile",
            "git_commit",
            "git_modified",
            "date",
        ] {
            assert!(json.get(key).is_some(), "{key} missing from {json}");
        }
        assert_eq!(json["embree"]["version"], "4.4.0");
        assert_eq!(serde_json::from_value::<Environment>(json).unwrap(), env);
        assert_eq!(env.rows().last().unwrap().0, "date");
    }
}
