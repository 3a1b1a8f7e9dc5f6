//! raypack's own engine: its kernels through the structure `--accel` names,
//! the SAH BVH or brute force (the reference).

use crate::accel::{AccelKind, BruteForce, Bvh, TwoLevel};
use crate::engines::capabilities::Capabilities;
use crate::engines::engine_module::{Description, EngineModule, EngineOptions, WithAccel};
use crate::geometry::Primitive;
use crate::scene::Scene;

/// raypack in the registry.
pub struct RaypackEngine;

/// raypack's structure over a scene: either kind, each traced as its own type.
pub enum RaypackBuilt<'p> {
    /// Brute force over the scene's primitives.
    None(BruteForce<'p>),
    /// The SAH BVH (boxed: its buffer headers take 232 bytes, brute force's slice 16).
    Bvh(Box<Bvh>),
    /// A scene with instances: brute force over each mesh under a top-level BVH.
    InstancedNone(Box<TwoLevel<BruteForce<'p>>>),
    /// A scene with instances: a BVH per mesh under a top-level BVH.
    InstancedBvh(Box<TwoLevel<Bvh>>),
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

    fn build_scene<'p>(kind: &AccelKind, scene: &'p Scene) -> anyhow::Result<RaypackBuilt<'p>> {
        if scene.instances.is_empty() {
            return Self::build(kind, &scene.primitives);
        }
        Ok(match kind {
            AccelKind::None => RaypackBuilt::InstancedNone(Box::new(TwoLevel::new(scene, BruteForce::new))),
            AccelKind::Bvh => RaypackBuilt::InstancedBvh(Box::new(TwoLevel::new(scene, Bvh::new))),
        })
    }

    fn visit<'s, J: WithAccel<'s>>(built: &'s RaypackBuilt<'_>, job: J) -> J::Output {
        match built {
            RaypackBuilt::None(brute_force) => job.run(brute_force),
            RaypackBuilt::Bvh(bvh) => job.run(&**bvh),
            RaypackBuilt::InstancedNone(two_level) => job.run(&**two_level),
            RaypackBuilt::InstancedBvh(two_level) => job.run(&**two_level),
        }
    }

    fn describe(built: &RaypackBuilt<'_>) -> Description {
        let (kind, instanced) = match built {
            RaypackBuilt::None(_) => (AccelKind::None, ""),
            RaypackBuilt::Bvh(_) => (AccelKind::Bvh, ""),
            RaypackBuilt::InstancedNone(_) => (AccelKind::None, " per mesh, instances under a bvh"),
            RaypackBuilt::InstancedBvh(_) => (AccelKind::Bvh, " per mesh, instances under a bvh"),
        };
        Description {
            structure: kind.name(),
            settings: format!(
                "raypack {}, {}{instanced}",
                env!("CARGO_PKG_VERSION"),
                kind.name()
            ),
            translation: None,
        }
    }

    fn sah_cost(built: &RaypackBuilt<'_>) -> Option<f64> {
        match built {
            RaypackBuilt::Bvh(bvh) => Some(bvh.info().sah_cost),
            _ => None,
        }
    }
}
