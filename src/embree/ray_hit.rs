//! Ray-hit records handed to Embree, padded for the library actually loaded,
//! and the query arguments that Embree's inline initialisers would fill in.
//!
//! `embree4-sys` 0.0.12 bundles the Embree 4.2 headers, but Embree ≥ 4.3 (built
//! with instance arrays, the default) writes one more field, `instPrimID`, after
//! `instID` in every hit: 4 bytes past the 4.2 `RTCRayHit` (80 → 96 bytes) and
//! 32 bytes past `RTCRayHit8` (640 → 672). Handing Embree the 4.2 structs lets it
//! write over whatever follows them on the stack. The records here append that
//! field (and keep the alignment `rtcIntersect4/8/16` require: 16/32/64 bytes),
//! so they fit both layouts.
//!
//! `rtcInitIntersectArguments` and `rtcInitOccludedArguments` are inline C
//! functions that bindgen skips; [`intersect_arguments`] and
//! [`occluded_arguments`] fill in the same defaults.

use glam::Vec3;

use embree4_sys as sys;

use crate::packet::RayPacket;
use crate::ray::Ray;
use crate::simd::SimdFloat;

/// Geometry / instance id of "nothing" in Embree's records.
pub const INVALID_ID: u32 = sys::RTC_INVALID_GEOMETRY_ID;

/// The defaults of Embree's inline `rtcInitIntersectArguments`: incoherent
/// rays (packet queries mark coherent packets coherent, see `EmbreeScene`),
/// every feature enabled, no context (Embree makes its own), no filter,
/// geometry callbacks taken from the geometry.
pub fn intersect_arguments() -> sys::RTCIntersectArguments {
    sys::RTCIntersectArguments {
        flags: sys::RTCRayQueryFlags::INCOHERENT,
        feature_mask: sys::RTCFeatureFlags::RTC_FEATURE_FLAG_ALL,
        context: std::ptr::null_mut(),
        filter: None,
        intersect: None,
    }
}

/// The defaults of Embree's inline `rtcInitOccludedArguments`.
pub fn occluded_arguments() -> sys::RTCOccludedArguments {
    sys::RTCOccludedArguments {
        flags: sys::RTCRayQueryFlags::INCOHERENT,
        feature_mask: sys::RTCFeatureFlags::RTC_FEATURE_FLAG_ALL,
        context: std::ptr::null_mut(),
        filter: None,
        occluded: None,
    }
}

/// Whether Embree may trace `ray`: finite origin and direction, a non-zero
/// direction and an ordered, non-NaN interval. raypack's kernels miss every
/// other ray; Embree's behaviour on them is undefined, so they are not sent.
#[inline]
pub fn traceable(ray: &Ray) -> bool {
    ray.origin.is_finite() && ray.dir.is_finite() && ray.dir != Vec3::ZERO && ray.t_min <= ray.t_max
}

/// One ray and its hit (`RTCRayHit`) plus the `instPrimID` of Embree ≥ 4.3.
/// 96 bytes, 16-byte aligned.
#[repr(C, align(16))]
pub struct RayHit1 {
    /// The record in the 4.2 layout.
    pub inner: sys::RTCRayHit,
    /// Written by Embree ≥ 4.3 only.
    pub inst_prim_id: u32,
}

impl RayHit1 {
    /// A record for `ray`, with nothing hit.
    #[inline]
    pub fn new(ray: &Ray) -> Self {
        Self {
            inner: sys::RTCRayHit {
                ray: sys::RTCRay {
                    org_x: ray.origin.x,
                    org_y: ray.origin.y,
                    org_z: ray.origin.z,
                    tnear: ray.t_min,
                    dir_x: ray.dir.x,
                    dir_y: ray.dir.y,
                    dir_z: ray.dir.z,
                    time: 0.0,
                    tfar: ray.t_max,
                    mask: u32::MAX,
                    id: 0,
                    flags: 0,
                },
                hit: sys::RTCHit {
                    Ng_x: 0.0,
                    Ng_y: 0.0,
                    Ng_z: 0.0,
                    u: 0.0,
                    v: 0.0,
                    primID: INVALID_ID,
                    geomID: INVALID_ID,
                    instID: [INVALID_ID],
                },
            },
            inst_prim_id: INVALID_ID,
        }
    }
}

/// A packet of Embree ray-hit records with its lane-validity mask.
pub trait RayHitPacket: Sized {
    /// Lanes.
    const LANES: usize;

    /// Records for the rays of `rays` (which has `LANES` lanes), nothing hit.
    /// A lane is valid when it is active and [`traceable`].
    fn new<F: SimdFloat>(rays: &RayPacket<F>) -> Self;

    /// `rtcIntersect{LANES}` on the valid lanes.
    ///
    /// # Safety
    /// `scene` must be a committed scene.
    unsafe fn intersect(&mut self, scene: sys::RTCScene, args: &mut sys::RTCIntersectArguments);

    /// `rtcOccluded{LANES}` on the valid lanes; occluded lanes get `tfar = −∞`.
    ///
    /// # Safety
    /// `scene` must be a committed scene.
    unsafe fn occluded(&mut self, scene: sys::RTCScene, args: &mut sys::RTCOccludedArguments);

    /// The lane-validity mask, one bit per lane.
    fn valid_bits(&self) -> u32;

    /// `tfar` per lane (the hit distance after `intersect`).
    fn tfar(&self) -> &[f32];
    /// `geomID` per lane.
    fn geom_id(&self) -> &[u32];
    /// `primID` per lane.
    fn prim_id(&self) -> &[u32];
    /// `instID[0]` per lane.
    fn inst_id(&self) -> &[u32];
    /// Hit parameter `u` per lane.
    fn u(&self) -> &[f32];
    /// Hit parameter `v` per lane.
    fn v(&self) -> &[f32];
}

/// Define a padded `RTCRayHit{N}` record and its [`RayHitPacket`] impl.
macro_rules! ray_hit_packet {
    ($name:ident, $sys_rayhit:ident, $sys_ray:ident, $sys_hit:ident, $n:literal, $align:literal,
     $intersect:ident, $occluded:ident, $bytes:literal) => {
        #[doc = concat!("`", stringify!($sys_rayhit), "` plus the `instPrimID` lanes of Embree ≥ 4.3, and the lane mask. ")]
        #[doc = concat!($bytes, " bytes, ", stringify!($align), "-byte aligned.")]
        #[repr(C, align($align))]
        pub struct $name {
            /// The records in the 4.2 layout.
            pub inner: sys::$sys_rayhit,
            /// Written by Embree ≥ 4.3 only.
            pub inst_prim_id: [u32; $n],
            /// Which lanes Embree traces (-1) or skips (0); it follows the padded
            /// record at an offset aligned as `rtcIntersect{N}` needs.
            pub valid: [i32; $n],
        }

        impl RayHitPacket for $name {
            const LANES: usize = $n;

            #[inline]
            fn new<F: SimdFloat>(rays: &RayPacket<F>) -> Self {
                debug_assert_eq!(F::LANES, $n);
                let copy = |x: F| {
                    let mut lanes = [0.0f32; $n];
                    lanes.copy_from_slice(x.to_array().as_ref());
                    lanes
                };
                let mut valid = [0i32; $n];
                for (i, v) in valid.iter_mut().enumerate() {
                    if rays.is_active(i) && traceable(&rays.ray(i)) {
                        *v = -1;
                    }
                }
                Self {
                    inner: sys::$sys_rayhit {
                        ray: sys::$sys_ray {
                            org_x: copy(rays.origin.x),
                            org_y: copy(rays.origin.y),
                            org_z: copy(rays.origin.z),
                            tnear: copy(rays.t_min),
                            dir_x: copy(rays.dir.x),
                            dir_y: copy(rays.dir.y),
                            dir_z: copy(rays.dir.z),
                            time: [0.0; $n],
                            tfar: copy(rays.t_max),
                            mask: [u32::MAX; $n],
                            id: [0; $n],
                            flags: [0; $n],
                        },
                        hit: sys::$sys_hit {
                            Ng_x: [0.0; $n],
                            Ng_y: [0.0; $n],
                            Ng_z: [0.0; $n],
                            u: [0.0; $n],
                            v: [0.0; $n],
                            primID: [INVALID_ID; $n],
                            geomID: [INVALID_ID; $n],
                            instID: [[INVALID_ID; $n]],
                        },
                    },
                    inst_prim_id: [INVALID_ID; $n],
                    valid,
                }
            }

            #[inline]
            unsafe fn intersect(&mut self, scene: sys::RTCScene, args: &mut sys::RTCIntersectArguments) {
                // SAFETY: the record is aligned and padded for Embree ≥ 4.3's layout;
                // the caller guarantees a committed scene.
                unsafe { sys::$intersect(self.valid.as_ptr(), scene, &mut self.inner, args) }
            }

            #[inline]
            unsafe fn occluded(&mut self, scene: sys::RTCScene, args: &mut sys::RTCOccludedArguments) {
                // SAFETY: occlusion writes only the ray part (tfar); aligned record,
                // committed scene.
                unsafe { sys::$occluded(self.valid.as_ptr(), scene, &mut self.inner.ray, args) }
            }

            #[inline]
            fn valid_bits(&self) -> u32 {
                self.valid
                    .iter()
                    .enumerate()
                    .fold(0, |bits, (i, &v)| bits | (((v != 0) as u32) << i))
            }

            #[inline]
            fn tfar(&self) -> &[f32] {
                &self.inner.ray.tfar
            }
            #[inline]
            fn geom_id(&self) -> &[u32] {
                &self.inner.hit.geomID
            }
            #[inline]
            fn prim_id(&self) -> &[u32] {
                &self.inner.hit.primID
            }
            #[inline]
            fn inst_id(&self) -> &[u32] {
                &self.inner.hit.instID[0]
            }
            #[inline]
            fn u(&self) -> &[f32] {
                &self.inner.hit.u
            }
            #[inline]
            fn v(&self) -> &[f32] {
                &self.inner.hit.v
            }
        }
    };
}

ray_hit_packet!(
    RayHit4,
    RTCRayHit4,
    RTCRay4,
    RTCHit4,
    4,
    16,
    rtcIntersect4,
    rtcOccluded4,
    352
);
ray_hit_packet!(
    RayHit8,
    RTCRayHit8,
    RTCRay8,
    RTCHit8,
    8,
    32,
    rtcIntersect8,
    rtcOccluded8,
    704
);
ray_hit_packet!(
    RayHit16,
    RTCRayHit16,
    RTCRay16,
    RTCHit16,
    16,
    64,
    rtcIntersect16,
    rtcOccluded16,
    1408
);
