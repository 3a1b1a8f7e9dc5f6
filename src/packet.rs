//! Ray packets: `LANES` rays in structure-of-arrays form, and their hit records.
//!
//! The width is the SIMD type parameter `F` ([`SimdFloat`]); [`RayPacket8`] and
//! [`HitPacket8`] are the 8-wide packets the engine traces. A lane whose bit in
//! `active` is clear is carried along but never changes its hit record.

use glam::Vec3;

use crate::bounds::Aabb;
use crate::ray::{Hit, NO_HIT, Ray};
use crate::simd::{SimdFloat, SimdU32, V3};

/// `F::LANES` rays, one per lane. For `f32x8`: 9 vectors of 32 bytes = 288 bytes.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
pub struct RayPacket<F: SimdFloat> {
    /// Origins.
    pub origin: V3<F>,
    /// Directions (unit length).
    pub dir: V3<F>,
    /// Smallest accepted t per lane.
    pub t_min: F,
    /// Largest accepted t per lane.
    pub t_max: F,
    /// Lane mask: set lanes are traced, clear lanes are left alone.
    pub active: F,
}

/// The 8-wide ray packet.
pub type RayPacket8 = RayPacket<wide::f32x8>;

/// A 16-ray packet.
pub type RayPacket16 = RayPacket<wide::f32x16>;
/// The 8-wide hit packet.
pub type HitPacket8 = HitPacket<wide::f32x8>;

impl<F: SimdFloat> RayPacket<F> {
    /// Number of lanes.
    pub const LANES: usize = F::LANES;

    /// Pack up to `LANES` rays; lanes past `rays.len()` are inactive copies of
    /// the first ray (or of a zero ray when `rays` is empty).
    pub fn from_rays(rays: &[Ray]) -> Self {
        Self::from_rays_masked(rays, u32::MAX)
    }

    /// Pack up to `LANES` rays, with only the lanes whose bit is set in `mask` active.
    #[inline(always)]
    pub fn from_rays_masked(rays: &[Ray], mask: u32) -> Self {
        assert!(rays.len() <= F::LANES, "more rays than lanes");
        let filler = rays
            .first()
            .copied()
            .unwrap_or(Ray::new(Vec3::ZERO, Vec3::Z, 0.0, 0.0));
        let mut lanes: [F::Array; 8] = Default::default();
        for i in 0..F::LANES {
            let r = rays.get(i).unwrap_or(&filler);
            let values = [
                r.origin.x, r.origin.y, r.origin.z, r.dir.x, r.dir.y, r.dir.z, r.t_min, r.t_max,
            ];
            for (array, value) in lanes.iter_mut().zip(values) {
                array.as_mut()[i] = value;
            }
        }
        let present = if rays.len() >= 32 {
            u32::MAX
        } else {
            (1u32 << rays.len()) - 1
        };
        // (No array map: this is compiled into instruction sets' entry points.)
        let [ox, oy, oz, dx, dy, dz, t_min, t_max] = lanes;
        Self {
            origin: V3 {
                x: F::from_array(ox),
                y: F::from_array(oy),
                z: F::from_array(oz),
            },
            dir: V3 {
                x: F::from_array(dx),
                y: F::from_array(dy),
                z: F::from_array(dz),
            },
            t_min: F::from_array(t_min),
            t_max: F::from_array(t_max),
            active: F::mask_from_bits(mask & present),
        }
    }

    /// The ray in lane `i`.
    #[inline(always)]
    pub fn ray(&self, i: usize) -> Ray {
        Ray::new(
            self.origin.lane(i),
            self.dir.lane(i),
            self.t_min.to_array().as_ref()[i],
            self.t_max.to_array().as_ref()[i],
        )
    }

    /// Whether lane `i` is active.
    #[inline]
    pub fn is_active(&self, i: usize) -> bool {
        self.active.bitmask() >> i & 1 == 1
    }

    /// The same packet in another lane type of the same width (another
    /// instruction set's), bit for bit.
    #[inline(always)]
    pub fn convert<G: SimdFloat>(&self) -> RayPacket<G> {
        // (A run-time check, folded away: callers match on the width, so
        // their other arms name widths that never meet.)
        assert_eq!(size_of::<F>(), size_of::<G>(), "packets of two widths");
        // SAFETY: both are `repr(C)` structs of 9 lane vectors of one size
        // (checked above), so their fields lie at the same offsets; `SimdFloat`
        // types are plain lanes in lane order, any bit pattern valid. Copying
        // the bytes from memory (rather than vector by vector through
        // registers) keeps a wide store from feeding narrower loads.
        unsafe { std::mem::transmute_copy(self) }
    }
}

/// Cosine of the widest angle (about 8°) between a lane's direction and the
/// first active lane's for which a packet counts as coherent ([`RayPacket::is_coherent`]).
pub const COHERENT_COS: f32 = 0.99;

/// Fraction of the scene box's diagonal by which some lane's origin must lie
/// from the first active lane's for the packet to count as scattered
/// ([`RayPacket::is_scattered`]).
pub const SCATTERED_SPREAD: f32 = 0.25;

/// Classification: which walk suits a packet (the BVH traversal and Embree's
/// adapter both ask).
impl<F: SimdFloat> RayPacket<F> {
    /// True when every active lane's direction lies within [`COHERENT_COS`] of the
    /// first active lane's, as for the primary rays of a pixel block or shadow
    /// rays from nearby points to one light. Such lanes stay together down to the
    /// leaves, where even one or two lanes finish a subtree as a packet faster than
    /// as single rays (measured on primary rays of the dragon against a fallback
    /// at 2 lanes), so coherent packets never fall back; incoherent ones walk the
    /// wide tree and hand subtrees to single rays ([`traverse_hybrid`](crate::accel::bvh::traverse_hybrid)).
    ///
    /// Asked of every packet (and again at every instance it enters), so it
    /// compares the lanes with one of them rather than with their mean, whose
    /// sums cost a lane at a time; packets are coherent or not by far either way.
    #[inline(always)]
    pub fn is_coherent(&self) -> bool {
        let d = &self.dir;
        let Some(reference) = first_active_lane(self.active, d) else {
            return true;
        };
        let reference_length2 = reference.length_squared();
        // A zero or NaN reference direction is no direction to share.
        if !(reference_length2 > 0.0) {
            return false;
        }
        let dot = d.dot_splat(reference);
        let length2 = d.x * d.x + d.y * d.y + d.z * d.z;
        // dot ≥ cos·|d|·|reference|, squared (both sides non-negative).
        let bound = F::splat(COHERENT_COS * COHERENT_COS * reference_length2);
        let inside = dot.ge(F::splat(0.0)) & (dot * dot).ge(bound * length2);
        self.active.and_not(inside).none()
    }

    /// True when some active lane's origin lies farther than
    /// [`SCATTERED_SPREAD`] of the diagonal of `scene` (the tree's box) from
    /// the first active lane's, as random rays from all over a scene do. Such
    /// lanes share no node below the root, so sharing node tests (the hybrid
    /// traversal) only costs, and walked as single rays interleaved they beat
    /// single rays; secondary rays from a pixel block's hit points, which do
    /// share their first nodes, lose that way. A NaN origin in an active lane
    /// makes no packet scattered.
    ///
    /// Asked of every packet (and again at every instance it enters): one
    /// lane against the others, not the lanes' extent, whose folds cost a lane at a time.
    #[inline(always)]
    pub fn is_scattered(&self, scene: &Aabb) -> bool {
        let Some(first) = first_active_lane(self.active, &self.origin) else {
            return false;
        };
        let offset = self.origin - V3::splat(first);
        let distance2 = offset.dot(offset);
        let diagonal = scene.max - scene.min;
        let bound = F::splat(SCATTERED_SPREAD * SCATTERED_SPREAD * diagonal.length_squared());
        let active = self.active;
        (distance2.gt(bound) & active).any() && (distance2.ne(distance2) & active).none()
    }
}

/// Lane `i` of `v`, where `i` is the lowest lane set in the mask `active`
/// (none if no lane is set).
#[inline(always)]
fn first_active_lane<F: SimdFloat>(active: F, v: &V3<F>) -> Option<Vec3> {
    let bits = active.bitmask();
    if bits == 0 {
        return None;
    }
    // (The remainder keeps the index provably in range: a panic path in the
    // walk's function cost primary packets 10%, docs/measurements.md. No
    // closure: it must inline into every instruction set's entry point.)
    Some(v.lane(bits.trailing_zeros() as usize % F::LANES))
}

/// Hit records of a packet, one per lane. For `f32x8`: 7 vectors = 224 bytes.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
pub struct HitPacket<F: SimdFloat> {
    /// Ray parameter of the nearest hit (`t_max` while nothing is hit).
    pub t: F,
    /// Index of the primitive hit, [`NO_HIT`] for none.
    pub prim: F::U32,
    /// First surface parameter.
    pub u: F,
    /// Second surface parameter.
    pub v: F,
    /// Geometric normal, filled in after traversal.
    pub ng: V3<F>,
}

impl<F: SimdFloat> HitPacket<F> {
    /// The same records in another lane type of the same width, bit for bit.
    #[inline(always)]
    pub fn convert<G: SimdFloat>(&self) -> HitPacket<G> {
        assert_eq!(size_of::<F>(), size_of::<G>(), "packets of two widths");
        assert_eq!(size_of::<F::U32>(), size_of::<G::U32>(), "packets of two widths");
        // SAFETY: as in `RayPacket::convert`; the u32 vectors are plain lanes too.
        unsafe { std::mem::transmute_copy(self) }
    }

    /// Empty records for `rays`: nothing hit, `t = t_max`.
    #[inline(always)]
    pub fn none(rays: &RayPacket<F>) -> Self {
        Self {
            t: rays.t_max,
            prim: F::U32::splat(NO_HIT),
            u: F::splat(0.0),
            v: F::splat(0.0),
            ng: V3::splat(Vec3::ZERO),
        }
    }

    /// The lane mask of candidates at `t` on primitive `prim` that replace the
    /// current records: the packet form of [`Hit::accepts`], restricted to active lanes.
    #[inline(always)]
    pub fn accepts(&self, rays: &RayPacket<F>, t: F, prim: u32) -> F {
        self.accepts_among(rays.active, rays, t, prim)
    }

    /// [`accepts`](Self::accepts) restricted to the lanes of `lanes`, a mask
    /// within the active lanes (a kernel's own early test), which saves the
    /// kernel a second `and` with them.
    #[inline(always)]
    pub fn accepts_among(&self, lanes: F, rays: &RayPacket<F>, t: F, prim: u32) -> F {
        // `t < hit.t` implies `t < ∞`, so only a tie needs that check.
        let mut closer = t.lt(self.t);
        let tie = t.eq(self.t);
        // Equal t is rare outside shared edges: only then compare primitive indices.
        if tie.any() {
            let finite = t.lt(F::splat(f32::INFINITY));
            closer = closer | (tie & finite & F::U32::splat(prim).lt(self.prim));
        }
        lanes & t.ge(rays.t_min) & closer
    }

    /// Record hits in the lanes of `mask`.
    #[inline(always)]
    pub fn record(&mut self, mask: F, t: F, prim: u32, u: F, v: F) {
        self.t = mask.select(t, self.t);
        self.prim = F::U32::select(mask, F::U32::splat(prim), self.prim);
        self.u = mask.select(u, self.u);
        self.v = mask.select(v, self.v);
    }

    /// Record hits without surface coordinates (u = v = 0) in the lanes of
    /// `mask`: clearing u and v takes a bitwise and-not each where a general
    /// [`record`](Self::record) blends two values.
    #[inline(always)]
    pub fn record_without_uv(&mut self, mask: F, t: F, prim: u32) {
        self.t = mask.select(t, self.t);
        self.prim = F::U32::select(mask, F::U32::splat(prim), self.prim);
        self.u = self.u.and_not(mask);
        self.v = self.v.and_not(mask);
    }

    /// The mask of lanes that hit something.
    #[inline(always)]
    pub fn hit_mask(&self) -> F {
        self.prim.lt(F::U32::splat(NO_HIT))
    }

    /// The record of lane `i`.
    #[inline(always)]
    pub fn hit(&self, i: usize) -> Hit {
        Hit {
            t: self.t.to_array().as_ref()[i],
            prim: self.prim.to_array().as_ref()[i],
            u: self.u.to_array().as_ref()[i],
            v: self.v.to_array().as_ref()[i],
            ng: self.ng.lane(i),
        }
    }

    /// Overwrite the record of lane `i` (by blends, not through memory: a
    /// vector reloaded right after a scalar store into it stalls).
    #[inline(always)]
    pub fn set_hit(&mut self, i: usize, hit: &Hit) {
        let lane = F::mask_from_bits(1 << i);
        self.t = lane.select(F::splat(hit.t), self.t);
        self.u = lane.select(F::splat(hit.u), self.u);
        self.v = lane.select(F::splat(hit.v), self.v);
        self.ng.x = lane.select(F::splat(hit.ng.x), self.ng.x);
        self.ng.y = lane.select(F::splat(hit.ng.y), self.ng.y);
        self.ng.z = lane.select(F::splat(hit.ng.z), self.ng.z);
        self.prim = F::U32::select(lane, F::U32::splat(hit.prim), self.prim);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Camera;
    use crate::rng::Rng;

    /// Random rays from all over a scene are scattered; rays from points
    /// close together are not, whatever their directions; inactive lanes and
    /// NaN origins do not make a packet scattered.
    #[test]
    fn random_rays_are_scattered_and_rays_from_nearby_points_are_not() {
        let scene = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
        let mut rng = Rng::new(8);
        for _ in 0..100 {
            let random: Vec<Ray> = (0..8)
                .map(|_| Ray::unbounded(rng.point_in(scene.min, scene.max), rng.unit_vector()))
                .collect();
            assert!(RayPacket8::from_rays(&random).is_scattered(&scene));
            let centre = rng.point_in(scene.min, scene.max);
            let nearby: Vec<Ray> = (0..8)
                .map(|_| {
                    Ray::unbounded(
                        centre + rng.point_in(Vec3::splat(-0.1), Vec3::splat(0.1)),
                        rng.unit_vector(),
                    )
                })
                .collect();
            assert!(!RayPacket8::from_rays(&nearby).is_scattered(&scene));
        }
        // Two lanes at opposite corners: scattered only while both are active.
        let mut rays = [Ray::unbounded(scene.min, Vec3::Z); 8];
        rays[1].origin = scene.max;
        assert!(RayPacket8::from_rays(&rays).is_scattered(&scene));
        assert!(!RayPacket8::from_rays_masked(&rays, 0b1111_1101).is_scattered(&scene));
        // The first lane, far from the others, counts only while active.
        assert!(!RayPacket8::from_rays_masked(&rays[1..], 0b1111_1110).is_scattered(&scene));
        let mut far_first = [Ray::unbounded(scene.min, Vec3::Z); 8];
        far_first[0].origin = scene.max;
        assert!(RayPacket8::from_rays(&far_first).is_scattered(&scene));
        assert!(!RayPacket8::from_rays_masked(&far_first, 0b1111_1110).is_scattered(&scene));
        rays[2].origin.x = f32::NAN;
        assert!(!RayPacket8::from_rays(&rays).is_scattered(&scene));
    }

    #[test]
    fn pixel_blocks_are_coherent_and_random_rays_are_not() {
        let camera = Camera::new(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 60.0, 60.0, 64, 64).unwrap();
        let pixels: Vec<(u32, u32)> = (0..8).map(|k| (10 + k % 4, 20 + k / 4)).collect();
        let block = camera.pixel_packet::<wide::f32x8>(&pixels);
        assert!(block.is_coherent());

        let mut rng = Rng::new(3);
        let random: Vec<Ray> = (0..8)
            .map(|_| Ray::unbounded(Vec3::ZERO, rng.unit_vector()))
            .collect();
        assert!(!RayPacket8::from_rays(&random).is_coherent());

        // Inactive lanes do not count.
        let mut mixed = random.clone();
        mixed[..4].copy_from_slice(&[Ray::unbounded(Vec3::ZERO, Vec3::Z); 4]);
        assert!(RayPacket8::from_rays_masked(&mixed, 0b1111).is_coherent());
        // A random first lane counts only while active, a NaN direction in any active lane breaks coherence.
        mixed[0].dir = random[0].dir;
        assert!(!RayPacket8::from_rays_masked(&mixed, 0b1111).is_coherent());
        assert!(RayPacket8::from_rays_masked(&mixed, 0b1110).is_coherent());
        mixed[2].dir = Vec3::new(f32::NAN, 0.0, 1.0);
        assert!(!RayPacket8::from_rays_masked(&mixed, 0b1110).is_coherent());
        mixed[1].dir = Vec3::new(f32::NAN, 0.0, 1.0);
        assert!(!RayPacket8::from_rays_masked(&mixed, 0b1110).is_coherent());
        // Directions 10° apart are not coherent, 5° apart are.
        let tilted = |deg: f32| {
            let a = deg.to_radians();
            let mut rays = [Ray::unbounded(Vec3::ZERO, Vec3::Z); 8];
            rays[7].dir = Vec3::new(a.sin(), 0.0, a.cos());
            RayPacket8::from_rays(&rays)
        };
        assert!(tilted(5.0).is_coherent());
        assert!(!tilted(10.0).is_coherent());
    }
}
