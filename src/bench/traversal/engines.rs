//! The engines the traversal bench measures: which (each engine of the
//! registry, Embree once per ISA setting), their devices, and the rayon pools
//! their rays are traced on.

use crate::bench::pinned_pool::pinned_pool;
use crate::bench::rays::KindRays;
use crate::bench::traversal::trace::trace_path;
use crate::embree_settings::EmbreeIsa;
use crate::engines::{Built, Engine, EngineDevice, EngineOptions, WithAccel};
use crate::render::settings::KernelKind;
use crate::scene::Scene;

/// An engine as measured: Embree with the kernels of one ISA setting.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EngineVariant {
    /// The engine.
    pub engine: Engine,
    /// Embree's ISA setting (None for the other engines).
    pub embree_isa: Option<EmbreeIsa>,
}

impl EngineVariant {
    /// `raypack`, `embree(avx2)`, `embree(default)`.
    pub fn name(self) -> String {
        match self.embree_isa {
            Some(isa) => format!("{}({})", self.engine, isa.name()),
            None => self.engine.name().into(),
        }
    }

    /// The options of this variant's device with `threads` build threads:
    /// raypack's BVH, Embree fast on its ISA setting.
    pub fn options(self, threads: usize) -> EngineOptions {
        let defaults = EngineOptions::default();
        EngineOptions {
            embree_config: self
                .embree_isa
                .map_or(defaults.embree_config.clone(), |isa| isa.config(threads)),
            ..defaults
        }
    }
}

/// Trace a kind's rays by one path ([`trace_path`]): one by one, or in packets.
pub(super) struct TraceKind<'r> {
    /// The rays.
    pub set: &'r KindRays,
    /// Single rays, 8- or 16-ray packets.
    pub path: KernelKind,
}

impl WithAccel<'_> for TraceKind<'_> {
    type Output = u64;

    fn run<A: crate::accel::Accel>(self, accel: &A) -> u64 {
        trace_path(accel, self.set, self.path)
    }
}

/// `engines` as measured, in the order given, Embree once per setting of
/// `embree_isas`.
pub fn engine_variants(engines: &[Engine], embree_isas: &[EmbreeIsa]) -> anyhow::Result<Vec<EngineVariant>> {
    anyhow::ensure!(!engines.is_empty(), "no engine to measure");
    let mut variants: Vec<EngineVariant> = Vec::new();
    for &engine in engines {
        let isas = match engine {
            Engine::Embree => embree_isas.iter().copied().map(Some).collect(),
            _ => vec![None],
        };
        for embree_isa in isas {
            let variant = EngineVariant { engine, embree_isa };
            if !variants.contains(&variant) {
                variants.push(variant);
            }
        }
    }
    anyhow::ensure!(!variants.is_empty(), "no Embree ISA setting to measure");
    Ok(variants)
}

/// Builds each engine variant's structure with `threads` threads: holds the
/// devices of every variant.
pub struct Builder {
    devices: Vec<(EngineVariant, EngineDevice)>,
}

impl Builder {
    /// A builder for `engines` on `threads` threads, Embree at each setting of
    /// `embree_isas`: the devices (Embree's on [`EmbreeIsa::config`]`(threads)`,
    /// so its build gets as many threads as raypack's) are made here, so a
    /// missing feature or a failing device is reported before any scene is
    /// generated.
    ///
    /// Embree's thread limit is the task scheduler's, shared by every device
    /// of the process: drop one builder before making the next.
    pub fn new(engines: &[Engine], embree_isas: &[EmbreeIsa], threads: usize) -> anyhow::Result<Self> {
        let devices = engine_variants(engines, embree_isas)?
            .into_iter()
            .map(|v| Ok((v, v.engine.device(&v.options(threads.max(1)))?)))
            .collect::<anyhow::Result<_>>()?;
        Ok(Self { devices })
    }

    /// Build `variant`'s structure over `scene` (its instances as the engine takes them).
    pub fn build<'p>(&self, variant: EngineVariant, scene: &'p Scene) -> anyhow::Result<Built<'p>> {
        let (_, device) = self
            .devices
            .iter()
            .find(|(v, _)| *v == variant)
            .ok_or_else(|| anyhow::anyhow!("{} was not among the builder's engines", variant.name()))?;
        device.build_scene(scene)
    }
}

/// A rayon pool of `threads` threads, each pinned to its own CPU
/// ([`pinned_pool`]) and set up for every engine of `variants` (Embree's
/// FTZ/DAZ), so all engines run in the same mode.
pub(super) fn pool(threads: usize, variants: &[EngineVariant]) -> anyhow::Result<rayon::ThreadPool> {
    let pool = pinned_pool(threads)?;
    let engines: Vec<Engine> = variants.iter().map(|v| v.engine).collect();
    Engine::prepare_threads(&engines, &pool);
    Ok(pool)
}
