//! The choice of acceleration structure, made once at run time and then handed
//! to code generic over [`Accel`] (renderer, statistics, benchmarks) through a
//! visitor, so the traversal is monomorphised per structure.
//!
//! Adding a structure is one enum variant and one match arm in [`with_accel`].

use std::time::Instant;

pub use crate::accel::AccelKind;
use crate::accel::{Accel, BruteForce, Bvh};
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
