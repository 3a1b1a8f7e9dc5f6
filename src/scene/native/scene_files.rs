//! The seam through which a TOML scene's includes are read, so that scenes
//! and their includes can come from the disk or from memory.

use std::path::{Path, PathBuf};

use crate::scene::error::SceneError;
use crate::scene::model::Scene;

/// Where a TOML scene's includes come from: [`FileSystem`] when a scene is
/// loaded from disk, [`InMemory`] for scenes and their includes held in memory
/// (tests and the fuzz targets, which must never touch the disk).
///
/// [`FileSystem`]: crate::scene::loader::FileSystem
/// [`InMemory`]: crate::scene::loader::InMemory
pub trait SceneFiles {
    /// The name that identifies `path` when looking for include cycles
    /// (two names of one file must give the same identity).
    fn identity(&self, path: &Path) -> PathBuf;
    /// The bytes of the TOML file at `path`; an error without a line when it cannot be read.
    fn read(&self, path: &Path) -> Result<Vec<u8>, SceneError>;
    /// The scene in the non-TOML file at `path` (NFF, OBJ, PLY), read by extension.
    fn load(&self, path: &Path) -> Result<Scene, SceneError>;
}
