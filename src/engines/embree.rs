//! Embree 4 as an engine (the `embree` feature): a device per run made with
//! the `--embree-config` string, a scene per build in the `--embree-mode`
//! (robust for checks, fast for benchmarks), every primitive kind translated
//! (`embree::translate`). Without the feature the engine keeps its
//! name and says how to get it.

use crate::engines::capabilities::Capabilities;

/// Embree in the registry.
pub struct EmbreeEngine;

/// What Embree can do, linked or not: everything raypack's kernels do, uncounted.
const CAPABILITIES: Capabilities = Capabilities {
    counts_work: false,
    // Embree's own instances (RTC_GEOMETRY_TYPE_INSTANCE) for meshes of its
    // native shapes; a scene with another mesh reaches it flattened.
    instances: true,
    ..Capabilities::ALL
};

#[cfg(feature = "embree")]
mod linked {
    use std::sync::Arc;

    use anyhow::Context;

    use crate::embree::{Device, EmbreeScene, flush_denormals};
    use crate::embree_settings::EmbreeMode;
    use crate::engines::capabilities::Capabilities;
    use crate::engines::embree::{CAPABILITIES, EmbreeEngine};
    use crate::engines::engine_module::{Description, EngineModule, EngineOptions, NO_INSTANCES, WithAccel};
    use crate::geometry::Primitive;
    use crate::scene::Scene;

    impl EngineModule for EmbreeEngine {
        const NAME: &'static str = "embree";
        const CAPABILITIES: Capabilities = CAPABILITIES;
        /// The device and the scene mode of every build.
        type Device = (Arc<Device>, EmbreeMode);
        type Built<'p> = EmbreeScene;

        fn device(options: &EngineOptions) -> anyhow::Result<Self::Device> {
            Ok((
                Arc::new(Device::new(&options.embree_config)?),
                options.embree_mode,
            ))
        }

        fn build((device, mode): &Self::Device, prims: &[Primitive]) -> anyhow::Result<EmbreeScene> {
            let device = device.clone();
            Ok(match mode {
                EmbreeMode::Robust => EmbreeScene::robust(device, prims),
                EmbreeMode::Fast => EmbreeScene::new(device, prims),
            }?)
        }

        fn build_scene(device: &Self::Device, scene: &Scene) -> anyhow::Result<EmbreeScene> {
            let instanced = scene.instances.meshes().iter().all(EmbreeScene::instances_mesh);
            if scene.instances.is_empty() || !instanced {
                // No instances, or a mesh Embree cannot instance: copies under the same ids.
                return Self::build(device, scene.flat_primitives().context(NO_INSTANCES)?);
            }
            let (device, mode) = device;
            Ok(EmbreeScene::with_instances(
                device.clone(),
                scene,
                *mode == EmbreeMode::Robust,
            )?)
        }

        fn visit<'s, J: WithAccel<'s>>(scene: &'s EmbreeScene, job: J) -> J::Output {
            job.run(scene)
        }

        fn describe(scene: &EmbreeScene) -> Description {
            let device = scene.device();
            let mode = if scene.is_robust() { "robust" } else { "fast" };
            let meshes = match scene.instanced_meshes() {
                0 => String::new(),
                n => format!(", {} instanced", crate::plural::count(n as u64, "mesh", "meshes")),
            };
            Description {
                structure: "embree",
                settings: format!(
                    "Embree {} \"{}\", {mode}{meshes}",
                    device.version_string(),
                    device.config()
                ),
                translation: serde_json::to_value(scene.stats()).ok(),
            }
        }

        fn thread_start() {
            flush_denormals();
        }
    }
}

#[cfg(not(feature = "embree"))]
crate::engines::unavailable::not_linked!(
    EmbreeEngine,
    "embree",
    CAPABILITIES,
    message = crate::embree_settings::EMBREE_MISSING
);
