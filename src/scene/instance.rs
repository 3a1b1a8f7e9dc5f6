//! Instancing: a mesh placed in the world any number of times by affine
//! transforms, held once (lecture section 7, transformed objects, applied to
//! whole meshes).
//!
//! A scene's primitives are numbered in one 32-bit id space, which every
//! engine's hit records use: first the scene's own primitives (`0..n`), then
//! each instance's primitives in instance order, an instance's ids a run as
//! long as its mesh. [`Scene::locate`](crate::scene::Scene::locate) turns an id
//! back into the instance and the mesh primitive;
//! [`Scene::flattened`](crate::scene::Scene::flattened) makes the same
//! primitives as copies, under the same ids (for engines without instances of
//! their own, and to check that instancing changes nothing).
//!
//! Instances of instances (an included file that itself includes) are
//! composed when the scene is read, into one level of instances of meshes:
//! memory grows with the instance count and the unique primitives, never with
//! the instanced ones. (Embree's default build also traces one instance level,
//! `RTC_MAX_INSTANCE_LEVEL_COUNT = 1`.)

use std::collections::HashMap;
use std::sync::OnceLock;

use glam::{Mat3, Mat4, Vec3};

use crate::bounds::Aabb;
use crate::geometry::transformed::affine_inverse;
use crate::geometry::{GeometryError, Primitive, Transformed, Triangle};

/// Most ids a scene may have: hit records name primitives by `u32`, and
/// `u32::MAX` means "no hit".
pub const MAX_IDS: u64 = u32::MAX as u64;

/// Most primitives [`Scene::flattened`](crate::scene::Scene::flattened) makes
/// (2²⁶, some 8 GB of copies): an engine without instances of its own cannot
/// take a larger instanced scene.
pub const MAX_FLATTENED: u64 = 1 << 26;

/// A mesh that instances place: primitives in object space, each with its
/// material, and the shading normals of smooth triangles.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// Where it came from (a file, a generator), for `info`.
    pub name: String,
    /// Primitives in object space; an instance's id `first + i` is primitive `i`.
    pub primitives: Vec<Primitive>,
    /// Material index of each primitive (into the scene's materials).
    pub material_of: Vec<u32>,
    /// Object-space shading normals of smooth triangles, by primitive index.
    pub vertex_normals: HashMap<u32, [Vec3; 3]>,
}

impl Mesh {
    /// Bounds of the bounded primitives (planes are unbounded and left out).
    pub fn bounds(&self) -> Aabb {
        self.primitives
            .iter()
            .filter_map(Primitive::bounds)
            .fold(Aabb::EMPTY, Aabb::union)
    }

    /// Whether some primitive has no bounds (a plane): its instances cannot be
    /// culled by a box.
    pub fn has_unbounded(&self) -> bool {
        self.primitives.iter().any(|p| p.bounds().is_none())
    }

    /// Whether a ray brought into this mesh's space must have a unit
    /// direction: the sphere and cone kernels need one, while triangles and
    /// polygons take any length (their t is a ratio, the same in both spaces).
    pub fn needs_unit_directions(&self) -> bool {
        !self
            .primitives
            .iter()
            .all(|p| matches!(p, Primitive::Triangle(_) | Primitive::Polygon(_)))
    }
}

/// A mesh placed by an affine transform. 140 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instance {
    /// The mesh (index into the scene's meshes).
    pub mesh: u32,
    /// M, object to world.
    pub to_world: Mat4,
    /// M⁻¹, world to object (rays).
    pub to_object: Mat4,
    /// Where this instance's ids start, counted from the first instanced id
    /// (the scene's own primitives come before).
    pub first: u32,
}

impl Instance {
    /// M⁻ᵀ (upper 3×3): object-space normals to world space.
    pub fn normal_to_world(&self) -> Mat3 {
        Mat3::from_mat4(self.to_object).transpose()
    }

    /// World bounds: the corners of its mesh's box `b` ([`Mesh::bounds`]) mapped by M.
    pub fn bounds(&self, b: Aabb) -> Aabb {
        if b.is_empty() {
            return b;
        }
        Aabb::from_points(b.corners().map(|c| self.to_world.transform_point3(c)))
    }
}

/// Why a mesh cannot be placed, or a scene not flattened.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum InstanceError {
    /// The transform is not a finite, invertible affine map.
    #[error("{0}")]
    Transform(GeometryError),
    /// The ids would not fit 32 bits.
    #[error(
        "expected at most {MAX_IDS} primitives in all (hit records name them by 32-bit ids), \
         found {0} once instanced"
    )]
    TooManyIds(u64),
    /// Too many copies to flatten.
    #[error(
        "flattening the scene into copies would make {0} primitives, more than \
         {MAX_FLATTENED} (raypack::scene::instance::MAX_FLATTENED)"
    )]
    TooLargeToFlatten(u64),
}

/// What a scene's instancing amounts to, for `info` and render captions.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct InstancingSummary {
    /// Instances placed.
    pub instances: usize,
    /// Meshes they place.
    pub meshes: usize,
    /// Instance levels in the file as written (an include of a file that
    /// includes is 2); traced as one level of composed transforms.
    pub depth: u32,
    /// Primitives held: the scene's own and one copy of each mesh's.
    pub unique_primitives: u64,
    /// Primitives rays meet: the scene's own and each instance's.
    pub instanced_primitives: u64,
    /// Bytes of the scene's own primitives (top level).
    pub own_bytes: u64,
    /// Bytes of the meshes' primitives and materials (bottom level).
    pub mesh_bytes: u64,
    /// Bytes of the instance records (top level).
    pub instance_bytes: u64,
}

impl InstancingSummary {
    /// One line: `1,000 instances of 2 meshes (depth 2): 10,000 unique, 5,000,000 instanced primitives`.
    pub fn line(&self) -> String {
        format!(
            "{} of {} (depth {}): {} unique, {} instanced primitives",
            crate::plural::count(self.instances as u64, "instance", "instances"),
            crate::plural::count(self.meshes as u64, "mesh", "meshes"),
            self.depth,
            self.unique_primitives,
            self.instanced_primitives
        )
    }
}

/// A scene's meshes and instances (empty for a scene without instances).
/// The fields stay private so that the instances' id runs stay consistent.
#[derive(Clone, Debug, Default)]
pub struct Instances {
    meshes: Vec<Mesh>,
    placed: Vec<Instance>,
    /// Instanced ids so far: the sum of the placed meshes' sizes.
    ids: u64,
    /// Instance levels as written (see [`InstancingSummary::depth`]).
    depth: u32,
    /// The scene's primitives flattened, made once when an engine asks.
    flat: OnceLock<Vec<Primitive>>,
}

impl Instances {
    /// Add a mesh for instances to place; returns its index.
    pub fn add_mesh(&mut self, mesh: Mesh) -> u32 {
        self.meshes.push(mesh);
        self.meshes.len() as u32 - 1
    }

    /// Place mesh `mesh` by `to_world`, in a scene of `own` primitives of its
    /// own; returns the instance's index.
    pub fn place(&mut self, mesh: u32, to_world: Mat4, own: usize) -> Result<u32, InstanceError> {
        let to_object = affine_inverse(&to_world).map_err(InstanceError::Transform)?;
        let size = self.meshes[mesh as usize].primitives.len() as u64;
        let ids = self.ids + size;
        if own as u64 + ids > MAX_IDS {
            return Err(InstanceError::TooManyIds(own as u64 + ids));
        }
        self.placed.push(Instance {
            mesh,
            to_world,
            to_object,
            first: self.ids as u32,
        });
        self.ids = ids;
        Ok(self.placed.len() as u32 - 1)
    }

    /// Note that the file nests instances `depth` levels deep (the deepest counts).
    pub fn nested(&mut self, depth: u32) {
        self.depth = self.depth.max(depth);
    }

    /// Instance levels as written: 0 without instances, at least 1 with.
    pub fn depth(&self) -> u32 {
        if self.placed.is_empty() {
            0
        } else {
            self.depth.max(1)
        }
    }

    /// True when nothing is placed.
    pub fn is_empty(&self) -> bool {
        self.placed.is_empty()
    }

    /// The meshes.
    pub fn meshes(&self) -> &[Mesh] {
        &self.meshes
    }

    /// The instances, in id order.
    pub fn list(&self) -> &[Instance] {
        &self.placed
    }

    /// How many ids the instances take: the instanced primitives.
    pub fn ids(&self) -> u64 {
        self.ids
    }

    /// The instance holding instanced id `k` (counted from the first
    /// instanced id), and `k` within it.
    pub fn holding(&self, k: u32) -> (u32, u32) {
        let i = self.placed.partition_point(|p| p.first <= k) - 1;
        (i as u32, k - self.placed[i].first)
    }

    /// The flattened primitives, made by `make` the first time.
    pub(super) fn flat_or(&self, make: impl FnOnce() -> Vec<Primitive>) -> &[Primitive] {
        self.flat.get_or_init(make)
    }

    /// Change every mesh primitive by `f` (a triangle test set on the scene
    /// reaches its meshes too); the flattened copies are made again.
    pub fn for_each_primitive(&mut self, mut f: impl FnMut(&mut Primitive)) {
        self.meshes
            .iter_mut()
            .flat_map(|m| &mut m.primitives)
            .for_each(&mut f);
        self.flat = OnceLock::new();
    }
}

/// `prim` under the affine map `m` as a primitive of its own: a triangle's
/// vertices are moved (under the same test), anything else becomes a
/// [`Transformed`] primitive (composed with a transform it already has).
pub fn placed_primitive(prim: &Primitive, m: Mat4) -> Result<Primitive, GeometryError> {
    Ok(match prim {
        Primitive::Triangle(t) => {
            let [a, b, c] = t.vertices().map(|v| m.transform_point3(v));
            Primitive::Triangle(Triangle::new(a, b, c).with_test(t.test()))
        }
        Primitive::Transformed(inner) => Primitive::Transformed(Box::new(Transformed::new(
            inner.object().clone(),
            m * inner.matrix(),
        )?)),
        prim => Primitive::Transformed(Box::new(Transformed::new(prim.clone(), m)?)),
    })
}

/// A shading normal under M, by M⁻ᵀ (`normal_to_world`), renormalised.
pub fn placed_normal(n: Vec3, normal_to_world: Mat3) -> Vec3 {
    (normal_to_world * n).normalize_or_zero()
}
