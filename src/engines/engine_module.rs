//! What every engine module of the registry implements ([`EngineModule`]),
//! the settings its device is made with, what its structure says about
//! itself, and the jobs that run on any engine's structure ([`WithAccel`]).

use anyhow::Context;

use crate::accel::{Accel, AccelKind};
use crate::embree_settings::{DEFAULT_EMBREE_CONFIG, EmbreeMode};
use crate::engines::capabilities::Capabilities;
use crate::geometry::Primitive;
use crate::scene::Scene;

/// What an engine that builds over copies says when the copies would be too many.
pub const NO_INSTANCES: &str = "this engine has no instances of its own";

/// Code to run with an engine's structure, whatever its type; the output may
/// borrow the structure for `'s` (a timed unit of `bench scene` does).
pub trait WithAccel<'s> {
    /// What the code returns.
    type Output;
    /// Run with the structure `accel`.
    fn run<A: Accel + 's>(self, accel: &'s A) -> Self::Output;
}

/// The settings an engine's device is made with; each engine reads its own.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct EngineOptions {
    /// raypack: which acceleration structure (`--accel`).
    pub accel: AccelKind,
    /// Embree: the device configuration (`--embree-config`, or an ISA
    /// setting's with a thread count).
    pub embree_config: String,
    /// Embree: the scene mode.
    pub embree_mode: EmbreeMode,
}

impl Default for EngineOptions {
    /// raypack's BVH; Embree fast on [`DEFAULT_EMBREE_CONFIG`], the pairing benchmarks use.
    fn default() -> Self {
        Self {
            accel: AccelKind::Bvh,
            embree_config: DEFAULT_EMBREE_CONFIG.to_string(),
            embree_mode: EmbreeMode::Fast,
        }
    }
}

/// What a built structure says about itself, for captions and results.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Description {
    /// The structure in a few words: `bvh`, `embree` (the `accel` of results).
    pub structure: &'static str,
    /// The engine's version and settings, one line (`Embree 4.4.0 "threads=1,isa=avx2", fast`).
    pub settings: String,
    /// What the engine made of the scene's primitives (Embree: its geometries per kind).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub translation: Option<serde_json::Value>,
}

/// One engine: what it can do, how it is made and built, and how work reaches
/// its structure. Implemented by one type per module of `engines/`.
pub trait EngineModule {
    /// The name on the command line and in results.
    const NAME: &'static str;
    /// What the engine can trace.
    const CAPABILITIES: Capabilities;
    /// Whether this build has the engine (an engine behind a cargo feature
    /// keeps its line without it, and says how to get it).
    const LINKED: bool = true;
    /// What is made once per run and shared by every build (Embree's device).
    type Device: Send + Sync;
    /// The structure built over a scene's primitives (which it may borrow).
    type Built<'p>: Send + Sync;

    /// Make the device with `options`; an engine missing from this build says
    /// here how to get it.
    fn device(options: &EngineOptions) -> anyhow::Result<Self::Device>;

    /// Build the structure over `prims` (a hit's primitive index is the position in `prims`).
    fn build<'p>(device: &Self::Device, prims: &'p [Primitive]) -> anyhow::Result<Self::Built<'p>>;

    /// Build the structure over `scene`, its instances included (hit ids as
    /// [`Scene::locate`] reads them). By default the engine has no instances
    /// of its own and builds over copies of the instanced primitives under
    /// the same ids ([`Scene::flat_primitives`]).
    fn build_scene<'p>(device: &Self::Device, scene: &'p Scene) -> anyhow::Result<Self::Built<'p>> {
        Self::build(device, scene.flat_primitives().context(NO_INSTANCES)?)
    }

    /// Run `job` with the structure `built`.
    fn visit<'s, J: WithAccel<'s>>(built: &'s Self::Built<'_>, job: J) -> J::Output;

    /// What `built` says about itself.
    fn describe(built: &Self::Built<'_>) -> Description;

    /// The tree's SAH cost, where the engine shows its tree (a walk over it).
    fn sah_cost(_built: &Self::Built<'_>) -> Option<f64> {
        None
    }

    /// Set up a worker thread that will trace through this engine (Embree:
    /// flush denormals to zero, as it asks of its callers).
    fn thread_start() {}
}
