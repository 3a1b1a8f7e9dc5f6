//! The JSON result of a `raypack bench` command: the environment it ran on,
//! the command's own rows, every timed figure flattened into [`Figure`]s, and,
//! when compared against a baseline, the [`Comparison`].
//!
//! Baselines and `raypack report` read only `command`, `environment` and
//! `figures`, so they take the result of any bench command alike.

use serde::{Deserialize, Serialize};

use crate::bench::change::Comparison;
use crate::bench::figure::Figure;
use crate::environment::Environment;

/// A bench command's result; `R` is its row type (read back as JSON values).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct BenchResult<R> {
    /// The bench subcommand: `kernels`, `scene`, `traversal` or `matrix`.
    pub command: String,
    /// raypack's arguments as given (`bench traversal assets/dragon.ply
    /// --threads 1,2 …`), for a reader to run it again; empty in results
    /// stored before they were kept.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub arguments: Vec<String>,
    /// The machine and build it ran on.
    pub environment: Environment,
    /// The command's rows, as its table shows them.
    pub rows: Vec<R>,
    /// Every timed figure and ratio of the rows, named and labelled.
    pub figures: Vec<Figure>,
    /// The comparison with a baseline, when one was asked for.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub comparison: Option<Comparison>,
}

/// A result read back from JSON, rows untyped.
pub type StoredResult = BenchResult<serde_json::Value>;

impl<R: Serialize> BenchResult<R> {
    /// The same result with its rows as JSON values, as a stored result reads back.
    pub fn stored(&self) -> Result<StoredResult, serde_json::Error> {
        Ok(BenchResult {
            command: self.command.clone(),
            arguments: self.arguments.clone(),
            environment: self.environment.clone(),
            rows: self
                .rows
                .iter()
                .map(serde_json::to_value)
                .collect::<Result<_, _>>()?,
            figures: self.figures.clone(),
            comparison: self.comparison.clone(),
        })
    }
}
