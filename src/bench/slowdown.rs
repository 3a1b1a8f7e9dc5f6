//! A test hook, not a feature: `RAYPACK_TEST_SLOWDOWN=VARIANT:FACTOR`
//! multiplies the measured time of every sample of the variant named VARIANT
//! (a kernel name: `scalar`, `packet8`, `packet4`, `packet16`; `single` for
//! single-ray traversal) by FACTOR, so that a test can check that a baseline
//! comparison reports a slowed variant as slower. Only the bench timing loops
//! read it; unset (the normal case) it changes nothing.

/// The environment variable of the hook.
pub const VARIABLE: &str = "RAYPACK_TEST_SLOWDOWN";

/// The hook's setting: which variant, by how much.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Slowdown {
    variant: Option<(String, f64)>,
}

impl Slowdown {
    /// The setting of [`VARIABLE`]; an error names a malformed value.
    pub fn from_env() -> Result<Self, String> {
        match std::env::var(VARIABLE) {
            Ok(value) => Self::parse(&value),
            Err(_) => Ok(Self::default()),
        }
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
        })
    }

    /// `seconds` measured on `variant`, slowed if it is the hook's variant.
    pub fn apply(&self, variant: &str, seconds: f64) -> f64 {
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
        let s = Slowdown::parse("packet8:2.5").unwrap();
        assert_eq!(s.apply("packet8", 2.0), 5.0);
        assert_eq!(s.apply("scalar", 2.0), 2.0);
        assert_eq!(Slowdown::default().apply("packet8", 2.0), 2.0);
        for bad in ["packet8", "packet8:x", ":2", "packet8:0", "packet8:-1", "a:inf"] {
            assert!(Slowdown::parse(bad).is_err(), "{bad}");
        }
    }
}
