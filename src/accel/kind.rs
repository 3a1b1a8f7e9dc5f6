//! The choice of acceleration structure (`--accel none|bvh`); raypack's engine
//! in the registry (`engines::raypack`) builds it.

use std::fmt;

/// Which acceleration structure to trace with.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum AccelKind {
    /// No acceleration: every ray against every primitive (the reference).
    None,
    /// The SAH bounding volume hierarchy.
    #[default]
    Bvh,
}

impl AccelKind {
    /// The name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            AccelKind::None => "none",
            AccelKind::Bvh => "bvh",
        }
    }
}

impl fmt::Display for AccelKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}
