//! Test hooks, not features, read by the bench timing loops only; unset (the
//! normal case) they change nothing:
//! - `RAYPACK_TEST_SLOWDOWN=VARIANT:FACTOR` multiplies the time of every
//!   sample of the variant named VARIANT (a kernel name: `scalar`, `packet8`,
//!   `packet4`, `packet16`; `single` for single-ray traversal) by FACTOR, so
//!   that a test can check that a baseline comparison reports a slowed variant
//!   as slower;
//! - `RAYPACK_TEST_CLOCK=work` times every sample by its work instead of the
//!   clock, one nanosecond per unit (a kernel test, a ray, a frame), so that
//!   two runs of one build give the same figures whatever else the machine
//!   does: a test of baseline comparisons then asserts on no timing.

/// The environment variable of the slowdown hook.
pub const VARIABLE: &str = "RAYPACK_TEST_SLOWDOWN";

/// The environment variable of the work clock.
pub const CLOCK_VARIABLE: &str = "RAYPACK_TEST_CLOCK";

/// Seconds a unit of work takes by the work clock.
const WORK_SECONDS: f64 = 1e-9;

/// The hooks' setting: which variant is slowed, by how much, and whether
/// samples are timed by their work.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TimingHooks {
    variant: Option<(String, f64)>,
    work_clock: bool,
}

impl TimingHooks {
    /// The setting of [`VARIABLE`] and [`CLOCK_VARIABLE`]; an error names a
    /// malformed value.
    pub fn from_env() -> Result<Self, String> {
        let mut hooks = match std::env::var(VARIABLE) {
            Ok(value) => Self::parse(&value)?,
            Err(_) => Self::default(),
        };
        match std::env::var(CLOCK_VARIABLE).as_deref() {
            Ok("work") => hooks.work_clock = true,
            Ok(other) => return Err(format!("{CLOCK_VARIABLE}={other}: expected work")),
            Err(_) => {}
        }
        Ok(hooks)
    }

    /// `VARIANT:FACTOR`, FACTOR a positive number.
    pub fn parse(value: &str) -> Result<Self, String> {
        let bad = || format!("{VARIABLE}={value}: expected VARIANT:FACTOR, e.g. packet8:2");
        let (name, factor) = value.split_once(':').ok_or_else(bad)?;
        let factor: f64 = factor.parse().map_err(|_| bad())?;
        if name.is_empty() || !(factor > 0.0 && factor.is_finite()) {
            return Err(bad());
        }
        Ok(Self {
            variant: Some((name.to_string(), factor)),
            work_clock: false,
        })
    }

    /// The time of a sample of `work` units on `variant` that the clock
    /// measured as `seconds` (or its work's time, by the work clock), slowed
    /// if `variant` is the hook's.
    pub fn apply(&self, variant: &str, work: f64, seconds: f64) -> f64 {
        let seconds = if self.work_clock {
            work * WORK_SECONDS
        } else {
            seconds
        };
        match &self.variant {
            Some((name, factor)) if name == variant => seconds * factor,
            _ => seconds,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_applies() {
        let s = TimingHooks::parse("packet8:2.5").unwrap();
        assert_eq!(s.apply("packet8", 7.0, 2.0), 5.0);
        assert_eq!(s.apply("scalar", 7.0, 2.0), 2.0);
        assert_eq!(TimingHooks::default().apply("packet8", 7.0, 2.0), 2.0);
        // By the work clock, a sample takes its work's time.
        let clocked = TimingHooks {
            work_clock: true,
            ..s
        };
        assert_eq!(clocked.apply("scalar", 7.0, 2.0), 7.0 * WORK_SECONDS);
        assert_eq!(clocked.apply("packet8", 7.0, 2.0), 2.5 * 7.0 * WORK_SECONDS);
        for bad in ["packet8", "packet8:x", ":2", "packet8:0", "packet8:-1", "a:inf"] {
            assert!(TimingHooks::parse(bad).is_err(), "{bad}");
        }
    }
}
