//! [`EmbreeScene`]: raypack primitives translated into an Embree scene (see
//! [`translate`](super::translate) for which primitive becomes which Embree
//! geometry), with the map from Embree's geometry and primitive ids back to
//! raypack's primitive indices. Tracing through it is `trace.rs`.

use std::sync::Arc;

use embree4_sys as sys;

use crate::embree::EmbreeError;
use crate::embree::denormals::flush_denormals;
use crate::embree::device::Device;
use crate::embree::raw_scene::RawScene;
use crate::embree::ray_hit::INVALID_ID;
use crate::embree::translate::{NativeShape, Placement, TranslationStats, place};
use crate::embree::user_geometry::UserPrims;
use crate::geometry::Primitive;
use crate::scene::{Mesh, Scene};

/// What an Embree geometry id stands for.
#[derive(Clone, Debug)]
enum GeomMap {
    /// A geometry whose Embree primitive `i` came from raypack primitive `prims[i]`.
    Prims(Vec<u32>),
    /// An instance of raypack primitive `.0` (every hit inside it is that primitive).
    Instance(u32),
    /// An instance of a scene's mesh `mesh`, whose primitive `i` has id `first + i`.
    Placed {
        /// The mesh (index into the scene's meshes and [`EmbreeScene`]'s maps of them).
        mesh: u32,
        /// The id of the mesh's primitive 0 in this instance.
        first: u32,
    },
}

/// raypack primitives in an Embree scene. 112 bytes plus the maps (4 bytes per
/// Embree primitive), the user primitives and Embree's own data.
///
/// Fields drop in declaration order: the scenes are released before the user
/// primitives their callbacks point at, and before the device.
pub struct EmbreeScene {
    scene: RawScene,
    /// The primitives traced by raypack's kernels inside Embree: never read here,
    /// kept alive (and in place) for the callbacks, which point into it.
    _user: Option<Box<UserPrims>>,
    /// By Embree geometry id.
    geoms: Vec<GeomMap>,
    /// Each instanced mesh's geometries, by Embree geometry id in its scene
    /// (only [`GeomMap::Prims`]: a mesh goes to Embree instanced only when
    /// every primitive is a native shape).
    mesh_geoms: Vec<Vec<GeomMap>>,
    /// The meshes' scenes, which the instances hold references to as well.
    meshes: Vec<RawScene>,
    stats: TranslationStats,
    robust: bool,
    primitives: usize,
    device: Arc<Device>,
}

// SAFETY: a committed Embree scene is immutable and may be queried from any
// thread; the user primitives are only read by the callbacks.
unsafe impl Send for EmbreeScene {}
// SAFETY: as above.
unsafe impl Sync for EmbreeScene {}

impl EmbreeScene {
    /// Translate `prims` (see [`translate`](super::translate)) and build Embree's
    /// BVH with Embree's default (fast) scene flags: what the throughput
    /// comparisons use.
    pub fn new(device: Arc<Device>, prims: &[Primitive]) -> Result<Self, EmbreeError> {
        Self::build(device, prims, sys::RTCSceneFlags::NONE)
    }

    /// As [`EmbreeScene::new`], in Embree's robust mode (`RTC_SCENE_FLAG_ROBUST`):
    /// slower, but its triangle test is watertight, so no ray slips through an
    /// edge or vertex shared by two triangles. The reference for correctness checks.
    pub fn robust(device: Arc<Device>, prims: &[Primitive]) -> Result<Self, EmbreeError> {
        Self::build(device, prims, sys::RTCSceneFlags::ROBUST)
    }

    fn build(
        device: Arc<Device>,
        prims: &[Primitive],
        flags: sys::RTCSceneFlags,
    ) -> Result<Self, EmbreeError> {
        flush_denormals();
        let mut stats = TranslationStats::default();
        let scene = RawScene::new(&device)?;
        let (geoms, user) = fill(&scene, &device, prims, &mut stats)?;
        Self::commit(
            device,
            scene,
            geoms,
            user,
            (Vec::new(), Vec::new()),
            stats,
            flags,
            prims.len(),
        )
    }

    /// Whether every primitive of `mesh` is one of Embree's own shapes, so
    /// that the mesh can be an Embree scene instanced by the top one (Embree
    /// traces one instance level: a transformed primitive, itself an
    /// instance, or raypack's kernels as user geometry, which expect unit
    /// directions, cannot sit inside).
    pub fn instances_mesh(mesh: &Mesh) -> bool {
        mesh.primitives
            .iter()
            .all(|p| matches!(place(p), Placement::Native(_) | Placement::Empty))
    }

    /// `scene` with its instances as Embree instances
    /// (`RTC_GEOMETRY_TYPE_INSTANCE`) of one Embree scene per mesh, hit ids
    /// as [`Scene::locate`](crate::scene::Scene::locate) reads them. Every
    /// mesh must pass [`instances_mesh`](Self::instances_mesh).
    pub fn with_instances(device: Arc<Device>, scene: &Scene, robust: bool) -> Result<Self, EmbreeError> {
        flush_denormals();
        let flags = if robust {
            sys::RTCSceneFlags::ROBUST
        } else {
            sys::RTCSceneFlags::NONE
        };
        let mut stats = TranslationStats::default();
        // One committed Embree scene per mesh.
        let (mut meshes, mut mesh_geoms) = (Vec::new(), Vec::new());
        for mesh in scene.instances.meshes() {
            let child = RawScene::new(&device)?;
            let (geoms, user) = fill(&child, &device, &mesh.primitives, &mut stats)?;
            assert!(user.is_none(), "an instanced mesh of native shapes only");
            // SAFETY: a valid, uncommitted scene.
            unsafe { sys::rtcSetSceneFlags(child.raw(), flags) };
            child.commit(&device, "building an instanced mesh's BVH")?;
            meshes.push(child);
            mesh_geoms.push(geoms);
        }
        // The scene's own primitives, then one instance geometry per instance.
        let top = RawScene::new(&device)?;
        let (mut geoms, user) = fill(&top, &device, &scene.primitives, &mut stats)?;
        let own = scene.primitives.len() as u32;
        for instance in scene.instances.list() {
            let id = geoms.len() as u32;
            top.attach_instance(&device, &meshes[instance.mesh as usize], instance.to_world, id)?;
            geoms.push(GeomMap::Placed {
                mesh: instance.mesh,
                first: own + instance.first,
            });
        }
        let count = scene.id_count() as usize;
        Self::commit(
            device,
            top,
            geoms,
            user,
            (meshes, mesh_geoms),
            stats,
            flags,
            count,
        )
    }

    /// Set `flags` on the top scene, build its BVH and keep what tracing reads.
    #[allow(clippy::too_many_arguments)]
    fn commit(
        device: Arc<Device>,
        scene: RawScene,
        geoms: Vec<GeomMap>,
        user: Option<Box<UserPrims>>,
        (meshes, mesh_geoms): (Vec<RawScene>, Vec<Vec<GeomMap>>),
        stats: TranslationStats,
        flags: sys::RTCSceneFlags,
        primitives: usize,
    ) -> Result<Self, EmbreeError> {
        // SAFETY: a valid, uncommitted scene.
        unsafe { sys::rtcSetSceneFlags(scene.raw(), flags) };
        scene.commit(&device, "building the BVH")?;
        Ok(Self {
            scene,
            _user: user,
            geoms,
            mesh_geoms,
            meshes,
            stats,
            robust: flags == sys::RTCSceneFlags::ROBUST,
            primitives,
            device,
        })
    }

    /// The committed `RTCScene`, for calling Embree directly.
    #[inline]
    pub fn raw_scene(&self) -> sys::RTCScene {
        self.scene.raw()
    }

    /// The device the scene was built on.
    pub fn device(&self) -> &Arc<Device> {
        &self.device
    }

    /// How the primitives were translated.
    pub fn stats(&self) -> TranslationStats {
        self.stats
    }

    /// Whether the scene was built in robust mode ([`EmbreeScene::robust`]).
    pub fn is_robust(&self) -> bool {
        self.robust
    }

    /// Number of raypack primitives.
    pub fn primitive_count(&self) -> usize {
        self.primitives
    }

    /// Number of meshes traced as Embree instances ([`with_instances`](Self::with_instances)).
    pub fn instanced_meshes(&self) -> usize {
        self.meshes.len()
    }

    /// Number of top-level Embree geometries (meshes, sphere sets, instances, user geometry).
    pub fn geometry_count(&self) -> usize {
        self.geoms.len()
    }

    /// raypack's index of the primitive Embree hit.
    #[inline]
    pub(crate) fn prim_of(&self, geom: u32, prim: u32, inst: u32) -> u32 {
        let id = if inst != INVALID_ID { inst } else { geom };
        match &self.geoms[id as usize] {
            GeomMap::Prims(prims) => prims[prim as usize],
            GeomMap::Instance(p) => *p,
            GeomMap::Placed { mesh, first } => match &self.mesh_geoms[*mesh as usize][geom as usize] {
                GeomMap::Prims(prims) => first + prims[prim as usize],
                _ => unreachable!("a mesh's scene holds primitive geometries only"),
            },
        }
    }
}

/// Translate `prims` (see [`translate`](super::translate)) into geometries of
/// `scene` (ids from 0), with the map of each back to raypack's indices and
/// the user primitives, which must outlive the scene.
fn fill(
    scene: &RawScene,
    device: &Device,
    prims: &[Primitive],
    stats: &mut TranslationStats,
) -> Result<(Vec<GeomMap>, Option<Box<UserPrims>>), EmbreeError> {
    // The hit records' layout is checked before anything is traced.
    let inst_prim_id = device.writes_inst_prim_id()?;
    let (mut triangles, mut triangle_prims) = (Vec::new(), Vec::new());
    let (mut spheres, mut sphere_prims) = (Vec::new(), Vec::new());
    let mut instances = Vec::new();
    let mut user = Vec::new();
    for (i, prim) in prims.iter().enumerate() {
        let placement = place(prim);
        stats.add(prim, &placement);
        let i = i as u32;
        match placement {
            Placement::Native(NativeShape::Triangles(t)) => {
                triangle_prims.extend(std::iter::repeat_n(i, t.len()));
                triangles.extend(t);
            }
            Placement::Native(NativeShape::Sphere(c, r)) => {
                spheres.push((c, r));
                sphere_prims.push(i);
            }
            Placement::Instance(m, shape) => instances.push((i, m, shape)),
            Placement::User => user.push((i, prim.clone())),
            Placement::Empty => {}
        }
    }
    let mut geoms = Vec::new();
    let next = |geoms: &Vec<GeomMap>| geoms.len() as u32;
    if !triangles.is_empty() {
        scene.attach_triangles(device, &triangles, next(&geoms))?;
        geoms.push(GeomMap::Prims(triangle_prims));
    }
    if !spheres.is_empty() {
        scene.attach_spheres(device, &spheres, next(&geoms))?;
        geoms.push(GeomMap::Prims(sphere_prims));
    }
    for (prim, to_world, shape) in instances {
        let child = RawScene::new(device)?;
        match shape {
            NativeShape::Triangles(t) => child.attach_triangles(device, &t, 0)?,
            NativeShape::Sphere(c, r) => child.attach_spheres(device, &[(c, r)], 0)?,
        }
        child.commit(device, "building an instanced object's BVH")?;
        scene.attach_instance(device, &child, to_world, next(&geoms))?;
        // The instance holds its own reference to the child scene.
        geoms.push(GeomMap::Instance(prim));
    }
    let user = if user.is_empty() {
        None
    } else {
        let user = Box::new(UserPrims::new(user, inst_prim_id));
        // SAFETY: the box is returned to be stored beside the scene and dropped after it.
        let geom = unsafe { user.geometry(device.raw()) };
        scene.attach(device, geom, next(&geoms))?;
        geoms.push(GeomMap::Prims(user.indices()));
        Some(user)
    };
    Ok((geoms, user))
}
