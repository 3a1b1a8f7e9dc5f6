//! What N timing samples say: the median, a 95% confidence interval of the
//! median, the spread, and whether the figure is too noisy to trust.
//!
//! # The interval: order statistics
//!
//! The interval needs no assumption about the distribution of the samples (timings
//! are skewed, with a long tail of slow rounds). Each of `n` independent samples
//! falls below the true median `m` with probability ½, so the number `B` of
//! samples below `m` is Binomial(n, ½). With the samples sorted,
//! `x(1) ≤ … ≤ x(n)`, the interval `[x(l), x(n+1−l)]` holds `m` unless
//! `B < l` or `B > n − l`, so its coverage is `1 − 2·P(B ≤ l − 1)`. [`median_ranks`]
//! takes the largest `l` whose coverage is still at least 95% (for `n` = 20:
//! `[x(6), x(15)]`, 95.9%; for `n` = 100: `[x(40), x(61)]`, 96.5%). Below 6
//! samples no pair of ranks reaches 95% (`[x(1), x(5)]` of 5 covers 93.75%):
//! the interval is then the whole range, its [`Summary::confidence`] says how
//! much it covers, and the figure is flagged noisy.
//!
//! # Ratios of two variants
//!
//! Two variants timed in *paired, interleaved* rounds (A, B, A, B, …) share each
//! round's machine state (clock, cache, neighbours), so the ratio of a round's
//! two times cancels most of that state. [`Summary::paired_ratio`] is the
//! summary of the per-round ratios `a_i / b_i`: its median and the interval of
//! that median, by the same order statistics.
//!
//! # Spread and noise
//!
//! The spread is the minimum, the maximum and the quartiles (linear
//! interpolation between order statistics, numpy's default). A figure is
//! [`noisy`](Summary::noisy) when either end of its interval lies more than 5%
//! from the median, or when the interval covers less than 95%.

use serde::{Deserialize, Serialize};

/// The confidence the interval aims for.
pub const CONFIDENCE: f64 = 0.95;

/// The half-width, relative to the median, beyond which a figure is noisy.
pub const NOISY_HALF_WIDTH: f64 = 0.05;

/// Why samples cannot be summarised.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StatsError {
    /// No samples at all.
    #[error("no samples")]
    Empty,
    /// A NaN or infinite sample.
    #[error("sample {index} is not finite ({value})")]
    NotFinite {
        /// Its position.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// Paired samples of different lengths.
    #[error("paired samples differ in length: {a} and {b}")]
    Unpaired {
        /// Samples of the first variant.
        a: usize,
        /// Samples of the second variant.
        b: usize,
    },
    /// A ratio's denominator that is zero or negative.
    #[error("round {index}: the denominator {value} is not positive")]
    NotPositive {
        /// The round.
        index: usize,
        /// Its value.
        value: f64,
    },
}

/// The ranks (1-based) of the order statistics that bound the median's interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MedianRanks {
    /// Rank of the lower bound, `l`.
    pub low: usize,
    /// Rank of the upper bound, `n + 1 − l`.
    pub high: usize,
    /// The interval's coverage, `1 − 2·P(B ≤ l − 1)` for B ~ Binomial(n, ½).
    pub confidence: f64,
}

/// The ranks of the distribution-free interval of the median of `n ≥ 1`
/// samples at [`CONFIDENCE`] (see the module docs); the whole range, with the
/// coverage it has, when `n` is too small to reach it.
pub fn median_ranks(n: usize) -> MedianRanks {
    assert!(n >= 1, "median_ranks of no samples");
    // Step 1: P(B = 0) = 2^-n, in logs so that a large n cannot underflow it
    // before the sum starts; l = 1 (the whole range) covers 1 − 2·P(B = 0).
    let mut ln_pmf = -(n as f64) * std::f64::consts::LN_2;
    let mut cdf = ln_pmf.exp(); // P(B ≤ l − 1)
    let mut l = 1;
    let tail = (1.0 - CONFIDENCE) / 2.0;
    // Step 2: move both ranks inwards while P(B ≤ l) stays within the tail and
    // the lower rank stays below the upper one.
    loop {
        let ln_next = ln_pmf + ((n + 1 - l) as f64 / l as f64).ln(); // ln P(B = l)
        let next = cdf + ln_next.exp();
        if next > tail || 2 * (l + 1) > n + 1 {
            break;
        }
        (cdf, ln_pmf, l) = (next, ln_next, l + 1);
    }
    MedianRanks {
        low: l,
        high: n + 1 - l,
        confidence: 1.0 - 2.0 * cdf,
    }
}

/// The summary of N samples: median, its interval, spread, and the noise flag.
/// Serialised as `{median, ci_low, ci_high, samples, confidence, min, q1, q3, max, noisy}`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// The median (the mean of the middle two for an even count).
    pub median: f64,
    /// Lower end of the median's interval.
    pub ci_low: f64,
    /// Upper end of the median's interval.
    pub ci_high: f64,
    /// Number of samples.
    pub samples: usize,
    /// Coverage of `[ci_low, ci_high]` (at least [`CONFIDENCE`] from 6 samples on).
    pub confidence: f64,
    /// Smallest sample.
    pub min: f64,
    /// First quartile.
    pub q1: f64,
    /// Third quartile.
    pub q3: f64,
    /// Largest sample.
    pub max: f64,
    /// The interval reaches more than ±5% from the median, or covers less than 95%.
    pub noisy: bool,
}

impl Summary {
    /// The summary of `samples` (any order).
    pub fn of(samples: &[f64]) -> Result<Self, StatsError> {
        if samples.is_empty() {
            return Err(StatsError::Empty);
        }
        if let Some((index, &value)) = samples.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(StatsError::NotFinite { index, value });
        }
        let mut x = samples.to_vec();
        x.sort_by(f64::total_cmp);
        let n = x.len();
        let ranks = median_ranks(n);
        let median = quantile(&x, 0.5);
        let (ci_low, ci_high) = (x[ranks.low - 1], x[ranks.high - 1]);
        let reach = NOISY_HALF_WIDTH * median.abs();
        let noisy = ranks.confidence < CONFIDENCE || median - ci_low > reach || ci_high - median > reach;
        Ok(Self {
            median,
            ci_low,
            ci_high,
            samples: n,
            confidence: ranks.confidence,
            min: x[0],
            q1: quantile(&x, 0.25),
            q3: quantile(&x, 0.75),
            max: x[n - 1],
            noisy,
        })
    }

    /// The summary of the per-round ratios `a[i] / b[i]` of two variants timed
    /// in paired, interleaved rounds: the ratio's median and its interval.
    pub fn paired_ratio(a: &[f64], b: &[f64]) -> Result<Self, StatsError> {
        if a.len() != b.len() {
            return Err(StatsError::Unpaired {
                a: a.len(),
                b: b.len(),
            });
        }
        if let Some((index, &value)) = b.iter().enumerate().find(|(_, v)| !(**v > 0.0)) {
            return Err(StatsError::NotPositive { index, value });
        }
        let ratios: Vec<f64> = a.iter().zip(b).map(|(a, b)| a / b).collect();
        Self::of(&ratios)
    }

    /// The same summary in another unit: every value times `factor > 0`.
    pub fn scaled(&self, factor: f64) -> Self {
        Self {
            median: self.median * factor,
            ci_low: self.ci_low * factor,
            ci_high: self.ci_high * factor,
            min: self.min * factor,
            q1: self.q1 * factor,
            q3: self.q3 * factor,
            max: self.max * factor,
            ..*self
        }
    }

    /// The interval's half-widths relative to the median, `(below, above)`.
    pub fn relative_interval(&self) -> (f64, f64) {
        let m = self.median.abs();
        ((self.median - self.ci_low) / m, (self.ci_high - self.median) / m)
    }
}

/// The `q` quantile of sorted `x` by linear interpolation between order
/// statistics (Hyndman and Fan's type 7, numpy's default).
fn quantile(x: &[f64], q: f64) -> f64 {
    let h = (x.len() - 1) as f64 * q;
    let (lo, hi) = (h.floor() as usize, h.ceil() as usize);
    x[lo] + (h - lo as f64) * (x[hi] - x[lo])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Binomial(n, ½) tail P(B ≤ k), exactly, for small n.
    fn tail(n: u64, k: u64) -> f64 {
        let mut c = 1u128; // C(n, 0)
        let mut sum = 0u128;
        for i in 0..=k {
            sum += c;
            c = c * u128::from(n - i) / u128::from(i + 1);
        }
        sum as f64 / 2f64.powi(n as i32)
    }

    #[test]
    fn ranks_match_the_published_table() {
        // Ranks of the 95% interval of the median (e.g. Conover, Practical
        // Nonparametric Statistics, table A3; Campbell & Gardner, BMJ 1988).
        let table = [
            (6, 1, 6),
            (7, 1, 7),
            (8, 1, 8),
            (9, 2, 8),
            (10, 2, 9),
            (11, 2, 10),
            (12, 3, 10),
            (15, 4, 12),
            (20, 6, 15),
            (30, 10, 21),
            (50, 18, 33),
            (100, 40, 61),
        ];
        for (n, low, high) in table {
            let r = median_ranks(n);
            assert_eq!((r.low, r.high), (low, high), "n = {n}");
            let exact = 1.0 - 2.0 * tail(n as u64, low as u64 - 1);
            assert!(
                (r.confidence - exact).abs() < 1e-12,
                "n = {n}: {} vs {exact}",
                r.confidence
            );
            assert!(r.confidence >= CONFIDENCE);
            // One rank further in would drop below 95%.
            assert!(1.0 - 2.0 * tail(n as u64, low as u64) < CONFIDENCE, "n = {n}");
        }
    }

    #[test]
    fn few_samples_get_the_whole_range_and_its_coverage() {
        for n in 1..=5usize {
            let r = median_ranks(n);
            assert_eq!((r.low, r.high), (1, n));
            assert!((r.confidence - (1.0 - 2.0 / 2f64.powi(n as i32))).abs() < 1e-15);
            assert!(r.confidence < CONFIDENCE);
        }
    }

    #[test]
    fn large_counts_do_not_underflow() {
        let r = median_ranks(10_000);
        // Normal approximation: n/2 ∓ 1.96·√n/2 = 5000 ∓ 98.
        assert!(
            (r.low as i64 - 4902).abs() <= 2 && r.high == 10_001 - r.low,
            "{r:?}"
        );
        assert!(r.confidence >= CONFIDENCE && r.confidence < 0.953);
    }

    #[test]
    fn one_to_n() {
        let x: Vec<f64> = (1..=20).map(f64::from).collect();
        let s = Summary::of(&x).unwrap();
        assert_eq!(s.median, 10.5);
        assert_eq!((s.ci_low, s.ci_high), (6.0, 15.0));
        assert_eq!((s.min, s.max, s.samples), (1.0, 20.0, 20));
        assert_eq!((s.q1, s.q3), (5.75, 15.25));
        assert!(s.noisy, "±43% is noisy");
        // The order of the samples does not matter.
        let mut shuffled = x.clone();
        shuffled.reverse();
        shuffled.swap(3, 17);
        assert_eq!(Summary::of(&shuffled).unwrap(), s);

        let odd = Summary::of(&(1..=101).map(f64::from).collect::<Vec<_>>()).unwrap();
        assert_eq!((odd.median, odd.q1, odd.q3), (51.0, 26.0, 76.0));
    }

    #[test]
    fn constant_samples_have_a_zero_width_interval() {
        let s = Summary::of(&[3.5; 12]).unwrap();
        assert_eq!(
            (s.median, s.ci_low, s.ci_high, s.min, s.max),
            (3.5, 3.5, 3.5, 3.5, 3.5)
        );
        assert!(!s.noisy);
        assert_eq!(s.relative_interval(), (0.0, 0.0));
    }

    #[test]
    fn the_noise_flag_is_at_five_percent() {
        // 20 samples: the interval is [x(6), x(15)].
        let around = |below: f64, above: f64| {
            let mut x = vec![100.0; 20];
            x[..6].fill(100.0 - below);
            x[14..].fill(100.0 + above);
            Summary::of(&x).unwrap()
        };
        assert!(!around(4.9, 4.9).noisy);
        assert!(around(5.1, 0.0).noisy);
        assert!(around(0.0, 5.1).noisy);
        // Too few samples for 95%: noisy however tight.
        assert!(Summary::of(&[1.0; 5]).unwrap().noisy);
    }

    #[test]
    fn paired_ratios() {
        // B takes twice as long in every round, whatever the round's drift.
        let a: Vec<f64> = (0..10).map(|i| 1.0 + 0.3 * f64::from(i)).collect();
        let b: Vec<f64> = a.iter().map(|x| 2.0 * x).collect();
        let r = Summary::paired_ratio(&a, &b).unwrap();
        assert_eq!((r.median, r.ci_low, r.ci_high), (0.5, 0.5, 0.5));
        assert!(!r.noisy);
        // Each variant's own interval is wide (±45%): the drift cancels only in pairs.
        assert!(Summary::of(&a).unwrap().noisy);
        assert_eq!(
            Summary::paired_ratio(&[1.0], &[1.0, 2.0]),
            Err(StatsError::Unpaired { a: 1, b: 2 })
        );
        assert_eq!(
            Summary::paired_ratio(&[1.0, 1.0], &[1.0, 0.0]),
            Err(StatsError::NotPositive { index: 1, value: 0.0 })
        );
    }

    #[test]
    fn scaling_changes_the_unit_only() {
        let s = Summary::of(&(1..=20).map(f64::from).collect::<Vec<_>>()).unwrap();
        let k = s.scaled(1e-3);
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
        assert!(close(k.median, 10.5e-3) && close(k.ci_low, 6e-3) && close(k.ci_high, 15e-3));
        assert_eq!((k.samples, k.noisy), (s.samples, s.noisy));
        let (a, b) = (k.relative_interval(), s.relative_interval());
        assert!(close(a.0, b.0) && close(a.1, b.1));
    }

    #[test]
    fn bad_samples_are_errors() {
        assert_eq!(Summary::of(&[]), Err(StatsError::Empty));
        assert!(matches!(
            Summary::of(&[1.0, f64::NAN]),
            Err(StatsError::NotFinite { index: 1, .. })
        ));
    }

    #[test]
    fn serialises_with_the_report_field_names() {
        let s = Summary::of(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]).unwrap();
        let json = serde_json::to_value(s).unwrap();
        for key in [
            "median",
            "ci_low",
            "ci_high",
            "samples",
            "confidence",
            "min",
            "q1",
            "q3",
            "max",
            "noisy",
        ] {
            assert!(json.get(key).is_some(), "{key} missing from {json}");
        }
        assert_eq!(json["samples"], 6);
        assert_eq!(serde_json::from_value::<Summary>(json).unwrap(), s);
    }
}
