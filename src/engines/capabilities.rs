//! What an engine can trace, so that a command shows "n/a" with the reason
//! for what it cannot, instead of quietly taking another path.

/// The primitive kinds an engine's structure takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum PrimitiveKinds {
    /// Every kind raypack has (Embree's own or user geometry for the rest).
    All,
    /// Triangles only (polygons ear-clipped into triangles).
    Triangles,
}

/// What an engine can do; a `const` of each [`EngineModule`](super::EngineModule).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Capabilities {
    /// Nearest-hit queries.
    pub nearest: bool,
    /// Any-hit (occlusion) queries that stop at the first hit.
    pub any_hit: bool,
    /// 8-wide ray packets traced as packets.
    pub packet8: bool,
    /// 16-wide ray packets traced as packets.
    pub packet16: bool,
    /// The primitive kinds it takes.
    pub primitives: PrimitiveKinds,
    /// Rays with a `t_min` above zero (false: raypack moves such a ray's
    /// origin to `origin + t_min·dir` for the engine, and says so).
    pub t_min: bool,
    /// Traversal counts (nodes, leaves, primitives) for the statistics.
    pub counts_work: bool,
    /// Instances traced as instances, each mesh held once (false: the scene
    /// is flattened for the engine, every instanced primitive a copy).
    pub instances: bool,
}

impl Capabilities {
    /// Everything: raypack's own kernels, and Embree's.
    pub const ALL: Self = Self {
        nearest: true,
        any_hit: true,
        packet8: true,
        packet16: true,
        primitives: PrimitiveKinds::All,
        t_min: true,
        counts_work: true,
        instances: true,
    };

    /// A peer's: nearest and any hit on triangles (polygons split), one ray
    /// at a time, no traversal counts.
    pub const SINGLE_RAY_TRIANGLES: Self = Self {
        packet8: false,
        packet16: false,
        primitives: PrimitiveKinds::Triangles,
        counts_work: false,
        instances: false,
        ..Self::ALL
    };
}
