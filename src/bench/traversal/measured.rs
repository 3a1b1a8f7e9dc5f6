//! What the measurement keeps of each engine on each scene before it becomes
//! a row: the structure traced, the rays it hit, and the times of every round.

use crate::bench::traversal::engines::EngineVariant;
use crate::bench::traversal::setup::TraversalSetup;
use crate::bench::traversal::trace::PATHS;
use crate::engines::Built;

/// A scene and an engine measured on it: the structure traced and the rays it hit.
pub(super) struct EngineOnScene<'a> {
    /// The scene and its rays.
    pub setup: &'a TraversalSetup,
    /// The engine.
    pub variant: EngineVariant,
    /// The engine's structure over the scene, of the last build.
    pub structure: Built<'a>,
    /// Per ray set: rays hit by single rays.
    pub hits: Vec<u64>,
}

/// One thread count's figures of an [`EngineOnScene`].
pub(super) struct Timings {
    /// Build times, ms.
    pub build_ms: Vec<f64>,
    /// Per ray set and path of [`PATHS`]: each round's seconds per ray
    /// (none for a path the engine does not trace).
    pub per_ray: Vec<[Vec<f64>; PATHS.len()]>,
}

impl Timings {
    /// No figures yet, for `kinds` ray sets.
    pub fn empty(kinds: usize) -> Self {
        Self {
            build_ms: Vec::new(),
            per_ray: vec![Default::default(); kinds],
        }
    }
}
