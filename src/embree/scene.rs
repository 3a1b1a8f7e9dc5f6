//! [`EmbreeScene`]: raypack primitives translated into an Embree scene, queried
//! through raypack's [`Accel`] trait so every command can use Embree like any
//! other acceleration structure.
//!
//! | [`Accel`] | Embree |
//! | --- | --- |
//! | `intersect` | `rtcIntersect1` |
//! | `intersect_packet` (4 / 8 / 16 lanes) | `rtcIntersect4/8/16`, valid lanes = the packet's active lanes |
//! | `occluded` | `rtcOccluded1` |
//! | `occluded_packet` | `rtcOccluded4/8/16` |
//!
//! Hit records carry raypack's primitive index (file order); `u, v` are
//! Embree's (barycentric for triangles, the same convention as raypack's). Rays
//! with a non-finite origin or direction are not sent to Embree and miss, as
//! they do in raypack. Queries set FTZ/DAZ on the calling thread
//! ([`flush_denormals`]).

use std::sync::Arc;

use glam::{Mat4, Vec3};

use embree4_sys as sys;

use crate::accel::Accel;
use crate::accel::stats::Counter;
use crate::embree::EmbreeError;
use crate::embree::denormals::flush_denormals;
use crate::embree::device::Device;
use crate::embree::ray_hit::{
    INVALID_ID, RayHit1, RayHit4, RayHit8, RayHit16, RayHitPacket, intersect_arguments, occluded_arguments,
    traceable,
};
use crate::embree::translate::{NativeShape, Placement, TranslationStats, place};
use crate::embree::user_geometry::UserPrims;
use crate::geometry::Primitive;
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, NO_HIT, Ray};
use crate::simd::{SimdFloat, SimdU32};

impl Device {
    /// Whether the library writes `instPrimID` after `instID` in every hit
    /// record (Embree ≥ 4.3 built with instance arrays), probed once per device with one ray at a one-triangle
    /// scene; fails if it writes past the padded record (a layout raypack does
    /// not know). Every [`EmbreeScene`] asks before it is traced. (The probe
    /// needs a scene, so it lives here rather than in `device.rs`, below scenes.)
    pub fn writes_inst_prim_id(&self) -> Result<bool, EmbreeError> {
        if let Some(&known) = self.inst_prim_id.get() {
            return Ok(known);
        }
        let probed = probe_inst_prim_id(self)?;
        Ok(*self.inst_prim_id.get_or_init(|| probed))
    }
}

/// A value Embree never writes, to see which words it does write.
const SENTINEL: u32 = 0x5EED_F00D;

/// A [`RayHit1`] followed by guard words that Embree must leave alone.
#[repr(C)]
struct Guarded {
    record: RayHit1,
    guard: [u32; 8],
}

/// Trace one ray at a one-triangle scene and report whether the library writes
/// `instPrimID` into the padding, failing if it writes past the padded record
/// (a layout this module does not know, e.g. more than one instance level).
fn probe_inst_prim_id(device: &Device) -> Result<bool, EmbreeError> {
    let vertices = [
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ];
    let scene = RawScene::new(device)?;
    scene.attach_triangles(device, &[vertices], 0)?;
    scene.commit(device, "committing the layout probe scene")?;
    let ray = Ray::unbounded(Vec3::new(0.0, 0.0, 1.0), Vec3::NEG_Z);
    let mut probe = Guarded {
        record: RayHit1::new(&ray),
        guard: [SENTINEL; 8],
    };
    probe.record.inst_prim_id = SENTINEL;
    let mut args = intersect_arguments();
    // SAFETY: a committed scene and a padded, aligned record with guard words after it.
    unsafe { sys::rtcIntersect1(scene.raw(), &mut probe.record.inner, &mut args) };
    device.check("tracing the layout probe ray")?;
    if probe.guard != [SENTINEL; 8] {
        return Err(EmbreeError::Layout(
            "Embree wrote past the padded RTCRayHit (more than one instance level?)".into(),
        ));
    }
    if probe.record.inner.hit.geomID != 0 || (probe.record.inner.ray.tfar - 1.0).abs() > 1e-5 {
        return Err(EmbreeError::Layout(format!(
            "the probe ray should hit geometry 0 at t = 1, got geometry {} at t = {}",
            probe.record.inner.hit.geomID, probe.record.inner.ray.tfar
        )));
    }
    match probe.record.inst_prim_id {
        SENTINEL => Ok(false),
        INVALID_ID => Ok(true),
        other => Err(EmbreeError::Layout(format!(
            "unexpected value {other:#x} after instID in the hit record"
        ))),
    }
}

/// An owned `RTCScene` handle, released on drop.
pub(crate) struct RawScene(sys::RTCScene);

impl RawScene {
    /// A new, empty scene.
    pub(crate) fn new(device: &Device) -> Result<Self, EmbreeError> {
        // SAFETY: a valid device.
        let raw = unsafe { sys::rtcNewScene(device.raw()) };
        device.check("creating a scene")?;
        Ok(Self(raw))
    }

    /// The raw handle.
    pub(crate) fn raw(&self) -> sys::RTCScene {
        self.0
    }

    /// Commit `geom`, attach it under the next id `id`, and drop our reference.
    fn attach(&self, device: &Device, geom: sys::RTCGeometry, id: u32) -> Result<(), EmbreeError> {
        // SAFETY: a geometry made on this scene's device; the scene keeps its own reference.
        unsafe {
            sys::rtcCommitGeometry(geom);
            sys::rtcAttachGeometryByID(self.0, geom, id);
            sys::rtcReleaseGeometry(geom);
        }
        device.check("attaching a geometry")
    }

    /// A new Embree-owned buffer of `count` items of `stride` bytes, as a slice of `T`.
    ///
    /// # Safety
    /// `geom` is a valid geometry, `T` has `stride` bytes, and the slice is not
    /// used after the geometry is released.
    unsafe fn buffer<'g, T>(
        device: &Device,
        geom: sys::RTCGeometry,
        kind: sys::RTCBufferType,
        format: sys::RTCFormat,
        count: usize,
    ) -> Result<&'g mut [T], EmbreeError> {
        let stride = std::mem::size_of::<T>();
        // SAFETY: valid geometry; Embree returns `count·stride` bytes, aligned for
        // its own 16-byte loads, or null on failure.
        let ptr = unsafe { sys::rtcSetNewGeometryBuffer(geom, kind, 0, format, stride, count) };
        device.check("allocating a geometry buffer")?;
        if ptr.is_null() {
            return Err(EmbreeError::Api {
                step: "allocating a geometry buffer",
                message: "null buffer".into(),
            });
        }
        // SAFETY: see above; 4-byte aligned at least, `count` items of `T`.
        Ok(unsafe { std::slice::from_raw_parts_mut(ptr as *mut T, count) })
    }

    /// Attach a triangle mesh under id `id`.
    pub(crate) fn attach_triangles(
        &self,
        device: &Device,
        triangles: &[[Vec3; 3]],
        id: u32,
    ) -> Result<(), EmbreeError> {
        // SAFETY: valid device; buffers filled before the geometry is committed.
        unsafe {
            let geom = sys::rtcNewGeometry(device.raw(), sys::RTCGeometryType::TRIANGLE);
            let vertices: &mut [[f32; 3]] = Self::buffer(
                device,
                geom,
                sys::RTCBufferType::VERTEX,
                sys::RTCFormat::FLOAT3,
                3 * triangles.len(),
            )?;
            for (slot, v) in vertices.iter_mut().zip(triangles.iter().flatten()) {
                *slot = v.to_array();
            }
            let indices: &mut [[u32; 3]] = Self::buffer(
                device,
                geom,
                sys::RTCBufferType::INDEX,
                sys::RTCFormat::UINT3,
                triangles.len(),
            )?;
            for (i, slot) in indices.iter_mut().enumerate() {
                let first = 3 * i as u32;
                *slot = [first, first + 1, first + 2];
            }
            self.attach(device, geom, id)
        }
    }

    /// Attach spheres (`SPHERE_POINT`: centre and radius per point) under id `id`.
    pub(crate) fn attach_spheres(
        &self,
        device: &Device,
        spheres: &[(Vec3, f32)],
        id: u32,
    ) -> Result<(), EmbreeError> {
        // SAFETY: as for `attach_triangles`.
        unsafe {
            let geom = sys::rtcNewGeometry(device.raw(), sys::RTCGeometryType::SPHERE_POINT);
            let points: &mut [[f32; 4]] = Self::buffer(
                device,
                geom,
                sys::RTCBufferType::VERTEX,
                sys::RTCFormat::FLOAT4,
                spheres.len(),
            )?;
            for (slot, (c, r)) in points.iter_mut().zip(spheres) {
                *slot = [c.x, c.y, c.z, *r];
            }
            self.attach(device, geom, id)
        }
    }

    /// Attach an instance of `child` placed by `to_world` under id `id`.
    fn attach_instance(
        &self,
        device: &Device,
        child: &RawScene,
        to_world: Mat4,
        id: u32,
    ) -> Result<(), EmbreeError> {
        let columns = to_world.to_cols_array();
        // SAFETY: valid device and committed child scene; Embree copies the matrix.
        unsafe {
            let geom = sys::rtcNewGeometry(device.raw(), sys::RTCGeometryType::INSTANCE);
            sys::rtcSetGeometryInstancedScene(geom, child.0);
            sys::rtcSetGeometryTransform(
                geom,
                0,
                sys::RTCFormat::FLOAT4X4_COLUMN_MAJOR,
                columns.as_ptr() as *const std::ffi::c_void,
            );
            self.attach(device, geom, id)
        }
    }

    /// Build the scene's BVH.
    pub(crate) fn commit(&self, device: &Device, step: &'static str) -> Result<(), EmbreeError> {
        // SAFETY: a valid scene whose geometries are committed.
        unsafe { sys::rtcCommitScene(self.0) };
        device.check(step)
    }
}

impl Drop for RawScene {
    fn drop(&mut self) {
        // SAFETY: made by rtcNewScene, released once.
        unsafe { sys::rtcReleaseScene(self.0) };
    }
}

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
    fn prim_of(&self, geom: u32, prim: u32, inst: u32) -> u32 {
        let id = if inst != INVALID_ID { inst } else { geom };
        match &self.geoms[id as usize] {
            GeomMap::Prims(prims) => prims[prim as usize],
            GeomMap::Instance(p) => *p,
        }
    }

    /// Packet query through the `P`-lane record type (`P::LANES == F::LANES`).
    #[inline]
    fn packet<F: SimdFloat, P: RayHitPacket>(&self, rays: &RayPacket<F>) -> HitPacket<F> {
        let mut record = P::new(rays);
        let mut hits = HitPacket::none(rays);
        if record.valid_bits() == 0 {
            return hits;
        }
        flush_denormals();
        let mut args = intersect_arguments();
        args.flags = packet_flags(rays);
        // SAFETY: a committed scene.
        unsafe { record.intersect(self.scene.raw(), &mut args) };
        let mut prim = <F::U32 as SimdU32>::Array::default();
        let (geom, prim_id, inst) = (record.geom_id(), record.prim_id(), record.inst_id());
        for (i, p) in prim.as_mut().iter_mut().enumerate() {
            *p = if geom[i] == INVALID_ID {
                NO_HIT
            } else {
                self.prim_of(geom[i], prim_id[i], inst[i])
            };
        }
        let lanes = |x: &[f32]| {
            let mut a = F::Array::default();
            a.as_mut().copy_from_slice(x);
            F::from_array(a)
        };
        hits.t = lanes(record.tfar());
        hits.prim = F::U32::from_array(prim);
        hits.u = lanes(record.u());
        hits.v = lanes(record.v());
        hits
    }

    /// Packet occlusion through the `P`-lane record type.
    #[inline]
    fn packet_occluded<F: SimdFloat, P: RayHitPacket>(&self, rays: &RayPacket<F>) -> F {
        let mut record = P::new(rays);
        if record.valid_bits() == 0 {
            return F::splat(0.0);
        }
        flush_denormals();
        let mut args = occluded_arguments();
        args.flags = packet_flags(rays);
        // SAFETY: a committed scene.
        unsafe { record.occluded(self.scene.raw(), &mut args) };
        let bits = record
            .tfar()
            .iter()
            .enumerate()
            .fold(0, |bits, (i, &t)| bits | (((t == f32::NEG_INFINITY) as u32) << i));
        F::mask_from_bits(bits & record.valid_bits())
    }
}

/// The query flags for a packet: `RTC_RAY_QUERY_FLAG_COHERENT` where every
/// lane points the way of the others ([`RayPacket::is_coherent`], the test raypack's own
/// packet traversal makes), as Embree's documentation asks of coherent rays
/// (primary rays, shadow rays to one light), so that Embree uses its packet
/// traversal for them; incoherent otherwise. Embree's coherent packets run
/// faster with the flag and its incoherent ones slower (figures:
/// `docs/measurements.md`, "Constants").
#[inline]
fn packet_flags<F: SimdFloat>(rays: &RayPacket<F>) -> sys::RTCRayQueryFlags {
    if rays.is_coherent() {
        sys::RTCRayQueryFlags::COHERENT
    } else {
        sys::RTCRayQueryFlags::INCOHERENT
    }
}

// Embree's traversal is a black box: the counters see nothing.
impl Accel for EmbreeScene {
    const COUNTS_WORK: bool = false;

    fn intersect_counted<S: Counter>(&self, ray: &Ray, _: &mut S) -> Hit {
        if !traceable(ray) {
            return Hit::none(ray);
        }
        flush_denormals();
        let mut record = RayHit1::new(ray);
        let mut args = intersect_arguments();
        // SAFETY: a committed scene and a record padded for Embree ≥ 4.3.
        unsafe { sys::rtcIntersect1(self.scene.raw(), &mut record.inner, &mut args) };
        let h = &record.inner.hit;
        if h.geomID == INVALID_ID {
            return Hit::none(ray);
        }
        Hit {
            t: record.inner.ray.tfar,
            prim: self.prim_of(h.geomID, h.primID, h.instID[0]),
            u: h.u,
            v: h.v,
            ng: Vec3::ZERO,
        }
    }

    fn intersect_packet_counted<F: SimdFloat, S: Counter>(
        &self,
        rays: &RayPacket<F>,
        _: &mut S,
    ) -> HitPacket<F> {
        match F::LANES {
            4 => self.packet::<F, RayHit4>(rays),
            8 => self.packet::<F, RayHit8>(rays),
            16 => self.packet::<F, RayHit16>(rays),
            n => unreachable!("SimdFloat has 4, 8 or 16 lanes, not {n}"),
        }
    }

    fn occluded_counted<S: Counter>(&self, ray: &Ray, _: &mut S) -> bool {
        if !traceable(ray) {
            return false;
        }
        flush_denormals();
        let mut record = RayHit1::new(ray);
        let mut args = occluded_arguments();
        // SAFETY: a committed scene; occlusion writes only tfar.
        unsafe { sys::rtcOccluded1(self.scene.raw(), &mut record.inner.ray, &mut args) };
        record.inner.ray.tfar == f32::NEG_INFINITY
    }

    fn occluded_packet_counted<F: SimdFloat, S: Counter>(&self, rays: &RayPacket<F>, _: &mut S) -> F {
        match F::LANES {
            4 => self.packet_occluded::<F, RayHit4>(rays),
            8 => self.packet_occluded::<F, RayHit8>(rays),
            16 => self.packet_occluded::<F, RayHit16>(rays),
            n => unreachable!("SimdFloat has 4, 8 or 16 lanes, not {n}"),
        }
    }
}
