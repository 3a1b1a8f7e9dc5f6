//! One measured figure of a benchmark result, named so that two runs can be
//! matched figure by figure (baselines) and grouped into charts (reports).
//!
//! A figure is a [`Summary`] (median, 95% interval, samples, noise flag) with
//! what it measures (`name`, `unit`, which direction is better) and the
//! variant it was measured on as `labels` (scene, ray kind, engine, kernel,
//! threads…). Its [`key`](Figure::key) is the name and the labels together.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::statistics::Summary;

/// Which direction of a figure is an improvement.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Better {
    /// A rate: more is faster.
    Higher,
    /// A time: less is faster.
    Lower,
    /// A ratio between variants: neither direction is a regression by itself.
    Neither,
}

/// A named, labelled summary of samples.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Figure {
    /// What is measured: `throughput`, `build`, or a ratio such as `packet8/scalar`.
    pub name: String,
    /// Unit of the summary's values (`Mrays/s`, `tests/s`, `ms`, `x`).
    pub unit: String,
    /// Which direction is an improvement.
    pub better: Better,
    /// The variant measured, by label name (`scene`, `rays`, `engine`, `kernel`, `threads`…).
    pub labels: BTreeMap<String, String>,
    /// The samples' summary.
    #[serde(flatten)]
    pub summary: Summary,
}

impl Figure {
    /// A figure of `summary` named `name` in `unit`, with `labels` as `(name, value)` pairs.
    pub fn new(
        name: impl Into<String>,
        unit: &str,
        better: Better,
        labels: &[(&str, String)],
        summary: Summary,
    ) -> Self {
        Self {
            name: name.into(),
            unit: unit.to_string(),
            better,
            labels: labels
                .iter()
                .map(|(k, v)| ((*k).to_string(), v.clone()))
                .collect(),
            summary,
        }
    }

    /// The label `name`, or "" when the figure has none.
    pub fn label(&self, name: &str) -> &str {
        self.labels.get(name).map_or("", String::as_str)
    }

    /// The name and every label, `name scene=… threads=…`: unique within a result.
    pub fn key(&self) -> String {
        let mut key = self.name.clone();
        for (k, v) in &self.labels {
            key.push_str(&format!(" {k}={v}"));
        }
        key
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_and_json() {
        let s = Summary::of(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]).unwrap();
        let f = Figure::new(
            "throughput",
            "Mrays/s",
            Better::Higher,
            &[("threads", "2".into()), ("kernel", "scalar".into())],
            s,
        );
        assert_eq!(f.key(), "throughput kernel=scalar threads=2");
        assert_eq!((f.label("kernel"), f.label("scene")), ("scalar", ""));
        let json = serde_json::to_value(&f).unwrap();
        assert_eq!(json["median"], 3.5);
        assert_eq!(json["better"], "higher");
        assert_eq!(serde_json::from_value::<Figure>(json).unwrap(), f);
    }
}
