//! A run against a baseline: per figure, the change of its median, whether
//! the change's interval excludes zero, and whether it also clears the noise
//! threshold.
//!
//! The two runs are independent (not interleaved), so the change's interval is
//! taken from the two medians' intervals: from `new.ci_low / old.ci_high − 1`
//! to `new.ci_high / old.ci_low − 1`. It excludes zero only when the two
//! intervals do not overlap.
//!
//! Each interval describes one run, and a shared machine also moves between
//! runs: on a shared VM, two runs of one build a few seconds apart differ by
//! more than their intervals on some figures.
//! So, like criterion's noise threshold, a change is reported only when its
//! whole interval lies beyond ± a threshold (5% by default, the same reach
//! that flags a figure as noisy); `excludes_zero` keeps the bare statistical
//! answer.

use serde::{Deserialize, Serialize};

use crate::bench::figure::{Better, Figure};
use crate::statistics::{CONFIDENCE, Summary};

/// What a change means.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Verdict {
    /// The change's interval includes zero.
    #[serde(rename = "no significant change")]
    NoChange,
    /// Significantly better, for a rate or a time.
    #[serde(rename = "faster")]
    Faster,
    /// Significantly worse, for a rate or a time.
    #[serde(rename = "slower")]
    Slower,
    /// A ratio significantly higher.
    #[serde(rename = "higher")]
    Higher,
    /// A ratio significantly lower.
    #[serde(rename = "lower")]
    Lower,
    /// One of the runs has too few samples for a 95% interval.
    #[serde(rename = "too few samples")]
    TooFewSamples,
}

impl Verdict {
    /// The words of the table and the JSON.
    pub fn words(self) -> &'static str {
        match self {
            Self::NoChange => "no significant change",
            Self::Faster => "faster",
            Self::Slower => "slower",
            Self::Higher => "higher",
            Self::Lower => "lower",
            Self::TooFewSamples => "too few samples",
        }
    }
}

/// One figure of both runs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Change {
    /// The figure's [`key`](Figure::key).
    pub key: String,
    /// Its unit.
    pub unit: String,
    /// The baseline's median.
    pub baseline: f64,
    /// This run's median.
    pub current: f64,
    /// `current / baseline − 1`.
    pub change: f64,
    /// Lower end of the change's interval.
    pub change_low: f64,
    /// Upper end of the change's interval.
    pub change_high: f64,
    /// The interval excludes zero (the runs' intervals do not overlap).
    pub excludes_zero: bool,
    /// Whether the interval clears the noise threshold, and which way.
    pub verdict: Verdict,
}

/// This run against a stored baseline.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Comparison {
    /// The baseline's name.
    pub baseline: String,
    /// The commit the baseline was measured on.
    pub baseline_commit: String,
    /// When the baseline was measured.
    pub baseline_date: String,
    /// The relative change a figure's interval must clear to count (0.05: ±5%).
    pub noise_threshold: f64,
    /// The figures in both runs, in this run's order.
    pub changes: Vec<Change>,
    /// Keys of this run's figures the baseline lacks, and of the baseline's this run lacks.
    pub unmatched: Vec<String>,
}

/// The noise threshold when none is given: a figure noisier than ±5% is flagged.
pub const DEFAULT_NOISE_THRESHOLD: f64 = crate::statistics::NOISY_HALF_WIDTH;

/// The change of one figure from `old` to `new` (same key); it counts when its
/// interval lies beyond ±`threshold`.
pub fn change(old: &Figure, new: &Figure, threshold: f64) -> Change {
    let (a, b): (&Summary, &Summary) = (&old.summary, &new.summary);
    let ratio = |x: f64, y: f64| if y > 0.0 { x / y - 1.0 } else { f64::NAN };
    let (low, high) = (ratio(b.ci_low, a.ci_high), ratio(b.ci_high, a.ci_low));
    let excludes_zero = low > 0.0 || high < 0.0;
    let verdict = if a.confidence < CONFIDENCE || b.confidence < CONFIDENCE {
        Verdict::TooFewSamples
    } else if !(low > threshold || high < -threshold) {
        Verdict::NoChange
    } else {
        let up = low > threshold;
        match (new.better, up) {
            (Better::Higher, true) | (Better::Lower, false) => Verdict::Faster,
            (Better::Higher, false) | (Better::Lower, true) => Verdict::Slower,
            (Better::Neither, true) => Verdict::Higher,
            (Better::Neither, false) => Verdict::Lower,
        }
    };
    Change {
        key: new.key(),
        unit: new.unit.clone(),
        baseline: a.median,
        current: b.median,
        change: ratio(b.median, a.median),
        change_low: low,
        change_high: high,
        excludes_zero,
        verdict,
    }
}

/// Every figure of `current` that `baseline` also has, matched by key, with
/// the noise `threshold` of [`change`]; and the keys in only one of them.
pub fn compare(baseline: &[Figure], current: &[Figure], threshold: f64) -> (Vec<Change>, Vec<String>) {
    let mut unmatched = Vec::new();
    let mut changes = Vec::new();
    for new in current {
        match baseline.iter().find(|old| old.key() == new.key()) {
            Some(old) => changes.push(change(old, new, threshold)),
            None => unmatched.push(new.key()),
        }
    }
    for old in baseline {
        if !current.iter().any(|new| new.key() == old.key()) {
            unmatched.push(old.key());
        }
    }
    (changes, unmatched)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn figure(better: Better, samples: &[f64]) -> Figure {
        Figure::new(
            "throughput",
            "Mrays/s",
            better,
            &[],
            Summary::of(samples).unwrap(),
        )
    }

    /// Twelve samples around `m`: the interval is [x(3), x(10)] = [m − 1, m + 1].
    fn around(m: f64) -> Vec<f64> {
        let mut x = vec![m; 12];
        x[..3].fill(m - 1.0);
        x[9..].fill(m + 1.0);
        x
    }

    #[test]
    fn overlapping_intervals_are_no_change() {
        let c = change(
            &figure(Better::Higher, &around(100.0)),
            &figure(Better::Higher, &around(101.5)),
            0.0,
        );
        assert_eq!(c.verdict, Verdict::NoChange);
        assert!(!c.excludes_zero);
        assert!((c.change - 0.015).abs() < 1e-12);
        // [100.5/101 − 1, 102.5/99 − 1]
        assert!((c.change_low - (100.5 / 101.0 - 1.0)).abs() < 1e-12);
        assert!((c.change_high - (102.5 / 99.0 - 1.0)).abs() < 1e-12);
    }

    #[test]
    fn separated_intervals_say_which_way() {
        let (slow, fast) = (around(50.0), around(100.0));
        let verdict = |better, old: &[f64], new: &[f64]| {
            change(&figure(better, old), &figure(better, new), 0.05).verdict
        };
        assert_eq!(verdict(Better::Higher, &fast, &slow), Verdict::Slower);
        assert_eq!(verdict(Better::Higher, &slow, &fast), Verdict::Faster);
        assert_eq!(verdict(Better::Lower, &slow, &fast), Verdict::Slower);
        assert_eq!(verdict(Better::Lower, &fast, &slow), Verdict::Faster);
        assert_eq!(verdict(Better::Neither, &slow, &fast), Verdict::Higher);
        assert_eq!(verdict(Better::Neither, &fast, &slow), Verdict::Lower);
        let c = change(
            &figure(Better::Higher, &fast),
            &figure(Better::Higher, &slow),
            0.05,
        );
        assert_eq!(c.change, -0.5);
        assert!(c.change_high < 0.0 && c.excludes_zero);
    }

    #[test]
    fn changes_within_the_noise_threshold_do_not_count() {
        // [100 ± 1] to [104 ± 1]: the change's interval is [+2.0%, +6.1%].
        let (old, new) = (
            figure(Better::Higher, &around(100.0)),
            figure(Better::Higher, &around(104.0)),
        );
        let c = change(&old, &new, 0.0);
        assert!((c.change_low - (103.0 / 101.0 - 1.0)).abs() < 1e-12);
        assert!((c.change_high - (105.0 / 99.0 - 1.0)).abs() < 1e-12);
        assert_eq!(c.verdict, Verdict::Faster);
        assert_eq!(change(&old, &new, 0.019).verdict, Verdict::Faster);
        let c = change(&old, &new, 0.021);
        assert_eq!(c.verdict, Verdict::NoChange);
        assert!(c.excludes_zero, "still beyond zero, only within the threshold");
    }

    #[test]
    fn too_few_samples_cannot_tell() {
        let c = change(
            &figure(Better::Higher, &[1.0; 5]),
            &figure(Better::Higher, &[2.0; 12]),
            0.05,
        );
        assert_eq!(c.verdict, Verdict::TooFewSamples);
    }

    #[test]
    fn matches_by_key() {
        let mut other = figure(Better::Higher, &around(10.0));
        other.labels.insert("kernel".into(), "scalar".into());
        let same = figure(Better::Higher, &around(10.0));
        let (changes, unmatched) = compare(std::slice::from_ref(&same), &[same.clone(), other.clone()], 0.05);
        assert_eq!(changes.len(), 1);
        assert_eq!(changes[0].verdict, Verdict::NoChange);
        assert_eq!(unmatched, [other.key()]);
        let json = serde_json::to_value(&changes[0]).unwrap();
        assert_eq!(json["verdict"], "no significant change");
    }
}
