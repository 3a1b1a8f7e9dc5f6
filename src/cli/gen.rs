//! `raypack gen KIND [--size N] [--seed S] [-o FILE]`: write a generated scene
//! to stdout or, atomically ([`AtomicFile`]), to a file: as NFF, or as glTF
//! where the file name ends in `.glb` or `.gltf` (an instanced kind, `forest`
//! or `city`, is glTF only, and goes to stdout as `.gltf` JSON).

use std::io::{self, BufWriter, Write};
use std::path::PathBuf;

use clap::Args;

use crate::atomic_file::AtomicFile;
use crate::cli::error::{CliError, CliResult};
use crate::scene::generate::{Kind, Params};
use crate::scene::gltf_writer::{Container, write_gltf};

/// Options of `gen`.
#[derive(Args, Debug)]
pub struct GenArgs {
    /// What to generate.
    #[arg(value_enum)]
    pub kind: Kind,
    /// Size: the SPD size factor (sphereflake, tetra, fractal-mountain: 4 is the
    /// classic scene; rings 7, tree 11, teapot 12 give the SPD's published
    /// counts), the primitive count (random-spheres, random-triangles), the
    /// subdivision level (terrain: 2·4^N triangles) or the instance count (forest, city).
    #[arg(long)]
    pub size: Option<u32>,
    /// Seed of random-spheres, random-triangles, terrain, forest and city (default
    /// 1); the mountain number of fractal-mountain (default 21, the SPD's).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Write to this file instead of stdout: glTF where it ends in `.glb` or
    /// `.gltf` (triangles only), NFF otherwise.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

/// Run `gen`.
pub fn run(args: GenArgs) -> CliResult {
    let params = Params::new(args.kind, args.size, args.seed).map_err(|e| CliError::BadInput(e.into()))?;
    let gltf = match &args.output {
        Some(path) => Container::of_path(path),
        None => params.kind.is_instanced().then_some(Container::Json),
    };
    if gltf.is_none() && params.kind.is_instanced() {
        return Err(CliError::BadInput(anyhow::anyhow!(
            "{} is instanced, which NFF cannot hold: write it as glTF (-o FILE.glb or -o FILE.gltf)",
            params.kind.name()
        )));
    }
    // The glTF document is made in memory first: a scene it cannot hold
    // (spheres, polygons…) is refused before any output is started.
    let bytes = match gltf {
        Some(container) => Some(
            write_gltf(&params.scene(), container, Vec::new())
                .map_err(|e| CliError::BadInput(anyhow::anyhow!("{}: {e}", params.kind.name())))?,
        ),
        None => None,
    };
    let write = |out: &mut dyn Write| -> io::Result<()> {
        match &bytes {
            Some(bytes) => out.write_all(bytes),
            None => params.write_nff(out).map(drop),
        }
    };
    match &args.output {
        None => {
            let mut stdout = BufWriter::new(io::stdout().lock());
            write(&mut stdout)
                .and_then(|()| stdout.flush())
                .map_err(crate::cli::stdout::write_error)?;
        }
        Some(path) => {
            AtomicFile::create(path)?.commit_with(|out| write(out))?;
            eprintln!("{}: {}", path.display(), params.title());
        }
    }
    Ok(())
}
