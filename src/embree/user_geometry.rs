//! Embree user geometry whose callbacks run raypack's own scalar kernels: the
//! way planes, self-crossing polygons and shapes Embree has no type for (cones)
//! take part in Embree's traversal.
//!
//! Callbacks receive `N` rays in Embree's `RTCRayHitN` layout: twelve arrays of
//! `N` ray values (`org_x … flags`) followed by the hit arrays (`Ng_x, Ng_y,
//! Ng_z, u, v, primID, geomID, instID[0]`, and `instPrimID[0]` on Embree ≥ 4.3).
//! User geometry is only ever placed in the top-level scene, never instanced, so
//! the instance ids written on a hit are always "none".

use std::ffi::c_void;

use embree4_sys as sys;

use crate::geometry::{Intersect, Primitive};
use crate::ray::{Hit, Ray};

use super::ray_hit::INVALID_ID;

/// Half the extent of the box given to unbounded primitives (planes). Large
/// enough for any scene, small enough that Embree's surface-area heuristic
/// stays finite in f32 (6·(2·10¹⁸)² ≈ 2.4·10³⁷ < 3.4·10³⁸).
const UNBOUNDED: f32 = 1e18;

/// Offsets (in 4-byte words, times N) of the fields of `RTCRayHitN`.
mod field {
    pub const ORG: usize = 0;
    pub const TNEAR: usize = 3;
    pub const DIR: usize = 4;
    pub const TFAR: usize = 8;
    pub const NG: usize = 12;
    pub const U: usize = 15;
    pub const V: usize = 16;
    pub const PRIM_ID: usize = 17;
    pub const GEOM_ID: usize = 18;
    pub const INST_ID: usize = 19;
    pub const INST_PRIM_ID: usize = 20;
}

/// The primitives of one user geometry: raypack index and shape, by Embree primID.
/// 32 bytes plus the primitives.
#[derive(Debug)]
pub struct UserPrims {
    prims: Vec<(u32, Primitive)>,
    /// Whether hit records have an `instPrimID` field to reset.
    inst_prim_id: bool,
}

impl UserPrims {
    /// User primitives `(raypack index, primitive)`; `inst_prim_id` from
    /// [`Device::writes_inst_prim_id`](super::Device::writes_inst_prim_id).
    pub fn new(prims: Vec<(u32, Primitive)>, inst_prim_id: bool) -> Self {
        Self { prims, inst_prim_id }
    }

    /// raypack indices, by Embree primID.
    pub fn indices(&self) -> Vec<u32> {
        self.prims.iter().map(|(i, _)| *i).collect()
    }

    /// The user geometry, to attach to a scene. Embree keeps a pointer to
    /// `self`, which must stay in place until the scene is released.
    ///
    /// # Safety
    /// `device` must be valid and `self` must outlive every scene the geometry is attached to.
    pub unsafe fn geometry(&self, device: sys::RTCDevice) -> sys::RTCGeometry {
        let user = self as *const Self as *mut c_void;
        // SAFETY: valid device; callbacks get `user`, which the caller keeps alive.
        unsafe {
            let geom = sys::rtcNewGeometry(device, sys::RTCGeometryType::USER);
            sys::rtcSetGeometryUserPrimitiveCount(geom, self.prims.len() as u32);
            sys::rtcSetGeometryUserData(geom, user);
            sys::rtcSetGeometryBoundsFunction(geom, Some(bounds), user);
            sys::rtcSetGeometryIntersectFunction(geom, Some(intersect));
            sys::rtcSetGeometryOccludedFunction(geom, Some(occluded));
            geom
        }
    }
}

/// Read word `field·N + lane` of an `RTCRayHitN` as f32.
///
/// # Safety
/// `base` points at a record of `n` lanes that has the field.
#[inline(always)]
unsafe fn get(base: *const f32, field: usize, n: usize, lane: usize) -> f32 {
    // SAFETY: in bounds by the caller's guarantee.
    unsafe { *base.add(field * n + lane) }
}

/// Write word `field·N + lane` of an `RTCRayHitN` (f32 or u32 bits).
///
/// # Safety
/// As [`get`], and the record is writable.
#[inline(always)]
unsafe fn set(base: *mut f32, field: usize, n: usize, lane: usize, bits: u32) {
    // SAFETY: in bounds by the caller's guarantee.
    unsafe { *base.add(field * n + lane) = f32::from_bits(bits) }
}

/// Lane `i` of an `RTCRayN` as a raypack ray.
///
/// # Safety
/// `base` points at a ray record of `n` lanes.
#[inline(always)]
unsafe fn ray(base: *const f32, n: usize, i: usize) -> Ray {
    // SAFETY: the caller's guarantee.
    unsafe {
        let v =
            |k: usize| glam::Vec3::new(get(base, k, n, i), get(base, k + 1, n, i), get(base, k + 2, n, i));
        Ray::new(
            v(field::ORG),
            v(field::DIR),
            get(base, field::TNEAR, n, i),
            get(base, field::TFAR, n, i),
        )
    }
}

/// Bounds callback: the primitive's box, or a huge one for unbounded shapes.
unsafe extern "C" fn bounds(args: *const sys::RTCBoundsFunctionArguments) {
    // SAFETY: Embree passes valid arguments and the `UserPrims` registered above.
    unsafe {
        let args = &*args;
        let user = &*(args.geometryUserPtr as *const UserPrims);
        let (lo, hi) = match user.prims[args.primID as usize].1.bounds() {
            Some(b) => (b.min, b.max),
            None => (glam::Vec3::splat(-UNBOUNDED), glam::Vec3::splat(UNBOUNDED)),
        };
        *args.bounds_o = sys::RTCBounds {
            lower_x: lo.x,
            lower_y: lo.y,
            lower_z: lo.z,
            align0: 0.0,
            upper_x: hi.x,
            upper_y: hi.y,
            upper_z: hi.z,
            align1: 0.0,
        };
    }
}

/// What [`for_valid_lanes`] reads of an N-lane callback's arguments: the
/// registered [`UserPrims`], the primitive, the `valid` flags, N, the ray record.
type LaneFields = (*mut c_void, u32, *const i32, u32, *mut f32);

/// The N-lane callbacks' argument records.
trait LaneArgs {
    fn fields(&self) -> LaneFields;
}

impl LaneArgs for sys::RTCIntersectFunctionNArguments {
    fn fields(&self) -> LaneFields {
        (
            self.geometryUserPtr,
            self.primID,
            self.valid,
            self.N,
            self.rayhit as *mut f32,
        )
    }
}

impl LaneArgs for sys::RTCOccludedFunctionNArguments {
    fn fields(&self) -> LaneFields {
        (
            self.geometryUserPtr,
            self.primID,
            self.valid,
            self.N,
            self.ray as *mut f32,
        )
    }
}

/// Call `f` with the registered primitives, the callback's primitive, and
/// each valid lane of the N-lane ray record with its ray: the lanes Embree asks
/// a callback about.
///
/// # Safety
/// `args` are the arguments Embree passed to a callback of the [`UserPrims`]
/// registered here: `valid` holds N flags and the record has N lanes.
#[inline(always)]
unsafe fn for_valid_lanes(
    args: &impl LaneArgs,
    mut f: impl FnMut(&UserPrims, &(u32, Primitive), usize, Ray),
) {
    let (user, prim_id, valid, n, base) = args.fields();
    // SAFETY: the caller's guarantee.
    unsafe {
        let user = &*(user as *const UserPrims);
        let entry = &user.prims[prim_id as usize];
        let n = n as usize;
        for i in (0..n).filter(|&i| *valid.add(i) != 0) {
            f(user, entry, i, ray(base, n, i));
        }
    }
}

/// Intersect callback: raypack's scalar kernel on every valid lane; a closer
/// hit overwrites `tfar` and the hit fields.
unsafe extern "C" fn intersect(args: *const sys::RTCIntersectFunctionNArguments) {
    // SAFETY: Embree passes valid arguments: `valid` and `rayhit` of N lanes, and
    // the `UserPrims` registered above.
    unsafe {
        let args = &*args;
        let (n, base) = (args.N as usize, args.rayhit as *mut f32);
        for_valid_lanes(args, |user, (index, prim), i, ray| {
            let mut hit = Hit::none(&ray);
            if !prim.intersect(&ray, *index, &mut hit) {
                return;
            }
            let ng = prim.geometric_normal(&ray, &hit);
            set(base, field::TFAR, n, i, hit.t.to_bits());
            for (k, c) in [ng.x, ng.y, ng.z].into_iter().enumerate() {
                set(base, field::NG + k, n, i, c.to_bits());
            }
            set(base, field::U, n, i, hit.u.to_bits());
            set(base, field::V, n, i, hit.v.to_bits());
            set(base, field::PRIM_ID, n, i, args.primID);
            set(base, field::GEOM_ID, n, i, args.geomID);
            set(base, field::INST_ID, n, i, INVALID_ID);
            if user.inst_prim_id {
                set(base, field::INST_PRIM_ID, n, i, INVALID_ID);
            }
        });
    }
}

/// Occluded callback: raypack's scalar kernel; an occluded lane gets `tfar = −∞`.
unsafe extern "C" fn occluded(args: *const sys::RTCOccludedFunctionNArguments) {
    // SAFETY: as for `intersect`, with a ray record of N lanes.
    unsafe {
        let args = &*args;
        let (n, base) = (args.N as usize, args.ray as *mut f32);
        for_valid_lanes(args, |_, (index, prim), i, ray| {
            if prim.intersect(&ray, *index, &mut Hit::none(&ray)) {
                set(base, field::TFAR, n, i, f32::NEG_INFINITY.to_bits());
            }
        });
    }
}
