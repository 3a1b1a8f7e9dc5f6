//! `raypack gen KIND [--size N] [--seed S] [-o FILE]`: write a generated scene
//! as NFF to stdout or, atomically (a temporary file renamed into place), to a file.

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use anyhow::{Context, anyhow};
use clap::Args;

use crate::cli::{CliError, CliResult};
use crate::scene::generate::{Kind, Params};

/// Options of `gen`.
#[derive(Args, Debug)]
pub struct GenArgs {
    /// What to generate.
    #[arg(value_enum)]
    pub kind: Kind,
    /// Size: the SPD size factor (sphereflake, tetra, fractal-mountain: 4 is the
    /// classic scene; rings 7, tree 11, teapot 12 give the SPD's published
    /// counts), the primitive count (random-spheres, random-triangles) or the
    /// subdivision level (terrain: 2·4^N triangles).
    #[arg(long)]
    pub size: Option<u32>,
    /// Seed of random-spheres, random-triangles and terrain (default 1); the
    /// mountain number of fractal-mountain (default 21, the SPD's).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Write to this file instead of stdout.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

/// Run `gen`.
pub fn run(args: GenArgs) -> CliResult {
    let params = Params::new(args.kind, args.size, args.seed).map_err(|e| CliError::BadInput(e.into()))?;
    match &args.output {
        None => {
            let stdout = BufWriter::new(io::stdout().lock());
            params
                .write_nff(stdout)
                .map_err(|e| CliError::Failed(anyhow!(e).context("cannot write to stdout")))?;
        }
        Some(path) => {
            write_atomically(path, |file| params.write_nff(file).map(drop)).map_err(CliError::BadInput)?;
            eprintln!("{}: {}", path.display(), params.title());
        }
    }
    Ok(())
}

/// Write `path` through `write` into a temporary file beside it, renamed over
/// `path` only once complete, so no half-written file is ever left there.
fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
) -> anyhow::Result<()> {
    let name = path
        .file_name()
        .ok_or_else(|| anyhow!("{}: not a file name", path.display()))?;
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let temp = dir.join(format!(".{}.{}.tmp", name.to_string_lossy(), std::process::id()));
    let result = File::create(&temp)
        .and_then(|file| {
            let mut out = BufWriter::new(file);
            write(&mut out)?;
            out.flush()?;
            out.into_inner()
                .map_err(io::IntoInnerError::into_error)?
                .sync_all()
        })
        .and_then(|()| std::fs::rename(&temp, path));
    if result.is_err() {
        // Best effort: the temporary may not even exist.
        let _ = std::fs::remove_file(&temp);
    }
    result.with_context(|| format!("cannot write {}", path.display()))
}
