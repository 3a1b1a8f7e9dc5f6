//! The SIMD lane types behind ray packets.
//!
//! [`SimdFloat`] is the one trait the packet kernels are written against. It is
//! implemented for `wide::f32x4`, `f32x8` and `f32x16`, so the packet width is a
//! type parameter: `RayPacket<f32x8>` is the 8-wide packet the engine uses, and a
//! 4- or 16-wide packet is the same code instantiated with another type.
//!
//! A *mask* is a float vector whose lanes are all-ones (true) or all-zeros
//! (false), as returned by the comparisons.

use std::fmt::Debug;
use std::ops::{Add, BitAnd, BitOr, BitXor, Div, Mul, Neg, Sub};

use wide::{f32x4, f32x8, f32x16, u32x4, u32x8, u32x16};

/// The SIMD type of a single ray's box test, and so the width of the BVH's
/// wide nodes and leaf blocks: 8 lanes per `f32x8` test where the CPU has
/// 256-bit vectors (AVX), 4 per `f32x4` elsewhere. The one place the width of
/// the single-ray kernels is chosen.
#[cfg(target_feature = "avx")]
pub type NodeLanes = f32x8;
/// The SIMD type of a single ray's box test (see the AVX variant).
#[cfg(not(target_feature = "avx"))]
pub type NodeLanes = f32x4;

/// A vector of `LANES` f32 lanes, with its lane-matched u32 vector.
pub trait SimdFloat:
    Copy
    + Debug
    + Send
    + Sync
    + 'static
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + BitAnd<Output = Self>
    + BitOr<Output = Self>
    + BitXor<Output = Self>
{
    /// Number of lanes.
    const LANES: usize;
    /// The u32 vector with the same lane count (primitive indices).
    type U32: SimdU32<Mask = Self>;
    /// `[f32; LANES]`.
    type Array: AsRef<[f32]> + AsMut<[f32]> + Copy + Default + Debug;

    /// All lanes set to `x`.
    fn splat(x: f32) -> Self;
    /// Lanes from an array.
    fn from_array(a: Self::Array) -> Self;
    /// Lanes to an array.
    fn to_array(self) -> Self::Array;
    /// Lane-wise `self < rhs` as a mask.
    fn lt(self, rhs: Self) -> Self;
    /// Lane-wise `self <= rhs` as a mask.
    fn le(self, rhs: Self) -> Self;
    /// Lane-wise `self > rhs` as a mask.
    fn gt(self, rhs: Self) -> Self;
    /// Lane-wise `self >= rhs` as a mask.
    fn ge(self, rhs: Self) -> Self;
    /// Lane-wise `self == rhs` as a mask.
    fn eq(self, rhs: Self) -> Self;
    /// Lane-wise `self != rhs` as a mask (true for NaN lanes).
    fn ne(self, rhs: Self) -> Self;
    /// Per lane: `if_true` where the mask `self` is set, else `if_false`.
    fn select(self, if_true: Self, if_false: Self) -> Self;
    /// `self & !rhs` on masks.
    fn and_not(self, rhs: Self) -> Self;
    /// One bit per lane, lane 0 in bit 0.
    fn bitmask(self) -> u32;
    /// True when any lane of the mask is set.
    fn any(self) -> bool;
    /// True when no lane of the mask is set.
    fn none(self) -> bool;
    /// Lane-wise square root (NaN for negative lanes).
    fn sqrt(self) -> Self;
    /// Lane-wise absolute value.
    fn abs(self) -> Self;
    /// Lane-wise minimum.
    fn min(self, rhs: Self) -> Self;
    /// Lane-wise maximum.
    fn max(self, rhs: Self) -> Self;
    /// Lane-wise minimum in one instruction (x86 `minps`): where either lane is
    /// NaN the result is the lane of `rhs`, so `candidate.fast_min(acc)` ignores
    /// a NaN candidate. The BVH's slab test relies on this.
    fn fast_min(self, rhs: Self) -> Self;
    /// Lane-wise maximum in one instruction (x86 `maxps`): where either lane is
    /// NaN the result is the lane of `rhs`.
    fn fast_max(self, rhs: Self) -> Self;
    /// The mask with every lane set.
    fn all_true() -> Self;
    /// The mask with lane `i` set where bit `i` of `bits` is.
    fn mask_from_bits(bits: u32) -> Self;
    /// The mask reinterpreted as a u32 mask of the same lanes.
    fn to_u32_mask(self) -> Self::U32;
}

/// A vector of u32 lanes, matched lane for lane to a [`SimdFloat`].
pub trait SimdU32: Copy + Debug + Send + Sync + 'static {
    /// The float mask type of the same width.
    type Mask;
    /// `[u32; LANES]`.
    type Array: AsRef<[u32]> + AsMut<[u32]> + Copy + Default + Debug;
    /// All lanes set to `x`.
    fn splat(x: u32) -> Self;
    /// Lanes from an array.
    fn from_array(a: Self::Array) -> Self;
    /// Lanes to an array.
    fn to_array(self) -> Self::Array;
    /// Lane-wise unsigned `self < rhs`, as a float mask.
    fn lt(self, rhs: Self) -> Self::Mask;
    /// Per lane: `if_true` where the float mask is set, else `if_false`.
    fn select(mask: Self::Mask, if_true: Self, if_false: Self) -> Self;
}

macro_rules! impl_simd_float {
    ($f:ident, $u:ident, $n:literal) => {
        impl SimdFloat for $f {
            const LANES: usize = $n;
            type U32 = $u;
            type Array = [f32; $n];

            #[inline(always)]
            fn splat(x: f32) -> Self {
                $f::splat(x)
            }
            #[inline(always)]
            fn from_array(a: Self::Array) -> Self {
                $f::new(a)
            }
            #[inline(always)]
            fn to_array(self) -> Self::Array {
                $f::to_array(self)
            }
            #[inline(always)]
            fn lt(self, rhs: Self) -> Self {
                self.simd_lt(rhs)
            }
            #[inline(always)]
            fn le(self, rhs: Self) -> Self {
                self.simd_le(rhs)
            }
            #[inline(always)]
            fn gt(self, rhs: Self) -> Self {
                self.simd_gt(rhs)
            }
            #[inline(always)]
            fn ge(self, rhs: Self) -> Self {
                self.simd_ge(rhs)
            }
            #[inline(always)]
            fn eq(self, rhs: Self) -> Self {
                self.simd_eq(rhs)
            }
            #[inline(always)]
            fn ne(self, rhs: Self) -> Self {
                self.simd_ne(rhs)
            }
            #[inline(always)]
            fn select(self, if_true: Self, if_false: Self) -> Self {
                $f::select(self, if_true, if_false)
            }
            #[inline(always)]
            fn and_not(self, rhs: Self) -> Self {
                self & !rhs
            }
            #[inline(always)]
            fn bitmask(self) -> u32 {
                self.to_bitmask()
            }
            #[inline(always)]
            fn any(self) -> bool {
                $f::any(self)
            }
            #[inline(always)]
            fn none(self) -> bool {
                $f::none(self)
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                $f::sqrt(self)
            }
            #[inline(always)]
            fn abs(self) -> Self {
                $f::abs(self)
            }
            #[inline(always)]
            fn min(self, rhs: Self) -> Self {
                $f::min(self, rhs)
            }
            #[inline(always)]
            fn max(self, rhs: Self) -> Self {
                $f::max(self, rhs)
            }
            #[inline(always)]
            fn fast_min(self, rhs: Self) -> Self {
                $f::fast_min(self, rhs)
            }
            #[inline(always)]
            fn fast_max(self, rhs: Self) -> Self {
                $f::fast_max(self, rhs)
            }
            #[inline(always)]
            fn all_true() -> Self {
                $f::splat(f32::from_bits(u32::MAX))
            }
            #[inline(always)]
            fn mask_from_bits(bits: u32) -> Self {
                // Lane i keeps bit i of `bits`, then a compare widens it to the
                // whole lane (in registers: no stores and reloads).
                let lane_bits = $u::new(std::array::from_fn(|i| 1u32 << i));
                wide::bytemuck::cast(($u::splat(bits) & lane_bits).simd_eq(lane_bits))
            }
            #[inline(always)]
            fn to_u32_mask(self) -> $u {
                wide::bytemuck::cast(self)
            }
        }

        impl SimdU32 for $u {
            type Mask = $f;
            type Array = [u32; $n];

            #[inline(always)]
            fn splat(x: u32) -> Self {
                $u::splat(x)
            }
            #[inline(always)]
            fn from_array(a: Self::Array) -> Self {
                $u::new(a)
            }
            #[inline(always)]
            fn to_array(self) -> Self::Array {
                $u::to_array(self)
            }
            #[inline(always)]
            fn lt(self, rhs: Self) -> $f {
                wide::bytemuck::cast(self.simd_lt(rhs))
            }
            #[inline(always)]
            fn select(mask: $f, if_true: Self, if_false: Self) -> Self {
                let mask: $u = wide::bytemuck::cast(mask);
                mask.select(if_true, if_false)
            }
        }
    };
}

impl_simd_float!(f32x4, u32x4, 4);
impl_simd_float!(f32x8, u32x8, 8);
impl_simd_float!(f32x16, u32x16, 16);

/// A 3-vector of SIMD lanes (structure of arrays): lane `i` of `x, y, z` is one vector.
#[derive(Clone, Copy, Debug)]
pub struct V3<F> {
    /// x lanes.
    pub x: F,
    /// y lanes.
    pub y: F,
    /// z lanes.
    pub z: F,
}

impl<F: SimdFloat> V3<F> {
    /// Every lane holds the vector `v`.
    #[inline(always)]
    pub fn splat(v: glam::Vec3) -> Self {
        Self {
            x: F::splat(v.x),
            y: F::splat(v.y),
            z: F::splat(v.z),
        }
    }

    /// Component `k` (0 = x, 1 = y, 2 = z).
    #[inline(always)]
    pub fn axis(&self, k: usize) -> F {
        match k {
            0 => self.x,
            1 => self.y,
            _ => self.z,
        }
    }

    /// Dot product, summed in x, y, z order like `glam::Vec3::dot`.
    #[inline(always)]
    pub fn dot(self, o: Self) -> F {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// Dot product with one vector shared by all lanes.
    #[inline(always)]
    pub fn dot_splat(self, o: glam::Vec3) -> F {
        self.x * F::splat(o.x) + self.y * F::splat(o.y) + self.z * F::splat(o.z)
    }

    /// Cross product, the same formula as `glam::Vec3::cross`.
    #[inline(always)]
    pub fn cross(self, o: Self) -> Self {
        Self {
            x: self.y * o.z - o.y * self.z,
            y: self.z * o.x - o.z * self.x,
            z: self.x * o.y - o.x * self.y,
        }
    }

    /// Every lane scaled by the lanes of `s`.
    #[inline(always)]
    pub fn scale(self, s: F) -> Self {
        Self {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }

    /// Per lane: `a` where the mask is set, else `b`.
    #[inline(always)]
    pub fn select(mask: F, a: Self, b: Self) -> Self {
        Self {
            x: mask.select(a.x, b.x),
            y: mask.select(a.y, b.y),
            z: mask.select(a.z, b.z),
        }
    }

    /// Lane `i` as a `glam::Vec3`.
    #[inline]
    pub fn lane(&self, i: usize) -> glam::Vec3 {
        glam::Vec3::new(
            self.x.to_array().as_ref()[i],
            self.y.to_array().as_ref()[i],
            self.z.to_array().as_ref()[i],
        )
    }
}

impl<F: SimdFloat> Add for V3<F> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
}

impl<F: SimdFloat> Sub for V3<F> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
}

impl<F: SimdFloat> Neg for V3<F> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self {
            x: -self.x,
            y: -self.y,
            z: -self.z,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check_masks<F: SimdFloat>() {
        let bits = 0b1010_0110 & ((1u32 << F::LANES.min(31)) - 1);
        let m = F::mask_from_bits(bits);
        assert_eq!(m.bitmask(), bits);
        assert!(F::all_true().any());
        assert_eq!(F::all_true().bitmask().count_ones() as usize, F::LANES);
        let a = F::splat(1.0);
        let b = F::splat(2.0);
        let s = m.select(a, b).to_array();
        for (i, x) in s.as_ref().iter().enumerate() {
            assert_eq!(*x, if bits >> i & 1 == 1 { 1.0 } else { 2.0 });
        }
        let ids = F::U32::select(m, F::U32::splat(7), F::U32::splat(9)).to_array();
        for (i, x) in ids.as_ref().iter().enumerate() {
            assert_eq!(*x, if bits >> i & 1 == 1 { 7 } else { 9 });
        }
        // Unsigned order: u32::MAX (no primitive) is larger than every index.
        assert!(F::U32::splat(3).lt(F::U32::splat(u32::MAX)).any());
        assert!(F::U32::splat(u32::MAX).lt(F::U32::splat(3)).none());
    }

    fn check_fast_min_max<F: SimdFloat>() {
        let nan = F::splat(f32::NAN);
        let (one, two) = (F::splat(1.0), F::splat(2.0));
        assert_eq!(one.fast_min(two).to_array().as_ref()[0], 1.0);
        assert_eq!(two.fast_max(one).to_array().as_ref()[0], 2.0);
        // A NaN on either side yields the right-hand lane.
        assert_eq!(nan.fast_min(one).to_array().as_ref()[0], 1.0);
        assert_eq!(nan.fast_max(one).to_array().as_ref()[0], 1.0);
        assert!(one.fast_min(nan).to_array().as_ref()[0].is_nan());
        assert!(one.fast_max(nan).to_array().as_ref()[0].is_nan());
    }

    #[test]
    fn fast_min_max_return_rhs_on_nan_at_every_width() {
        check_fast_min_max::<f32x4>();
        check_fast_min_max::<f32x8>();
        check_fast_min_max::<f32x16>();
    }

    #[test]
    fn masks_and_selects_work_at_every_width() {
        check_masks::<f32x4>();
        check_masks::<f32x8>();
        check_masks::<f32x16>();
    }
}
