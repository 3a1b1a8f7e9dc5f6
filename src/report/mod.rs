//! `raypack report`: one self-contained HTML page from the JSON results of
//! `raypack bench … --json` and `raypack robustness --json` (a render's own
//! JSON sidecar is [`crate::picture::render_report`]). Charts are drawn with
//! plotters as SVG and inlined as data URIs, so the page loads nothing from anywhere.
//!
//! [`page`] lays the page out; [`engines`] tables raypack against Embree;
//! [`matrix`] tables a `bench matrix` result, raypack ÷ Embree per cell; [`chart`] draws a figure group's medians as bars
//! with their 95% intervals; [`lines`] draws figures over thread counts or
//! scene sizes; [`robustness`] tables the robustness oracle's results;
//! [`html`] escapes text and inlines images.

use crate::bench::result::StoredResult;
use crate::compare::robustness_result::RobustnessResult;

pub mod chart;
pub mod engines;
pub mod html;
pub mod lines;
pub mod matrix;
pub mod page;
pub mod robustness;

/// A result file to report.
#[derive(Debug, Clone)]
pub struct Input {
    /// Its name on the page (the file name).
    pub name: String,
    /// What it holds.
    pub result: StoredResult,
}

impl Input {
    /// A result of `command` holding `figures`, named `name`, measured here
    /// and now (for tests).
    #[cfg(test)]
    pub(crate) fn of_figures(name: &str, command: &str, figures: Vec<crate::bench::figure::Figure>) -> Self {
        Self {
            name: name.into(),
            result: StoredResult {
                command: command.into(),
                arguments: Vec::new(),
                environment: crate::environment::Environment::collect(),
                rows: Vec::new(),
                figures,
                comparison: None,
            },
        }
    }
}

/// A robustness result file to report.
#[derive(Debug, Clone)]
pub struct RobustnessInput {
    /// Its name on the page (the file name).
    pub name: String,
    /// What it holds.
    pub result: RobustnessResult,
}

/// Why a page could not be made.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// No result to report.
    #[error("no results to report")]
    Empty,
    /// A chart failed to draw.
    #[error("chart {title:?}: {reason}")]
    Chart {
        /// The chart's title.
        title: String,
        /// What plotters said.
        reason: String,
    },
}
