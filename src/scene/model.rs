//! The scene model: primitives in file order, their materials, the lights and
//! the camera, as every reader returns them.

use std::borrow::Cow;
use std::collections::HashMap;

use glam::{Mat4, Vec3};

use crate::bounds::Aabb;
use crate::camera::{Camera, CameraError};
use crate::geometry::triangle::TriangleTest;
use crate::geometry::{Primitive, PrimitiveKind};
use crate::ray::{Hit, Ray};
use crate::scene::instance::{
    Instance, InstanceError, Instances, InstancingSummary, MAX_FLATTENED, Mesh, placed_normal,
    placed_primitive,
};

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
    /// The scene's own primitives in file order: ids `0..n` (instanced ones
    /// follow, see [`Scene::locate`]).
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
    /// Meshes placed by instances (none in a scene without instances).
    pub instances: Instances,
    /// What the reader left out or changed, one line each (glTF's points and
    /// lines, unsupported extensions…), for `info`.
    pub notes: Vec<String>,
}

/// What a primitive id names ([`Scene::locate`]).
#[derive(Clone, Copy, Debug)]
pub struct Located<'a> {
    /// The primitive (in object space for an instanced one).
    pub primitive: &'a Primitive,
    /// Its material index.
    pub material: u32,
    /// Its shading normals, if smooth (object space for an instanced one).
    pub vertex_normals: Option<&'a [Vec3; 3]>,
    /// The instance, with its index, for an instanced primitive.
    pub instance: Option<(u32, &'a Instance)>,
    /// Its index in the scene's own primitives or in its mesh.
    pub index: u32,
}

impl Scene {
    /// Every triangle of the scene under `test`.
    pub fn set_triangle_test(&mut self, test: TriangleTest) {
        for prim in &mut self.primitives {
            prim.set_triangle_test(test);
        }
        self.instances.for_each_primitive(|p| p.set_triangle_test(test));
    }

    /// Add a mesh for instances to place; returns its index.
    pub fn add_mesh(&mut self, mesh: Mesh) -> u32 {
        self.instances.add_mesh(mesh)
    }

    /// Place mesh `mesh` in the world by the affine matrix `to_world`; returns
    /// the instance's index.
    pub fn place(&mut self, mesh: u32, to_world: Mat4) -> Result<u32, InstanceError> {
        self.instances.place(mesh, to_world, self.primitives.len())
    }

    /// Every primitive id of the scene: its own primitives and the instanced ones.
    pub fn id_count(&self) -> u64 {
        self.primitives.len() as u64 + self.instances.ids()
    }

    /// The unique primitives: the scene's own and its meshes'.
    pub fn unique_primitives(&self) -> u64 {
        let meshes: usize = self.instances.meshes().iter().map(|m| m.primitives.len()).sum();
        (self.primitives.len() + meshes) as u64
    }

    /// What the scene's instancing amounts to; None without instances.
    pub fn instancing_summary(&self) -> Option<InstancingSummary> {
        if self.instances.is_empty() {
            return None;
        }
        let prim = size_of::<Primitive>() as u64;
        let meshes = self.instances.meshes();
        let mesh_prims: u64 = meshes.iter().map(|m| m.primitives.len() as u64).sum();
        Some(InstancingSummary {
            instances: self.instances.list().len(),
            meshes: meshes.len(),
            depth: self.instances.depth(),
            unique_primitives: self.unique_primitives(),
            instanced_primitives: self.id_count(),
            own_bytes: self.primitives.len() as u64 * (prim + 4),
            mesh_bytes: mesh_prims * (prim + 4),
            instance_bytes: size_of_val(self.instances.list()) as u64,
        })
    }

    /// What primitive id `id` (below [`id_count`](Self::id_count)) names.
    pub fn locate(&self, id: u32) -> Located<'_> {
        let own = self.primitives.len() as u32;
        if id < own {
            return Located {
                primitive: &self.primitives[id as usize],
                material: self.material_of[id as usize],
                vertex_normals: self.vertex_normals.get(&id),
                instance: None,
                index: id,
            };
        }
        let (i, index) = self.instances.holding(id - own);
        let instance = &self.instances.list()[i as usize];
        let mesh = &self.instances.meshes()[instance.mesh as usize];
        Located {
            primitive: &mesh.primitives[index as usize],
            material: mesh.material_of[index as usize],
            vertex_normals: mesh.vertex_normals.get(&index),
            instance: Some((i, instance)),
            index,
        }
    }

    /// The unit geometric normal at `hit` of `ray` (not turned to face the
    /// ray), and the world-space shading normals of its primitive if smooth.
    /// An instanced primitive's normal is found in its mesh's space, on the
    /// ray brought there by M⁻¹ (same t), and taken back by M⁻ᵀ.
    pub fn normals_at(&self, ray: &Ray, hit: &Hit) -> (Vec3, Option<[Vec3; 3]>) {
        let located = self.locate(hit.prim);
        let Some((_, instance)) = located.instance else {
            return (
                located.primitive.geometric_normal(ray, hit),
                located.vertex_normals.copied(),
            );
        };
        let local = Ray {
            origin: instance.to_object.transform_point3(ray.origin),
            dir: instance.to_object.transform_vector3(ray.dir),
            ..*ray
        };
        let m = instance.normal_to_world();
        let ng = placed_normal(located.primitive.geometric_normal(&local, hit), m);
        (ng, located.vertex_normals.map(|n| n.map(|n| placed_normal(n, m))))
    }

    /// Every primitive as a copy in world space, under its id: the scene's own
    /// primitives, then each instance's. What an engine without instances of
    /// its own builds over; made once, on the first call.
    pub fn flat_primitives(&self) -> Result<&[Primitive], InstanceError> {
        if self.instances.is_empty() {
            return Ok(&self.primitives);
        }
        let count = self.id_count();
        if count > MAX_FLATTENED {
            return Err(InstanceError::TooLargeToFlatten(count));
        }
        Ok(self
            .instances
            .flat_or(|| self.flattened_parts().map(|(p, _, _)| p).collect()))
    }

    /// The same scene without instances: every instanced primitive a copy of
    /// its own, under the same id, with its material and shading normals.
    pub fn flattened(&self) -> Result<Scene, InstanceError> {
        let count = self.id_count();
        if count > MAX_FLATTENED {
            return Err(InstanceError::TooLargeToFlatten(count));
        }
        let mut flat = Scene {
            primitives: Vec::with_capacity(count as usize),
            materials: self.materials.clone(),
            lights: self.lights.clone(),
            camera: self.camera,
            background: self.background,
            source: self.source.clone(),
            ..Scene::default()
        };
        for (prim, material, normals) in self.flattened_parts() {
            let id = flat.push(prim, material);
            if let Some(normals) = normals {
                flat.vertex_normals.insert(id, normals);
            }
        }
        Ok(flat)
    }

    /// Each id's primitive in world space, material and shading normals.
    fn flattened_parts(&self) -> impl Iterator<Item = (Primitive, u32, Option<[Vec3; 3]>)> + '_ {
        (0..self.id_count() as u32).map(|id| {
            let located = self.locate(id);
            let normals = match located.instance {
                None => located.vertex_normals.copied(),
                Some((_, instance)) => {
                    let m = instance.normal_to_world();
                    located.vertex_normals.map(|n| n.map(|n| placed_normal(n, m)))
                }
            };
            (self.world_primitive(id).into_owned(), located.material, normals)
        })
    }

    /// Primitive `id` (below [`id_count`](Self::id_count)) in world space:
    /// an own primitive as it is, an instanced one copied and placed, without
    /// flattening the scene.
    pub fn world_primitive(&self, id: u32) -> Cow<'_, Primitive> {
        let located = self.locate(id);
        match located.instance {
            None => Cow::Borrowed(located.primitive),
            Some((_, instance)) => Cow::Owned(
                placed_primitive(located.primitive, instance.to_world)
                    .expect("a placed instance's transform is affine and invertible"),
            ),
        }
    }

    /// Append a primitive with a material; returns its index.
    pub fn push(&mut self, prim: Primitive, material: u32) -> u32 {
        let index = self.primitives.len() as u32;
        self.primitives.push(prim);
        self.material_of.push(material);
        index
    }

    /// Bounds of all bounded primitives, instanced ones included (planes are
    /// unbounded and left out).
    pub fn bounds(&self) -> Aabb {
        let meshes: Vec<Aabb> = self.instances.meshes().iter().map(Mesh::bounds).collect();
        self.primitives
            .iter()
            .filter_map(Primitive::bounds)
            .chain(
                self.instances
                    .list()
                    .iter()
                    .map(|i| i.bounds(meshes[i.mesh as usize])),
            )
            .fold(Aabb::EMPTY, Aabb::union)
    }

    /// Primitive counts by kind, each instanced primitive counted once per
    /// instance (what rays meet).
    pub fn counts(&self) -> Vec<(PrimitiveKind, usize)> {
        let mut counts: std::collections::BTreeMap<PrimitiveKind, usize> = Default::default();
        for p in &self.primitives {
            *counts.entry(p.kind()).or_default() += 1;
        }
        // Each mesh's primitives once, times its instances.
        let meshes = self.instances.meshes();
        let mut placed = vec![0usize; meshes.len()];
        for instance in self.instances.list() {
            placed[instance.mesh as usize] += 1;
        }
        for (mesh, &times) in meshes.iter().zip(&placed) {
            for p in &mesh.primitives {
                *counts.entry(p.kind()).or_default() += times;
            }
        }
        counts.into_iter().collect()
    }

    /// The material of primitive `prim` (an id, instanced ones included).
    pub fn material(&self, prim: u32) -> &Material {
        &self.materials[self.locate(prim).material as usize]
    }

    /// A camera that frames the whole scene from [`DEFAULT_VIEW`], 512×512, for
    /// files without one (and the `gen:` test scenes at 256×256).
    pub fn default_camera(&self) -> CameraSpec {
        CameraSpec::framing_from(self.bounds(), 512, 512, DEFAULT_VIEW)
    }
}
