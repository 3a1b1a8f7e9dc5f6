//! The engines the traversal bench measures: which (raypack, Embree at each
//! ISA setting), the structures they build over a scene, and the rayon pools
//! their rays are traced on.

use crate::accel::Bvh;
use crate::bench::rays::KindRays;
use crate::bench::traversal::trace::{trace_packets, trace_single};
use crate::engine::{EmbreeIsa, Engine};
use crate::geometry::Primitive;

/// An engine as measured: Embree with the kernels of one ISA setting.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EngineVariant {
    /// The engine.
    pub engine: Engine,
    /// Embree's ISA setting (None for raypack).
    pub embree_isa: Option<EmbreeIsa>,
}

impl EngineVariant {
    /// `raypack`, `embree(avx2)`, `embree(default)`.
    pub fn name(self) -> String {
        match (self.engine, self.embree_isa) {
            (Engine::Raypack, _) => "raypack".into(),
            (Engine::Embree, Some(isa)) => format!("embree({})", isa.name()),
            (Engine::Embree, None) => "embree".into(),
        }
    }
}

/// A structure built over a scene whose traversal is timed.
pub enum Structure {
    /// raypack's SAH BVH.
    Raypack(Bvh),
    /// Embree's BVH, default (fast) scene flags.
    #[cfg(feature = "embree")]
    Embree(crate::embree::EmbreeScene),
}

impl Structure {
    /// Trace `set`'s rays one by one ([`trace_single`]) or in packets ([`trace_packets`]).
    pub(super) fn trace(&self, set: &KindRays, packets: bool) -> u64 {
        match (self, packets) {
            (Self::Raypack(bvh), false) => trace_single(bvh, set),
            (Self::Raypack(bvh), true) => trace_packets(bvh, set),
            #[cfg(feature = "embree")]
            (Self::Embree(scene), false) => trace_single(scene, set),
            #[cfg(feature = "embree")]
            (Self::Embree(scene), true) => trace_packets(scene, set),
        }
    }
}

/// `engines` as measured, in the order given, Embree once per setting of
/// `embree_isas`.
pub(super) fn engine_variants(
    engines: &[Engine],
    embree_isas: &[EmbreeIsa],
) -> anyhow::Result<Vec<EngineVariant>> {
    anyhow::ensure!(!engines.is_empty(), "no engine to measure");
    let mut variants: Vec<EngineVariant> = Vec::new();
    for &engine in engines {
        let isas = match engine {
            Engine::Raypack => vec![None],
            Engine::Embree => embree_isas.iter().copied().map(Some).collect(),
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

/// Builds each engine's structure with `threads` threads; holds Embree's
/// devices (one per ISA setting) when Embree is measured.
pub struct Builder {
    #[cfg(feature = "embree")]
    devices: Vec<(EmbreeIsa, std::sync::Arc<crate::embree::Device>)>,
}

impl Builder {
    /// A builder for `engines` on `threads` threads, Embree at each setting of
    /// `embree_isas`: Embree's devices (on [`EmbreeIsa::config`]`(threads)`,
    /// so its build gets as many threads as raypack's) are made here, so a
    /// missing feature or a failing device is reported before any scene is
    /// generated.
    ///
    /// Embree's thread limit is the task scheduler's, shared by every device
    /// of the process: drop one builder before making the next.
    pub fn new(engines: &[Engine], embree_isas: &[EmbreeIsa], threads: usize) -> anyhow::Result<Self> {
        let variants = engine_variants(engines, embree_isas)?;
        #[cfg(feature = "embree")]
        {
            let threads = threads.max(1);
            let devices = variants
                .iter()
                .filter_map(|v| v.embree_isa)
                .map(|isa| {
                    let device = crate::embree::Device::new(&isa.config(threads))?;
                    Ok((isa, std::sync::Arc::new(device)))
                })
                .collect::<anyhow::Result<_>>()?;
            Ok(Self { devices })
        }
        #[cfg(not(feature = "embree"))]
        {
            let _ = threads;
            let embree = variants.iter().any(|v| v.engine == Engine::Embree);
            anyhow::ensure!(!embree, crate::engine::EMBREE_MISSING);
            Ok(Self {})
        }
    }

    /// Build `variant`'s structure over `prims`.
    pub fn build(&self, variant: EngineVariant, prims: &[Primitive]) -> anyhow::Result<Structure> {
        match variant.engine {
            Engine::Raypack => Ok(Structure::Raypack(Bvh::new(prims))),
            #[cfg(feature = "embree")]
            Engine::Embree => {
                let device = self
                    .devices
                    .iter()
                    .find(|(isa, _)| Some(*isa) == variant.embree_isa)
                    .map(|(_, device)| device.clone())
                    .ok_or_else(|| {
                        anyhow::anyhow!("{} was not among the builder's engines", variant.name())
                    })?;
                Ok(Structure::Embree(crate::embree::EmbreeScene::new(device, prims)?))
            }
            #[cfg(not(feature = "embree"))]
            Engine::Embree => anyhow::bail!(crate::engine::EMBREE_MISSING),
        }
    }
}

/// A rayon pool of `threads` threads; with Embree among the engines every
/// thread sets FTZ/DAZ, so both engines run in that mode.
pub(super) fn pool(threads: usize, variants: &[EngineVariant]) -> anyhow::Result<rayon::ThreadPool> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads);
    #[cfg(feature = "embree")]
    let pool = if variants.iter().any(|v| v.engine == Engine::Embree) {
        pool.start_handler(|_| crate::embree::flush_denormals())
    } else {
        pool
    };
    #[cfg(not(feature = "embree"))]
    let _ = variants;
    Ok(pool.build()?)
}
