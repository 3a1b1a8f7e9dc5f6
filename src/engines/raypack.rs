//! raypack's own engine: its kernels through the structure `--accel` names,
//! the SAH BVH or brute force (the reference).

use crate::accel::{AccelKind, BruteForce, Bvh};
use crate::engines::capabilities::Capabilities;
use crate::engines::engine_module::{Description, EngineModule, EngineOptions, WithAccel};
use crate::geometry::Primitive;

/// raypack in the registry.
pub struct RaypackEngine;

/// raypack's structure over a scene: either kind, each traced as its own type.
pub enum RaypackBuilt<'p> {
    /// Brute force over the scene's primitives.
    None(BruteForce<'p>),
    /// The SAH BVH (boxed: its buffer headers take 232 bytes, brute force's slice 16).
    Bvh(Box<Bvh>),
}

impl EngineModule for RaypackEngine {
    const NAME: &'static str = "raypack";
    const CAPABILITIES: Capabilities = Capabilities::ALL;
    /// The structure to build.
    type Device = AccelKind;
    type Built<'p> = RaypackBuilt<'p>;

    fn device(options: &EngineOptions) -> anyhow::Result<AccelKind> {
        Ok(options.accel)
    }

    fn build<'p>(kind: &AccelKind, prims: &'p [Primitive]) -> anyhow::Result<RaypackBuilt<'p>> {
        Ok(match kind {
            AccelKind::None => RaypackBuilt::None(BruteForce::new(prims)),
            AccelKind::Bvh => RaypackBuilt::Bvh(Box::new(Bvh::new(prims))),
        })
    }

    fn visit<'s, J: WithAccel<'s>>(built: &'s RaypackBuilt<'_>, job: J) -> J::Output {
        match built {
            RaypackBuilt::None(brute_force) => job.run(brute_force),
            RaypackBuilt::Bvh(bvh) => job.run(&**bvh),
        }
    }

    fn describe(built: &RaypackBuilt<'_>) -> Description {
        let kind = match built {
            RaypackBuilt::None(_) => AccelKind::None,
            RaypackBuilt::Bvh(_) => AccelKind::Bvh,
        };
        Description {
            structure: kind.name(),
            settings: format!("raypack {}, {}", env!("CARGO_PKG_VERSION"), kind.name()),
            translation: None,
        }
    }

    fn sah_cost(built: &RaypackBuilt<'_>) -> Option<f64> {
        match built {
            RaypackBuilt::None(_) => None,
            RaypackBuilt::Bvh(bvh) => Some(bvh.info().sah_cost),
        }
    }
}
