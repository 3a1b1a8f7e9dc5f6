//! The scenes of the traversal bench and their rays, made before any timing.

use glam::Vec3;

use crate::bench::rays::{KindRays, RayKind, RaySource, default_light};
use crate::bounds::Aabb;
use crate::camera::{Camera, CameraError};
use crate::scene::Scene;
use crate::scene::generate::random::{bumpy_sphere, framing_camera, random_spheres};
use crate::scene::generate::test_scenes::scene_of;

/// A scene and the rays it is measured on.
pub struct TraversalSetup {
    /// Name in reports (`mesh-1000`, `dragon`…).
    pub name: String,
    /// The scene (primitives, and instances if it has any).
    pub scene: Scene,
    /// The rays of each kind measured, in the order asked.
    pub kinds: Vec<KindRays>,
    /// Image size of the primary rays.
    pub resolution: (u32, u32),
}

impl TraversalSetup {
    /// The rays of `kinds` for `scene` seen by `camera` (`width`, `height`
    /// multiples of 16 are best: partial tiles get inactive lanes), shadow rays
    /// going to `light` (or [`default_light`]), plus `random` random rays.
    pub fn new(
        name: impl Into<String>,
        scene: Scene,
        camera: &Camera,
        light: Option<Vec3>,
        random: usize,
        kinds: &[RayKind],
    ) -> Self {
        let bounds = scene_bounds(&scene);
        let rays = RaySource {
            scene: &scene,
            bounds,
            camera,
            light: light.unwrap_or_else(|| default_light(bounds)),
            random,
            seed: 2,
        }
        .make(kinds);
        Self {
            name: name.into(),
            scene,
            kinds: rays,
            resolution: (camera.width, camera.height),
        }
    }

    /// The rays of `kinds` for a loaded `scene` named `name`, seen by its own
    /// camera (or a [`framing_camera`] where it has none) at `width × height`,
    /// shadow rays going to its first light, plus `random` random rays; an
    /// error where its camera cannot be made.
    pub fn of_scene(
        name: impl Into<String>,
        scene: Scene,
        (width, height): (u32, u32),
        random: usize,
        kinds: &[RayKind],
    ) -> Result<Self, CameraError> {
        let camera = match scene.camera {
            Some(spec) => spec.camera_at(width, height)?,
            None => framing_camera(scene_bounds(&scene), width, height),
        };
        let light = scene.lights.first().map(|l| l.position);
        Ok(Self::new(name, scene, &camera, light, random, kinds))
    }

    /// A generated scene of about `n` primitives: `kind` is `mesh` (bumpy-sphere
    /// triangles) or `spheres`; seen by [`framing_camera`].
    pub fn generated(
        kind: &str,
        n: usize,
        (width, height): (u32, u32),
        random: usize,
        kinds: &[RayKind],
    ) -> Option<Self> {
        let prims = match kind {
            "mesh" => bumpy_sphere(n, 1),
            "spheres" => random_spheres(n, 1),
            _ => return None,
        };
        let scene = scene_of(format!("{kind}-{n}"), prims);
        let camera = framing_camera(scene_bounds(&scene), width, height);
        Some(Self::new(
            format!("{kind}-{n}"),
            scene,
            &camera,
            None,
            random,
            kinds,
        ))
    }

    /// The rays of `kind`, if measured.
    pub fn rays_of(&self, kind: RayKind) -> Option<&KindRays> {
        self.kinds.iter().find(|s| s.kind == kind)
    }
}

/// The box of the bounded primitives, instanced ones included (the unit
/// cube when there are none).
pub fn scene_bounds(scene: &Scene) -> Aabb {
    let b = scene.bounds();
    if b.is_empty() {
        Aabb::new(-glam::Vec3::ONE, glam::Vec3::ONE)
    } else {
        b
    }
}
