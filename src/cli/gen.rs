//! `raypack gen KIND [--size N] [--seed S] [-o FILE]`: write a generated scene
//! as NFF to stdout or, atomically ([`AtomicFile`]), to a file.

use std::io::{self, BufWriter};
use std::path::PathBuf;

use clap::Args;

use crate::atomic_file::AtomicFile;
use crate::cli::error::{CliError, CliResult};
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
                .map_err(crate::cli::stdout::write_error)?;
        }
        Some(path) => {
            AtomicFile::create(path)?.commit_with(|out| params.write_nff(out).map(drop))?;
            eprintln!("{}: {}", path.display(), params.title());
        }
    }
    Ok(())
}
