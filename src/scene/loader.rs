//! Loading a scene file of any format: the reader chosen by extension, and
//! the two places a TOML scene's includes are read from (the disk, or files
//! held in memory), which load an included file of any format in turn.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use crate::scene::error::SceneError;
use crate::scene::model::Scene;
use crate::scene::native::{self, SceneFiles};
use crate::scene::{gltf, nff, obj, ply};

/// The scene formats, as [`load`] tells them by file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Nff,
    Toml,
    Obj,
    Ply,
    Gltf,
}

/// The format of the file at `path`, by extension (`.ply.gz` is PLY).
fn format_of(path: &Path) -> Result<Format, SceneError> {
    let name = path.to_string_lossy().to_ascii_lowercase();
    let extension = match name.rsplit_once('.') {
        Some((stem, "gz")) if stem.ends_with(".ply") => "ply.gz",
        Some((_, ext)) => ext,
        None => "",
    };
    match extension {
        "nff" => Ok(Format::Nff),
        "toml" => Ok(Format::Toml),
        "obj" => Ok(Format::Obj),
        "ply" | "ply.gz" => Ok(Format::Ply),
        "gltf" | "glb" => Ok(Format::Gltf),
        _ => Err(SceneError::file(
            path,
            "unknown scene format (expected .nff, .obj, .ply, .ply.gz, .gltf, .glb or .toml)",
        )),
    }
}

/// Load a scene, choosing the reader by file extension.
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    match format_of(path)? {
        Format::Nff => nff::load(path),
        Format::Toml => native::load_from(path, &FileSystem),
        Format::Obj => obj::load(path),
        Format::Ply => ply::load(path),
        Format::Gltf => gltf::load(path),
    }
}

/// Parse a scene file already in memory, choosing the reader by the extension
/// of `path` as [`load`] does; `path` names it in errors. A TOML file's
/// includes are read from disk, relative to `path` (see
/// [`native::load_from`] to take them from memory too).
pub fn parse(path: &Path, bytes: &[u8]) -> Result<Scene, SceneError> {
    match format_of(path)? {
        Format::Nff => nff::parse(path, bytes),
        Format::Toml => native::parse_from(path, native::utf8_text(path, bytes)?, &FileSystem),
        Format::Obj => obj::parse(path, bytes),
        Format::Ply => ply::parse(path, bytes),
        Format::Gltf => gltf::parse(path, bytes),
    }
}

/// Includes read from disk: identities are canonical paths (so symbolic links
/// and `..` cannot hide a cycle).
#[derive(Clone, Copy, Debug, Default)]
pub struct FileSystem;

impl SceneFiles for FileSystem {
    fn identity(&self, path: &Path) -> PathBuf {
        path.canonicalize().unwrap_or_else(|_| path.to_path_buf())
    }

    fn read(&self, path: &Path) -> Result<Vec<u8>, SceneError> {
        std::fs::read(path).map_err(|e| SceneError::file(path, format!("cannot read: {e}")))
    }

    fn load(&self, path: &Path) -> Result<Scene, SceneError> {
        load(path)
    }
}

/// Files held in memory by path; paths are compared after lexical
/// normalisation (`a/./b/../c` is `a/c`), and a path that is not held cannot
/// be read. Nothing touches the disk.
#[derive(Clone, Debug, Default)]
pub struct InMemory {
    files: HashMap<PathBuf, Vec<u8>>,
}

impl InMemory {
    /// No files.
    pub fn new() -> Self {
        Self::default()
    }

    /// Hold `bytes` as the file at `path` (replacing any held there).
    pub fn insert(&mut self, path: impl AsRef<Path>, bytes: impl Into<Vec<u8>>) {
        self.files.insert(normalize(path.as_ref()), bytes.into());
    }

    fn get(&self, path: &Path) -> Result<&[u8], SceneError> {
        self.files
            .get(&normalize(path))
            .map(Vec::as_slice)
            .ok_or_else(|| SceneError::file(path, "cannot read: no such file in memory"))
    }
}

impl SceneFiles for InMemory {
    fn identity(&self, path: &Path) -> PathBuf {
        normalize(path)
    }

    fn read(&self, path: &Path) -> Result<Vec<u8>, SceneError> {
        self.get(path).map(<[u8]>::to_vec)
    }

    fn load(&self, path: &Path) -> Result<Scene, SceneError> {
        parse(path, self.get(path)?)
    }
}

/// `path` without `.` components, each `..` cancelling the name before it.
fn normalize(path: &Path) -> PathBuf {
    use std::path::Component;
    let mut out = PathBuf::new();
    for component in path.components() {
        match component {
            Component::CurDir => {}
            Component::ParentDir if matches!(out.components().next_back(), Some(Component::Normal(_))) => {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}
