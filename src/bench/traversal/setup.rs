//! The scenes of the traversal bench and their rays, made before any timing.

use glam::Vec3;

use crate::bench::rays::{KindRays, RayKind, RaySource, default_light};
use crate::bounds::Aabb;
use crate::camera::Camera;
use crate::geometry::Primitive;
use crate::scene::generate::random::{bumpy_sphere, framing_camera, random_spheres};

/// A scene and the rays it is measured on.
pub struct TraversalSetup {
    /// Name in reports (`mesh-1000`, `dragon`…).
    pub name: String,
    /// The primitives.
    pub prims: Vec<Primitive>,
    /// The rays of each kind measured, in the order asked.
    pub kinds: Vec<KindRays>,
    /// Image size of the primary rays.
    pub resolution: (u32, u32),
}

impl TraversalSetup {
    /// The rays of `kinds` for `prims` seen by `camera` (`width`, `height`
    /// multiples of 16 are best: partial tiles get inactive lanes), shadow rays
    /// going to `light` (or [`default_light`]), plus `random` random rays.
    pub fn new(
        name: impl Into<String>,
        prims: Vec<Primitive>,
        camera: &Camera,
        light: Option<Vec3>,
        random: usize,
        kinds: &[RayKind],
    ) -> Self {
        let bounds = scene_bounds(&prims);
        let rays = RaySource {
            prims: &prims,
            bounds,
            camera,
            light: light.unwrap_or_else(|| default_light(bounds)),
            random,
            seed: 2,
        }
        .make(kinds);
        Self {
            name: name.into(),
            prims,
            kinds: rays,
            resolution: (camera.width, camera.height),
        }
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
        let camera = framing_camera(scene_bounds(&prims), width, height);
        Some(Self::new(
            format!("{kind}-{n}"),
            prims,
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

/// The box of the bounded primitives (the unit cube when there are none).
pub fn scene_bounds(prims: &[Primitive]) -> Aabb {
    let b = prims
        .iter()
        .filter_map(Primitive::bounds)
        .fold(Aabb::EMPTY, Aabb::union);
    if b.is_empty() {
        Aabb::new(-glam::Vec3::ONE, glam::Vec3::ONE)
    } else {
        b
    }
}
