//! The scene model: primitives in file order, their materials, the lights and
//! the camera, as every reader returns them.

use std::collections::HashMap;

use glam::Vec3;

use crate::bounds::Aabb;
use crate::camera::{Camera, CameraError};
use crate::geometry::triangle::TriangleTest;
use crate::geometry::{Primitive, PrimitiveKind};

/// A Phong/Whitted surface, as NFF's `f` line describes it. 32 bytes.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Material {
    /// Base colour (linear RGB in `[0, 1]`).
    pub color: Vec3,
    /// Diffuse weight.
    pub kd: f32,
    /// Specular weight; > 0 also spawns mirror reflection rays.
    pub ks: f32,
    /// Phong exponent.
    pub shine: f32,
    /// Transmittance; > 0 spawns refraction rays and makes the surface two-sided.
    pub transmittance: f32,
    /// Index of refraction.
    pub ior: f32,
}

impl Default for Material {
    /// NFF's implied default: white, fully diffuse, opaque.
    fn default() -> Self {
        Self {
            color: Vec3::ONE,
            kd: 1.0,
            ks: 0.0,
            shine: 0.0,
            transmittance: 0.0,
            ior: 1.0,
        }
    }
}

/// A positional light. 24 bytes.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Light {
    /// Position.
    pub position: Vec3,
    /// Colour (linear RGB).
    pub color: Vec3,
}

/// The camera as a scene file states it, before it becomes a [`Camera`].
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CameraSpec {
    /// Eye position.
    pub eye: Vec3,
    /// Look-at point.
    pub center: Vec3,
    /// World up.
    pub up: Vec3,
    /// Horizontal field of view in degrees (edge to edge of the image).
    pub fovx: f32,
    /// Vertical field of view in degrees (edge to edge of the image).
    pub fovy: f32,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
}

/// The direction the default camera looks from: in front, a little right and
/// above, so a model without a camera of its own shows its depth rather than a
/// flat silhouette.
pub const DEFAULT_VIEW: Vec3 = Vec3::new(0.3, 0.4, 1.0);

impl CameraSpec {
    /// A camera looking down −z at the centre of `bounds` that fits the box's
    /// bounding sphere in the image: the benchmarks' fixed view (see
    /// [`framing_from`](Self::framing_from)).
    pub fn framing(bounds: Aabb, width: u32, height: u32) -> CameraSpec {
        Self::framing_from(bounds, width, height, Vec3::Z)
    }

    /// A camera at the centre of `bounds` plus a multiple of `direction`,
    /// looking back at the centre, that fits the box's bounding sphere in the
    /// image. The lecture's primary rays start on the image plane, one unit in
    /// front of the eye, so the eye stands at least `1 + 2·radius` away (a
    /// small model would otherwise lie behind the image plane and never be
    /// hit) and the field of view narrows to fit. `direction` must not be
    /// parallel to +y (the up vector).
    pub fn framing_from(bounds: Aabb, width: u32, height: u32, direction: Vec3) -> CameraSpec {
        let (center, radius) = if bounds.is_empty() {
            (Vec3::ZERO, 1.0)
        } else {
            (bounds.center(), (0.5 * bounds.extent().length()).max(1e-3))
        };
        let distance = (radius / 20f32.to_radians().sin()).max(1.0 + 2.0 * radius);
        let fovy = 2.0 * (radius / distance).asin();
        let fovx = 2.0 * ((0.5 * fovy).tan() * width as f32 / height as f32).atan();
        CameraSpec {
            eye: center + distance * direction.normalize(),
            center,
            up: Vec3::Y,
            fovx: fovx.to_degrees(),
            fovy: fovy.to_degrees(),
            width,
            height,
        }
    }

    /// The camera at the scene's own resolution.
    pub fn camera(&self) -> Result<Camera, CameraError> {
        self.camera_at(self.width, self.height)
    }

    /// The camera at another resolution, with the same fields of view.
    pub fn camera_at(&self, width: u32, height: u32) -> Result<Camera, CameraError> {
        Camera::new(
            self.eye,
            self.center,
            self.up,
            self.fovx,
            self.fovy,
            width,
            height,
        )
    }
}

/// A loaded scene.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    /// Primitives in file order; a hit's primitive index points here.
    pub primitives: Vec<Primitive>,
    /// Material index of each primitive (parallel to `primitives`).
    pub material_of: Vec<u32>,
    /// Materials.
    pub materials: Vec<Material>,
    /// Positional lights.
    pub lights: Vec<Light>,
    /// The camera, if the file has one.
    pub camera: Option<CameraSpec>,
    /// Background colour.
    pub background: Vec3,
    /// Per-vertex shading normals of smooth-shaded triangles (NFF `pp`, meshes
    /// with normals), by primitive index; interpolated with the hit's (u, v).
    pub vertex_normals: HashMap<u32, [Vec3; 3]>,
    /// Where the scene came from (file path or generator), for reports.
    pub source: String,
}

impl Scene {
    /// Every triangle of the scene under `test`.
    pub fn set_triangle_test(&mut self, test: TriangleTest) {
        for prim in &mut self.primitives {
            prim.set_triangle_test(test);
        }
    }

    /// Append a primitive with a material; returns its index.
    pub fn push(&mut self, prim: Primitive, material: u32) -> u32 {
        let index = self.primitives.len() as u32;
        self.primitives.push(prim);
        self.material_of.push(material);
        index
    }

    /// Bounds of all bounded primitives (planes are unbounded and left out).
    pub fn bounds(&self) -> Aabb {
        self.primitives
            .iter()
            .filter_map(Primitive::bounds)
            .fold(Aabb::EMPTY, Aabb::union)
    }

    /// Primitive counts by kind.
    pub fn counts(&self) -> Vec<(PrimitiveKind, usize)> {
        let mut counts: std::collections::BTreeMap<PrimitiveKind, usize> = Default::default();
        for p in &self.primitives {
            *counts.entry(p.kind()).or_default() += 1;
        }
        counts.into_iter().collect()
    }

    /// The material of primitive `prim`.
    pub fn material(&self, prim: u32) -> &Material {
        &self.materials[self.material_of[prim as usize] as usize]
    }

    /// A camera that frames the whole scene from [`DEFAULT_VIEW`], 512×512, for
    /// files without one (and the `gen:` test scenes at 256×256).
    pub fn default_camera(&self) -> CameraSpec {
        CameraSpec::framing_from(self.bounds(), 512, 512, DEFAULT_VIEW)
    }
}
