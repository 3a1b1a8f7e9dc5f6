//! The choice of acceleration structure, made once at run time and then handed
//! to code generic over [`Accel`] (renderer, statistics, benchmarks) through a
//! visitor, so the traversal is monomorphised per structure. A job may count
//! the traversal work of the structures that report it ([`Accel::COUNTS_WORK`]:
//! raypack's own, not Embree).
//!
//! Adding a structure is one enum variant and one match arm in [`with_accel`].

use std::time::Instant;

pub use crate::accel::AccelKind;
use crate::accel::{Accel, BruteForce, Bvh};
pub use crate::engine::Engine;
use crate::scene::Scene;

/// Code to run with an acceleration structure of any type.
pub trait WithAccel {
    /// What the code returns.
    type Output;
    /// Run with the structure `accel`, built in `setup_seconds`.
    fn run<A: Accel>(self, accel: &A, setup_seconds: f64) -> Self::Output;
}

/// Build the structure `kind` over `scene`'s primitives, timing the build, and run `job` with it.
pub fn with_accel<J: WithAccel>(scene: &Scene, kind: AccelKind, job: J) -> J::Output {
    let start = Instant::now();
    match kind {
        AccelKind::None => {
            let accel = BruteForce::new(&scene.primitives);
            job.run(&accel, start.elapsed().as_secs_f64())
        }
        AccelKind::Bvh => {
            let accel = Bvh::new(&scene.primitives);
            job.run(&accel, start.elapsed().as_secs_f64())
        }
    }
}

/// Run `job` with the engine the user chose: raypack's structure `kind`, or
/// Embree in its default (fast) scene mode on
/// [`DEFAULT_EMBREE_CONFIG`](crate::engine::DEFAULT_EMBREE_CONFIG), with
/// FTZ/DAZ set on every worker thread as Embree wants.
pub fn with_engine<J: WithAccel>(
    scene: &Scene,
    engine: Engine,
    kind: AccelKind,
    job: J,
) -> anyhow::Result<J::Output> {
    match engine {
        Engine::Raypack => Ok(with_accel(scene, kind, job)),
        Engine::Embree => with_embree(scene, job),
    }
}

#[cfg(feature = "embree")]
fn with_embree<J: WithAccel>(scene: &Scene, job: J) -> anyhow::Result<J::Output> {
    use crate::embree::{Device, EmbreeScene, flush_denormals};
    use crate::engine::DEFAULT_EMBREE_CONFIG;
    rayon::broadcast(|_| flush_denormals());
    let start = Instant::now();
    let device = std::sync::Arc::new(Device::new(DEFAULT_EMBREE_CONFIG)?);
    let embree = EmbreeScene::new(device, &scene.primitives)?;
    Ok(job.run(&embree, start.elapsed().as_secs_f64()))
}

#[cfg(not(feature = "embree"))]
fn with_embree<J: WithAccel>(_scene: &Scene, _job: J) -> anyhow::Result<J::Output> {
    anyhow::bail!(crate::engine::EMBREE_MISSING)
}
