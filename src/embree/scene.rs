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

/// What an Embree geometry id stands for.
#[derive(Clone, Debug)]
enum GeomMap {
    /// A geometry whose Embree primitive `i` came from raypack primitive `prims[i]`.
    Prims(Vec<u32>),
    /// An instance of raypack primitive `.0` (every hit inside it is that primitive).
    Instance(u32),
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
        // The hit records' layout is checked before anything is traced.
        let inst_prim_id = device.writes_inst_prim_id()?;
        let mut stats = TranslationStats::default();
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

        let scene = RawScene::new(&device)?;
        let mut geoms = Vec::new();
        let next = |geoms: &Vec<GeomMap>| geoms.len() as u32;
        if !triangles.is_empty() {
            scene.attach_triangles(&device, &triangles, next(&geoms))?;
            geoms.push(GeomMap::Prims(triangle_prims));
        }
        if !spheres.is_empty() {
            scene.attach_spheres(&device, &spheres, next(&geoms))?;
            geoms.push(GeomMap::Prims(sphere_prims));
        }
        for (prim, to_world, shape) in instances {
            let child = RawScene::new(&device)?;
            match shape {
                NativeShape::Triangles(t) => child.attach_triangles(&device, &t, 0)?,
                NativeShape::Sphere(c, r) => child.attach_spheres(&device, &[(c, r)], 0)?,
            }
            child.commit(&device, "building an instanced object's BVH")?;
            scene.attach_instance(&device, &child, to_world, next(&geoms))?;
            // The instance holds its own reference to the child scene.
            geoms.push(GeomMap::Instance(prim));
        }
        let user = if user.is_empty() {
            None
        } else {
            let user = Box::new(UserPrims::new(user, inst_prim_id));
            // SAFETY: the box is stored in the returned scene and dropped after it.
            let geom = unsafe { user.geometry(device.raw()) };
            scene.attach(&device, geom, next(&geoms))?;
            geoms.push(GeomMap::Prims(user.indices()));
            Some(user)
        };
        // SAFETY: a valid, uncommitted scene.
        unsafe { sys::rtcSetSceneFlags(scene.raw(), flags) };
        scene.commit(&device, "building the BVH")?;
        Ok(Self {
            scene,
            _user: user,
            geoms,
            stats,
            robust: flags == sys::RTCSceneFlags::ROBUST,
            primitives: prims.len(),
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
        }
    }
}
