//! Stored runs to compare later runs against (`--save-baseline NAME`,
//! `--baseline NAME`, criterion's words): the JSON result of a bench command,
//! as `NAME.json` in the directory `$RAYPACK_BASELINE_DIR`, or
//! `target/raypack-baselines` of the current directory when it is unset.

use std::path::PathBuf;

use crate::atomic_file::AtomicFile;
use crate::bench::result::StoredResult;

/// The environment variable naming the baseline directory.
pub const DIR_VARIABLE: &str = "RAYPACK_BASELINE_DIR";

/// The directory baselines live in.
pub fn directory() -> PathBuf {
    std::env::var_os(DIR_VARIABLE).map_or_else(|| PathBuf::from("target/raypack-baselines"), PathBuf::from)
}

/// The file of baseline `name`; a name is letters, digits, `-`, `_` and `.`,
/// not starting with `.` (so it cannot leave the directory).
pub fn path(name: &str) -> Result<PathBuf, String> {
    let allowed = |c: char| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.');
    if name.is_empty() || name.starts_with('.') || !name.chars().all(allowed) {
        return Err(format!(
            "baseline name {name:?}: use letters, digits, '-', '_' and '.', not starting with '.'"
        ));
    }
    Ok(directory().join(format!("{name}.json")))
}

/// Store `result` as baseline `name` (the directory is made if missing).
pub fn save(name: &str, result: &StoredResult) -> Result<PathBuf, String> {
    let path = path(name)?;
    let dir = directory();
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let text = serde_json::to_string_pretty(result).map_err(|e| e.to_string())?;
    AtomicFile::create(&path)
        .and_then(|f| f.commit(text.as_bytes()))
        .map_err(|e| e.to_string())?;
    Ok(path)
}

/// Baseline `name`, which must have been stored by the bench `command`.
pub fn load(name: &str, command: &str) -> Result<StoredResult, String> {
    let path = path(name)?;
    let text = std::fs::read_to_string(&path).map_err(|e| {
        format!(
            "baseline {name}: {}: {e} (store one with --save-baseline {name})",
            path.display()
        )
    })?;
    let stored: StoredResult =
        serde_json::from_str(&text).map_err(|e| format!("{}: not a bench result: {e}", path.display()))?;
    if stored.command != command {
        return Err(format!(
            "baseline {name} is of `bench {}`, not `bench {command}`",
            stored.command
        ));
    }
    Ok(stored)
}
