//! `raypack report RESULTS.json… -o report.html`: one self-contained HTML page
//! of bench results (`raypack bench … --json`): charts of every figure with
//! its interval, thread scaling, ratios, comparisons and the environment;
//! the tables of robustness results (`raypack robustness --json`); and the
//! pictures given with `--image` (annotated renders, heat maps, crack pictures).

use std::path::{Path, PathBuf};

use crate::atomic_file::AtomicFile;
use crate::bench::result::StoredResult;
use crate::cli::error::{CliError, CliResult};
use crate::compare::robustness_result::RobustnessResult;
use crate::environment::Environment;
use crate::report::html::is_png;
use crate::report::page::{Picture, page};
use crate::report::{Input, RobustnessInput};

/// Options of `report`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// JSON results of `raypack bench kernels|scene|traversal|matrix --json`
    /// (a matrix is drawn as one table, raypack ÷ Embree per cell) or
    /// `raypack robustness --json`.
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
    let (mut inputs, mut robustness) = (Vec::new(), Vec::new());
    for path in &args.results {
        let text = std::fs::read_to_string(path).map_err(|e| bad(format!("{}: {e}", path.display())))?;
        let name = file_name(path);
        // A result says which command made it; what is no robustness result must be a bench one.
        if RobustnessResult::claims(&text) {
            let result = serde_json::from_str(&text).map_err(|e| {
                bad(format!(
                    "{}:{}: not a robustness result (`raypack robustness --json`): {e}",
                    path.display(),
                    e.line()
                ))
            })?;
            robustness.push(RobustnessInput { name, result });
        } else {
            let result: StoredResult = serde_json::from_str(&text).map_err(|e| {
                bad(format!(
                    "{}:{}: not a bench result (`raypack bench … --json`) nor a robustness result \
                     (`raypack robustness --json`): {e}",
                    path.display(),
                    e.line()
                ))
            })?;
            inputs.push(Input { name, result });
        }
    }
    let mut pictures = Vec::new();
    for path in &args.images {
        let png = std::fs::read(path).map_err(|e| bad(format!("{}: {e}", path.display())))?;
        if !is_png(&png) {
            return Err(bad(format!("{}: not a PNG image", path.display())));
        }
        pictures.push(Picture {
            name: file_name(path),
            png,
        });
    }
    let html = page(&inputs, &robustness, &pictures, &Environment::collect().date)
        .map_err(|e| CliError::Failed(e.into()))?;
    file.commit(html.as_bytes())
        .map_err(|e| CliError::Failed(e.into()))?;
    Ok(())
}

/// The name a file goes by on the page: its file name, else its path.
fn file_name(path: &Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}
