//! What the bench subcommands share: the output options, the result with
//! its environment, and the comparison with a baseline.

use clap::Args;
use serde::Serialize;

use crate::atomic_file::AtomicFile;
use crate::bench::baseline;
use crate::bench::change::{Comparison, DEFAULT_NOISE_THRESHOLD, Verdict, compare};
use crate::bench::figure::Figure;
use crate::bench::result::{BenchResult, StoredResult};
use crate::bench::timing_hooks::TimingHooks;
use crate::cli::args::{arguments, environment};
use crate::cli::error::{CliError, CliResult};
use crate::cli::stdout::outln;
use crate::statistics::Summary;

/// How a bench subcommand reports: a table or JSON, and baselines.
#[derive(Args, Debug)]
pub struct Output {
    /// Print the result as JSON (environment, rows, figures, comparison) instead of tables.
    #[arg(long)]
    pub json: bool,
    /// Baselines to store and compare with.
    #[command(flatten)]
    pub baselines: Baselines,
}

/// The baseline options every bench subcommand takes.
#[derive(Args, Debug)]
pub struct Baselines {
    /// Store this run as baseline NAME: NAME.json in $RAYPACK_BASELINE_DIR
    /// (default: target/raypack-baselines of the current directory).
    #[arg(long, value_name = "NAME")]
    pub save_baseline: Option<String>,
    /// Compare this run with baseline NAME, figure by figure: the change of
    /// each median and whether its interval excludes zero.
    #[arg(long, value_name = "NAME")]
    pub baseline: Option<String>,
    /// With --baseline: the change, in percent, a figure's interval must lie
    /// beyond to count (runs of one build differ by a few percent on a shared machine).
    #[arg(long, value_name = "PERCENT", default_value_t = 100.0 * DEFAULT_NOISE_THRESHOLD)]
    pub noise_threshold: f64,
}

/// Where a run's JSON result goes.
pub enum JsonTo {
    /// Nowhere: the run prints its table.
    Nowhere,
    /// To stdout, instead of the table.
    Stdout,
    /// Into a file, claimed before measuring; the table still goes to stdout.
    File(AtomicFile),
}

/// A bench subcommand's run, from before measuring to its output.
pub struct Run<'a> {
    baselines: &'a Baselines,
    json: JsonTo,
    command: &'static str,
    baseline: Option<StoredResult>,
    /// Whether the table marks noisy figures `*` (as [`figure`] does), so
    /// that a note under it says what the mark means.
    marks_noise: bool,
    /// The bench timing hook.
    pub hooks: TimingHooks,
}

impl<'a> Run<'a> {
    /// [`Run::with`] the options of `output`: JSON to stdout or a table.
    pub fn start(output: &'a Output, command: &'static str) -> Result<Self, CliError> {
        let json = if output.json {
            JsonTo::Stdout
        } else {
            JsonTo::Nowhere
        };
        Self::with(&output.baselines, json, command)
    }

    /// Checks what can fail before measuring: the baseline to compare with
    /// exists, the name to save under is valid, the timing hook is well-formed;
    /// the JSON goes where `json` says.
    pub fn with(baselines: &'a Baselines, json: JsonTo, command: &'static str) -> Result<Self, CliError> {
        let bad = |e: String| CliError::BadInput(anyhow::anyhow!(e));
        if !(baselines.noise_threshold >= 0.0 && baselines.noise_threshold.is_finite()) {
            return Err(bad(format!(
                "--noise-threshold {}: expected a percentage of 0 or more",
                baselines.noise_threshold
            )));
        }
        if let Some(name) = &baselines.save_baseline {
            baseline::path(name).map_err(bad)?;
        }
        let stored = match &baselines.baseline {
            Some(name) => Some(baseline::load(name, command).map_err(bad)?),
            None => None,
        };
        Ok(Self {
            baselines,
            json,
            command,
            baseline: stored,
            marks_noise: true,
            hooks: TimingHooks::from_env().map_err(bad)?,
        })
    }

    /// The same run for a table that shows intervals rather than noise marks:
    /// no note about them under it.
    pub fn without_noise_marks(self) -> Self {
        Self {
            marks_noise: false,
            ..self
        }
    }

    /// Print the result (as `table` prints rows, or JSON), store it as a
    /// baseline and compare it with one, as asked. `embree_config` is the
    /// Embree device configuration when Embree was measured.
    pub fn finish<R: Serialize>(
        self,
        rows: Vec<R>,
        figures: Vec<Figure>,
        embree_config: Option<&str>,
        table: impl FnOnce(&[R]) -> CliResult,
    ) -> CliResult {
        let mut result = BenchResult {
            command: self.command.to_string(),
            arguments: arguments(),
            environment: environment(embree_config)?,
            rows,
            figures,
            comparison: None,
        };
        let threshold = self.baselines.noise_threshold / 100.0;
        result.comparison = self.baseline.map(|old| {
            let (changes, unmatched) = compare(&old.figures, &result.figures, threshold);
            Comparison {
                baseline: self.baselines.baseline.clone().unwrap_or_default(),
                baseline_commit: old.environment.commit_label(),
                baseline_date: old.environment.date,
                noise_threshold: threshold,
                changes,
                unmatched,
            }
        });
        let stored = result.stored().map_err(anyhow::Error::from)?;
        if let Some(name) = &self.baselines.save_baseline {
            let path = baseline::save(name, &stored).map_err(|e| CliError::Failed(anyhow::anyhow!(e)))?;
            eprintln!("baseline {name} saved to {}", path.display());
        }
        let json = || serde_json::to_string_pretty(&stored).map_err(anyhow::Error::from);
        match self.json {
            JsonTo::Nowhere => {}
            JsonTo::Stdout => return outln!("{}", json()?),
            JsonTo::File(file) => file.commit(format!("{}\n", json()?).as_bytes())?,
        }
        table(&result.rows)?;
        if self.marks_noise && result.figures.iter().any(|f| f.summary.noisy) {
            outln!("{NOISY_NOTE}")?;
        }
        let env = &result.environment;
        let triangles = if env.triangle_test.is_empty() {
            String::new()
        } else {
            format!(", {} triangles", env.triangle_test)
        };
        outln!(
            "(measured on {}, {} threads, kernels {}{triangles}, commit {}, {}; `raypack env` for the rest)",
            env.cpu_model,
            env.threads,
            env.isa_label(),
            env.commit_label(),
            env.date
        )?;
        if let Some(c) = &result.comparison {
            print_comparison(c)?;
        }
        Ok(())
    }
}

/// What a noisy mark means, under every table that has one.
const NOISY_NOTE: &str = "(median ±half-width of its 95% interval; * noisy: the interval reaches beyond ±5%)";

/// A summary as `median{unit} ±x%` (the larger half-width of its interval),
/// marked `*` when noisy; `digits` after the point.
pub fn figure(s: &Summary, digits: usize, unit: &str) -> String {
    let (below, above) = s.relative_interval();
    let half = 100.0 * below.max(above);
    let mark = if s.noisy { "*" } else { "" };
    format!("{:.digits$}{unit} ±{half:.1}%{mark}", s.median)
}

/// The comparison with a baseline, one line per figure.
fn print_comparison(c: &Comparison) -> CliResult {
    outln!(
        "against baseline {} (commit {}, {}); a change counts when its interval lies beyond ±{}%:",
        c.baseline,
        c.baseline_commit,
        c.baseline_date,
        100.0 * c.noise_threshold
    )?;
    let width = c.changes.iter().map(|x| x.key.len()).max().unwrap_or(0);
    for x in &c.changes {
        outln!(
            "  {:<width$} {:>12.4} -> {:>12.4} {:>+7.1}% [{:+.1}%, {:+.1}%] {}{}",
            x.key,
            x.baseline,
            x.current,
            100.0 * x.change,
            100.0 * x.change_low,
            100.0 * x.change_high,
            x.verdict.words(),
            if x.excludes_zero && x.verdict == Verdict::NoChange {
                " (beyond zero, within the threshold)"
            } else {
                ""
            }
        )?;
    }
    let unchanged = c
        .changes
        .iter()
        .filter(|x| x.verdict == Verdict::NoChange)
        .count();
    outln!(
        "  {unchanged} of {} figures without significant change{}",
        c.changes.len(),
        if c.unmatched.is_empty() {
            String::new()
        } else {
            format!("; {} figures in only one of the runs", c.unmatched.len())
        }
    )?;
    Ok(())
}
