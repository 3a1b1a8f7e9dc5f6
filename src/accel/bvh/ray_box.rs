//! The ray-box slab test (Kay & Kajiya, "Ray tracing complex scenes", SIGGRAPH
//! 1986), scalar and packet twins side by side.
//!
//! Per axis the ray is inside the slab `[min, max]` for `t` between
//! `(min − o)·(1/d)` and `(max − o)·(1/d)`; the box is entered at the largest slab
//! entry and left at the smallest slab exit. Made robust for traversal:
//! - a zero (or subnormal) direction component becomes `+0`, so its reciprocal is
//!   `+∞` and never `−∞`;
//! - a ray running inside a slab's bounding plane gives `0·∞ = NaN`; the min/max
//!   chain is written `candidate.fast_max(accumulator)` so a NaN candidate is
//!   ignored (x86 `maxps` semantics, see [`SimdFloat::fast_max`]): a ray lying in
//!   a face counts as inside that slab;
//! - a ray whose products cannot be NaN (finite origin, every direction
//!   component finite and normal, `t_min ≥ 0`: [`SlabRay::is_finite`], nearly
//!   every ray) combines its slabs by integer min/max of the bits instead
//!   ([`SimdFloat::max_bits`]: one cycle a step where `maxps` takes four on
//!   Intel cores, as Embree does). The entry is then the same number: its floor
//!   `t_min ≥ 0` outranks every negative candidate either way. The exit is the
//!   same wherever it is ≥ +0; where a candidate is negative both are below
//!   the entry (a miss), but for an exit at `−0` against an entry of `+0`,
//!   which the integer chain may keep where the float chain drops it (a box
//!   touched at t = 0 from behind: kept, never lost);
//! - the exit is scaled by [`FAR_SCALE`] (Ize, "Robust BVH ray traversal", JCGT
//!   2013), so rounding never culls a box the ray touches. The scale is folded
//!   into a second reciprocal used for exit planes (`(o − max)·(−s/d)`), which
//!   keeps the multiply off the exit's dependency chain; `min(a, b)·s` equals
//!   `min(a·s, b·s)` exactly, so the current hit's t is scaled alike.
//!
//! The planes are subtracted from the origin and scaled by `−1/d`:
//! `(o − p)·(−1/d)` is `(p − o)·(1/d)` exactly (rounding is symmetric under
//! negation), but for the sign of a zero t, which no comparison sees; and
//! with the plane second, a SIMD subtraction takes it straight from memory
//! (a 16-wide node's twelve plane loads are folded into the subtractions).
//!
//! Each ray picks each axis' entry and exit plane once, by the sign of its
//! direction (Williams et al., "An efficient and robust ray-box intersection
//! algorithm", JGT 2005): the single ray by index, the packet lane by lane with
//! a select. For every non-empty box the two give the same bits, NaN cases included.
//!
//! The hit test is `entry ≤ exit` with the current hit's t folded into the exit:
//! a box entered exactly at the current hit's t is kept, as the tie rule of
//! [`Hit::accepts`](crate::ray::Hit::accepts) needs.

use glam::Vec3;

use crate::accel::bvh::node::Node;
use crate::packet::RayPacket;
use crate::ray::Ray;
use crate::simd::{SimdFloat, V3, max_bits, min_bits};

/// Scale of the slab exit: `1 + 2⁻¹⁹`, a margin of about 32 ulps of t.
pub const FAR_SCALE: f32 = 1.0 + 1.0 / 524_288.0;

/// `1/d` with zero and subnormal components mapped to `+∞`.
#[inline(always)]
fn safe_inverse(d: f32) -> f32 {
    if d.abs() < f32::MIN_POSITIVE {
        f32::INFINITY
    } else {
        1.0 / d
    }
}

/// `a < b ? a : b`: x86 `minss`, where a NaN yields `b`.
#[inline(always)]
fn fast_min(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

/// `a > b ? a : b`: x86 `maxss`, where a NaN yields `b`.
#[inline(always)]
fn fast_max(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}

/// A ray prepared for slab tests: origin, negated reciprocal direction (plain
/// for entry planes, scaled by [`FAR_SCALE`] for exit planes), `t_min`, and per
/// axis which box corner holds the entry plane. 64 bytes.
#[derive(Clone, Copy, Debug)]
pub struct SlabRay {
    /// Origin.
    pub origin: Vec3,
    /// Negated reciprocal direction `−1/d`; zero and subnormal components give `−∞`.
    pub neg_inv_dir: Vec3,
    /// `−FAR_SCALE / d`, for exit planes.
    pub neg_inv_dir_far: Vec3,
    /// Smallest accepted t.
    pub t_min: f32,
    /// Whether no slab product can be NaN, so entry and exit are combined by
    /// integer min/max ([`SlabRay::is_finite`]).
    pub finite: bool,
    /// Per axis: 0 when the ray enters through the `min` plane (`1/d ≥ 0`), 1 through `max`.
    entry_corner: [usize; 3],
}

impl SlabRay {
    /// Prepare `ray`.
    #[inline(always)]
    pub fn new(ray: &Ray) -> Self {
        let inv_dir = Vec3::new(
            safe_inverse(ray.dir.x),
            safe_inverse(ray.dir.y),
            safe_inverse(ray.dir.z),
        );
        Self {
            origin: ray.origin,
            neg_inv_dir: -inv_dir,
            neg_inv_dir_far: inv_dir * -FAR_SCALE,
            t_min: ray.t_min,
            finite: Self::is_finite(ray),
            entry_corner: [0, 1, 2].map(|k| usize::from(inv_dir[k] < 0.0)),
        }
    }

    /// Whether `ray`'s slab products are never NaN and its entries floor at
    /// +0: a finite origin, every direction component finite and normal (so
    /// every reciprocal is finite and not zero) and `t_min ≥ 0`. Then entry
    /// and exit are combined by integer min/max of their bits, exactly as the
    /// float chain would (module docs).
    #[inline(always)]
    pub fn is_finite(ray: &Ray) -> bool {
        let normal = |d: f32| d.abs() >= f32::MIN_POSITIVE && d.is_finite();
        ray.origin.is_finite()
            && normal(ray.dir.x)
            && normal(ray.dir.y)
            && normal(ray.dir.z)
            && ray.t_min >= 0.0
    }

    /// The entry t of the non-empty box `[min, max]` if the ray meets it within
    /// `[t_min, t_max]`, else None.
    #[inline(always)]
    pub fn entry(&self, min: Vec3, max: Vec3, t_max: f32) -> Option<f32> {
        let corners = [min, max];
        let plane = |corner: usize, k: usize| self.origin[k] - corners[corner][k];
        let near = |k: usize| plane(self.entry_corner[k], k) * self.neg_inv_dir[k];
        let far = |k: usize| plane(1 - self.entry_corner[k], k) * self.neg_inv_dir_far[k];
        let (t_near, t_far) = if self.finite {
            (
                max_bits(near(0), max_bits(near(1), max_bits(near(2), self.t_min))),
                min_bits(far(0), min_bits(far(1), min_bits(far(2), t_max * FAR_SCALE))),
            )
        } else {
            (
                fast_max(near(0), fast_max(near(1), fast_max(near(2), self.t_min))),
                fast_min(far(0), fast_min(far(1), fast_min(far(2), t_max * FAR_SCALE))),
            )
        };
        (t_near <= t_far).then_some(t_near)
    }

    /// 0 when the ray enters boxes through their `min` plane along `axis`, 1 through `max`.
    #[inline(always)]
    pub fn entry_corner(&self, axis: usize) -> usize {
        self.entry_corner[axis]
    }

    /// [`SlabRay::entry`] of a node's box.
    #[inline(always)]
    pub fn node_entry(&self, node: &Node, t_max: f32) -> Option<f32> {
        self.entry(node.min, node.max, t_max)
    }
}

/// A box's entry and exit t from its three slabs' (`near`, `far`, per axis)
/// and the ray's `[t_min, t_max]`, combined by integer min/max of the bits:
/// for rays whose products cannot be NaN ([`SlabRay::is_finite`]), lane by
/// lane what [`combine_ignoring_nan`] gives but for the sign of a zero exit
/// (module docs). Packets and wide nodes share it; the scalar twin is in
/// [`SlabRay::entry`].
#[inline(always)]
pub fn combine_by_bits<F: SimdFloat>(near: [F; 3], far: [F; 3], t_min: F, t_max: F) -> (F, F) {
    (
        near[0].max_bits(near[1].max_bits(near[2].max_bits(t_min))),
        far[0].min_bits(far[1].min_bits(far[2].min_bits(t_max))),
    )
}

/// [`combine_by_bits`] by float min/max written so that a NaN candidate is
/// ignored ([`SimdFloat::fast_max`]): for every ray.
#[inline(always)]
pub fn combine_ignoring_nan<F: SimdFloat>(near: [F; 3], far: [F; 3], t_min: F, t_max: F) -> (F, F) {
    (
        near[0].fast_max(near[1].fast_max(near[2].fast_max(t_min))),
        far[0].fast_min(far[1].fast_min(far[2].fast_min(t_max))),
    )
}

/// A ray packet prepared for slab tests. For `f32x8`: 13 vectors = 416 bytes.
#[derive(Clone, Copy, Debug)]
pub struct SlabPacket<F: SimdFloat> {
    /// Origins.
    pub origin: V3<F>,
    /// Negated reciprocal directions `−1/d`; zero and subnormal components give `−∞`.
    pub neg_inv_dir: V3<F>,
    /// `−FAR_SCALE / d`, for exit planes.
    pub neg_inv_dir_far: V3<F>,
    /// Per axis, the lanes entering boxes through their `max` plane (`1/d < 0`).
    enters_max: V3<F>,
    /// Smallest accepted t per lane.
    pub t_min: F,
    /// The lanes whose slab products are never NaN ([`SlabRay::is_finite`]).
    finite: F,
    /// Whether every active lane is: then the whole packet combines by integer min/max.
    all_finite: bool,
}

impl<F: SimdFloat> SlabPacket<F> {
    /// Prepare `rays` (lane by lane the same numbers as [`SlabRay::new`]).
    #[inline(always)]
    pub fn new(rays: &RayPacket<F>) -> Self {
        let inv_dir = V3 {
            x: Self::inverse(rays.dir.x),
            y: Self::inverse(rays.dir.y),
            z: Self::inverse(rays.dir.z),
        };
        let (minus, neg_scale) = (F::splat(-1.0), F::splat(-FAR_SCALE));
        // Lane by lane `SlabRay::is_finite` (comparisons with NaN are false).
        let (o, d) = (&rays.origin, &rays.dir);
        let finite = Self::normal(d.x)
            & Self::normal(d.y)
            & Self::normal(d.z)
            & Self::finite_lanes(o.x)
            & Self::finite_lanes(o.y)
            & Self::finite_lanes(o.z)
            & rays.t_min.ge(F::splat(0.0));
        Self {
            origin: rays.origin,
            neg_inv_dir: V3 {
                x: inv_dir.x * minus,
                y: inv_dir.y * minus,
                z: inv_dir.z * minus,
            },
            neg_inv_dir_far: V3 {
                x: inv_dir.x * neg_scale,
                y: inv_dir.y * neg_scale,
                z: inv_dir.z * neg_scale,
            },
            enters_max: V3 {
                x: inv_dir.x.lt(F::splat(0.0)),
                y: inv_dir.y.lt(F::splat(0.0)),
                z: inv_dir.z.lt(F::splat(0.0)),
            },
            t_min: rays.t_min,
            finite,
            all_finite: rays.active.and_not(finite).none(),
        }
    }

    /// The lanes meeting the box `[min, max]` within `[t_min, t_max]`, as a mask,
    /// and every lane's entry t (meaningful in the mask's lanes).
    #[inline(always)]
    pub fn entry(&self, min: Vec3, max: Vec3, t_max: F) -> (F, F) {
        let (i, f, m) = (&self.neg_inv_dir, &self.neg_inv_dir_far, &self.enters_max);
        let (nx, fx) = Self::slab(min.x, max.x, self.origin.x, i.x, f.x, m.x);
        let (ny, fy) = Self::slab(min.y, max.y, self.origin.y, i.y, f.y, m.y);
        let (nz, fz) = Self::slab(min.z, max.z, self.origin.z, i.z, f.z, m.z);
        let (near, far) = ([nx, ny, nz], [fx, fy, fz]);
        let t_max = t_max * F::splat(FAR_SCALE);
        let (t_near, t_far) = combine_by_bits(near, far, self.t_min, t_max);
        if self.all_finite {
            return (t_near.le(t_far), t_near);
        }
        // Lanes where a product may be NaN take the float chain, which ignores it.
        let (float_near, float_far) = combine_ignoring_nan(near, far, self.t_min, t_max);
        let t_near = self.finite.select(t_near, float_near);
        let t_far = self.finite.select(t_far, float_far);
        (t_near.le(t_far), t_near)
    }

    /// `1/d`, with `+∞` for zero and subnormal `d`. (Functions rather than
    /// closures: everything under a level's entry point must inline, see
    /// [`LevelTask`](crate::simd::isa::LevelTask).)
    #[inline(always)]
    fn inverse(d: F) -> F {
        let tiny = d.abs().lt(F::splat(f32::MIN_POSITIVE));
        tiny.select(F::splat(f32::INFINITY), F::splat(1.0) / d)
    }

    /// The lanes of `d` that are finite and normal (their reciprocals finite, not zero).
    #[inline(always)]
    fn normal(d: F) -> F {
        d.abs().ge(F::splat(f32::MIN_POSITIVE)) & Self::finite_lanes(d)
    }

    /// The finite lanes of `x`.
    #[inline(always)]
    fn finite_lanes(x: F) -> F {
        x.abs().lt(F::splat(f32::INFINITY))
    }

    /// One axis's entry and exit t per lane: the planes picked by the sign of
    /// `1/d`, as the single ray picks them.
    #[inline(always)]
    fn slab(lo: f32, hi: f32, o: F, neg_inv: F, neg_inv_far: F, enters_max: F) -> (F, F) {
        let (lo, hi) = (F::splat(lo), F::splat(hi));
        let near = (o - enters_max.select(hi, lo)) * neg_inv;
        let far = (o - enters_max.select(lo, hi)) * neg_inv_far;
        (near, far)
    }

    /// [`SlabPacket::entry`] of a node's box.
    #[inline(always)]
    pub fn node_entry(&self, node: &Node, t_max: F) -> (F, F) {
        self.entry(node.min, node.max, t_max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use wide::f32x8;

    /// The boxes and rays of the edge cases: faces, edges, axis-parallel rays in
    /// bounding planes, flat and zero-size boxes, NaN and infinite input. (Empty
    /// boxes are left out: the BVH never tests one, and there the twins differ.)
    fn edge_cases() -> Vec<(Aabb3, Ray)> {
        let unit = (Vec3::ZERO, Vec3::ONE);
        let flat = (Vec3::new(0.0, 0.0, 0.5), Vec3::new(1.0, 1.0, 0.5));
        let point = (Vec3::splat(0.5), Vec3::splat(0.5));
        let r = |o: [f32; 3], d: [f32; 3]| Ray::unbounded(Vec3::from(o), Vec3::from(d));
        vec![
            (unit, r([0.5, 0.5, -1.0], [0.0, 0.0, 1.0])),  // straight through
            (unit, r([0.0, 0.5, -1.0], [0.0, 0.0, 1.0])),  // in the x = min face plane
            (unit, r([1.0, 0.5, -1.0], [0.0, 0.0, 1.0])),  // in the x = max face plane
            (unit, r([1.0, 1.0, -1.0], [0.0, -0.0, 1.0])), // along an edge, −0 direction
            (unit, r([1.5, 0.5, -1.0], [0.0, 0.0, 1.0])),  // parallel, outside
            (unit, r([0.5, 0.5, 0.5], [1.0, 0.0, 0.0])),   // inside
            (unit, r([0.5, 0.5, 2.0], [0.0, 0.0, 1.0])),   // box behind
            (unit, r([-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]).normalize_dir()), // through a corner
            (unit, r([-1.0, 0.0, 0.5], [1.0, 1.0, 0.0]).normalize_dir()), // touches the edge x = 0, y = 1
            (flat, r([0.5, 0.5, -1.0], [0.0, 0.0, 1.0])),  // flat box, perpendicular
            (flat, r([0.5, 0.5, 0.5], [1.0, 0.0, 0.0])),   // ray inside the flat box's plane
            (flat, r([-1.0, 0.2, 0.5], [1.0, 0.0, 0.0])),  // in the plane, from outside
            (point, r([0.5, 0.5, -1.0], [0.0, 0.0, 1.0])), // zero-size box hit dead on
            (point, r([0.6, 0.5, -1.0], [0.0, 0.0, 1.0])), // zero-size box missed
            // Past here no expected answer, only scalar/packet agreement on non-finite input.
            (unit, r([f32::NAN, 0.5, -1.0], [0.0, 0.0, 1.0])),
            (unit, r([0.5, 0.5, -1.0], [f32::NAN, 0.0, 1.0])),
            (unit, r([0.5, 0.5, f32::NEG_INFINITY], [0.0, 0.0, 1.0])),
            (unit, r([0.5, 0.5, -1.0], [1e-40, -1e-40, 1.0])), // subnormal components
        ]
    }

    type Aabb3 = (Vec3, Vec3);

    trait NormalizeDir {
        fn normalize_dir(self) -> Self;
    }
    impl NormalizeDir for Ray {
        fn normalize_dir(mut self) -> Self {
            self.dir = self.dir.normalize();
            self
        }
    }

    #[test]
    fn edge_cases_hit_as_geometry_says() {
        let expect = [
            true, true, true, true, false, true, false, true, true, true, true, true, true, false,
        ];
        for (i, ((min, max), ray)) in edge_cases().into_iter().take(expect.len()).enumerate() {
            let hit = SlabRay::new(&ray).entry(min, max, ray.t_max).is_some();
            assert_eq!(hit, expect[i], "case {i}: {ray:?} vs [{min}, {max}]");
        }
    }

    /// Random rays against random boxes (some flat, some rays axis-parallel and
    /// starting on a box plane), plus the edge cases: the packet twin must give
    /// every lane the scalar answer and entry t.
    #[test]
    fn packet_slab_test_agrees_with_scalar_lane_by_lane() {
        let mut rng = Rng::new(11);
        let mut cases = edge_cases();
        let n = 1 << 20;
        while cases.len() < n {
            let a = rng.point_in(Vec3::splat(-2.0), Vec3::splat(2.0));
            let mut b = rng.point_in(Vec3::splat(-2.0), Vec3::splat(2.0));
            if rng.below(8) == 0 {
                b.z = a.z; // flat box
            }
            let (min, max) = (a.min(b), a.max(b));
            let mut origin = rng.point_in(Vec3::splat(-4.0), Vec3::splat(4.0));
            // Half the rays aim at a point of the box, so about half of all rays hit.
            let mut dir = if rng.below(2) == 0 {
                (rng.point_in(min, max) - origin).normalize_or(Vec3::Z)
            } else {
                rng.unit_vector()
            };
            if rng.below(8) == 0 {
                let k = rng.below(3) as usize;
                dir[k] = 0.0; // axis-parallel ray, often in a box plane
                dir = dir.normalize_or(Vec3::X);
                origin[k] = if rng.below(2) == 0 { min[k] } else { max[k] };
            }
            let t_max = if rng.below(2) == 0 {
                f32::INFINITY
            } else {
                rng.range(0.0, 6.0)
            };
            cases.push(((min, max), Ray::new(origin, dir, rng.range(0.0, 0.5), t_max)));
        }
        let mut hits = 0usize;
        for chunk in cases.chunks(8) {
            let rays: Vec<Ray> = chunk.iter().map(|c| c.1).collect();
            let packet = RayPacket::<f32x8>::from_rays(&rays);
            let slab = SlabPacket::new(&packet);
            for (lane, ((min, max), ray)) in chunk.iter().enumerate() {
                // One box per lane: test the lane's box against the whole packet, read the lane.
                let (mask, t) = slab.entry(*min, *max, packet.t_max);
                let scalar = SlabRay::new(ray).entry(*min, *max, ray.t_max);
                let lane_hit = mask.bitmask() >> lane & 1 == 1;
                assert_eq!(lane_hit, scalar.is_some(), "{ray:?} vs [{min}, {max}]");
                if let Some(ts) = scalar {
                    assert_eq!(t.to_array()[lane].to_bits(), ts.to_bits(), "{ray:?}");
                    hits += 1;
                }
            }
        }
        assert!(hits > n / 4, "too few hits ({hits}) for a meaningful test");
    }
}
