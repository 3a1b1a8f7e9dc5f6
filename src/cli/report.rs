//! `raypack report RESULTS.json… -o report.html`: one self-contained HTML page
//! of bench results (`raypack bench … --json`): charts of every figure with
//! its interval, thread scaling, ratios, comparisons and the environment, and
//! the pictures given with `--image` (annotated renders, heat maps).

use std::path::PathBuf;

use crate::atomic_file::AtomicFile;
use crate::bench::result::StoredResult;
use crate::cli::error::{CliError, CliResult};
use crate::environment::Environment;
use crate::report::Input;
use crate::report::html::is_png;
use crate::report::page::{Picture, page};

/// Options of `report`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// JSON results of `raypack bench kernels|scene|traversal --json`.
    #[arg(required = true)]
    pub results: Vec<PathBuf>,
    /// The HTML page to write.
    #[arg(short, long)]
    pub output: PathBuf,
    /// A PNG to show on the page (an annotated render, a heat map); repeatable.
    #[arg(long = "image")]
    pub images: Vec<PathBuf>,
}

/// Read the results and write the page.
pub fn run(args: Args) -> CliResult {
    let bad = |e: String| CliError::BadInput(anyhow::anyhow!(e));
    // Claim the output first: an unwritable path fails before any work.
    let file = AtomicFile::create(&args.output).map_err(|e| bad(e.to_string()))?;
    let mut inputs = Vec::new();
    for path in &args.results {
        let text = std::fs::read_to_string(path).map_err(|e| bad(format!("{}: {e}", path.display())))?;
        let result: StoredResult = serde_json::from_str(&text).map_err(|e| {
            bad(format!(
                "{}:{}: not a bench result (`raypack bench … --json`): {e}",
                path.display(),
                e.line()
            ))
        })?;
        let name = path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        inputs.push(Input { name, result });
    }
    let mut pictures = Vec::new();
    for path in &args.images {
        let png = std::fs::read(path).map_err(|e| bad(format!("{}: {e}", path.display())))?;
        if !is_png(&png) {
            return Err(bad(format!("{}: not a PNG image", path.display())));
        }
        let name = path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        pictures.push(Picture { name, png });
    }
    let html =
        page(&inputs, &pictures, &Environment::collect().date).map_err(|e| CliError::Failed(e.into()))?;
    file.commit(html.as_bytes())
        .map_err(|e| CliError::Failed(e.into()))?;
    Ok(())
}
