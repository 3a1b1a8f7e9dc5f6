//! The SIMD lane types behind ray packets, and the instruction set they run on.
//!
//! [`SimdFloat`] is the one trait the packet kernels are written against, so
//! the packet width and the instructions are a type parameter: `RayPacket<F>`
//! with `F` one of
//! - the `wide` crate's `f32x4`, `f32x8`, `f32x16` ([`portable`]): whatever the
//!   crate was compiled for; the types callers build packets with;
//! - the x86 types of [`x86`] (`Sse4`, `Avx8`, `Avx8Vl`, `Avx16`): SSE4.2, AVX2 and
//!   AVX-512 instructions, used only inside functions compiled for them and
//!   entered after the CPU was checked ([`Isa`], chosen at run time).
//!
//! A *mask* is a float vector whose lanes are all-ones (true) or all-zeros
//! (false), as returned by the comparisons.

pub mod isa;
pub mod portable;
#[cfg(target_arch = "x86_64")]
pub mod x86;

use std::fmt::Debug;
use std::ops::{Add, BitAnd, BitOr, BitXor, Div, Mul, Neg, Sub};

pub use isa::Isa;

/// The storage of 8 lanes: leaf blocks hold their constants as this type's
/// arrays, and every instruction set reads them with its own 8-lane type
/// ([`SimdFloat::Lanes8`]); wide nodes are read in parts of that type too
/// (`accel::bvh::wide`). Blocks and nodes are as wide on every machine, so
/// one tree serves every instruction set.
pub type NodeLanes = wide::f32x8;

/// A [`SimdFloat`] of 8 lanes: what single rays test wide nodes and leaf blocks with.
pub trait Simd8: SimdFloat<Array = [f32; 8]> {}

impl<T: SimdFloat<Array = [f32; 8]>> Simd8 for T {}

/// A vector of `LANES` f32 lanes, with its lane-matched u32 vector.
///
/// # Safety
/// An implementor is plain data: exactly `LANES` f32 lanes in lane order
/// (`4 · LANES` bytes, any bit pattern valid), so that packets of two types of
/// one width are converted by copying their bytes ([`RayPacket::convert`]).
///
/// [`RayPacket::convert`]: crate::packet::RayPacket::convert
pub unsafe trait SimdFloat:
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
    /// The 8-lane type of the same instruction set, for the wide-node and
    /// leaf-block tests a packet's lanes do as single rays.
    type Lanes8: Simd8;

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
    /// Lane-wise maximum of the lanes' bits read as signed integers (x86
    /// `pmaxsd`, one cycle where `maxps` takes four on Intel cores): the float
    /// maximum wherever it is ≥ +0, and below every lane ≥ +0 any negative
    /// lane, −0 and x86's default NaN (negative). The BVH's slab entry, whose
    /// floor is `t_min`, relies on this.
    fn max_bits(self, rhs: Self) -> Self;
    /// Lane-wise minimum of the lanes' bits read as signed integers (`pminsd`):
    /// the float minimum where both lanes are ≥ +0; a positive NaN lane is
    /// above +∞, so it never wins.
    fn min_bits(self, rhs: Self) -> Self;
    /// The mask with every lane set.
    fn all_true() -> Self;
    /// The mask with lane `i` set where bit `i` of `bits` is.
    fn mask_from_bits(bits: u32) -> Self;
    /// The mask reinterpreted as a u32 mask of the same lanes.
    fn to_u32_mask(self) -> Self::U32;

    /// The same lanes as another type of the same width (another instruction
    /// set's), bit for bit.
    #[inline(always)]
    fn convert<G: SimdFloat>(self) -> G {
        debug_assert_eq!(G::LANES, Self::LANES);
        let mut lanes = G::Array::default();
        lanes.as_mut().copy_from_slice(self.to_array().as_ref());
        G::from_array(lanes)
    }
}

/// A vector of u32 lanes, matched lane for lane to a [`SimdFloat`].
///
/// # Safety
/// As [`SimdFloat`]: plain data, exactly its `LANES` u32 lanes in lane order.
pub unsafe trait SimdU32: Copy + Debug + Send + Sync + 'static {
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

    /// The same lanes as another type of the same width, bit for bit.
    #[inline(always)]
    fn convert<G: SimdU32>(self) -> G {
        let mut lanes = G::Array::default();
        lanes.as_mut().copy_from_slice(self.to_array().as_ref());
        G::from_array(lanes)
    }
}

/// [`SimdFloat::max_bits`] of one lane: the larger of the bits read as `i32`.
#[inline(always)]
pub fn max_bits(a: f32, b: f32) -> f32 {
    if (a.to_bits() as i32) > (b.to_bits() as i32) {
        a
    } else {
        b
    }
}

/// [`SimdFloat::min_bits`] of one lane: the smaller of the bits read as `i32`.
#[inline(always)]
pub fn min_bits(a: f32, b: f32) -> f32 {
    if (a.to_bits() as i32) < (b.to_bits() as i32) {
        a
    } else {
        b
    }
}

/// A 3-vector of SIMD lanes (structure of arrays): lane `i` of `x, y, z` is one vector.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
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
    #[inline(always)]
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
    use wide::{f32x4, f32x8, f32x16};

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

    fn check_min_max_bits<F: SimdFloat>() {
        let lane = |v: F| v.to_array().as_ref()[0].to_bits();
        let pairs = [(1.0, 2.0), (0.0, 3.5), (f32::INFINITY, 7.0), (1e-40, 1e-39)];
        for (a, b) in pairs {
            // On lanes ≥ +0, the float minimum and maximum.
            let (fa, fb) = (F::splat(a), F::splat(b));
            assert_eq!(lane(fa.min_bits(fb)), a.min(b).to_bits(), "{a} {b}");
            assert_eq!(lane(fb.max_bits(fa)), a.max(b).to_bits(), "{a} {b}");
        }
        // Below every lane ≥ +0: negatives, −0; above +∞: a positive NaN.
        let (zero, one) = (F::splat(0.0), F::splat(1.0));
        for below in [-1.0, -0.0, f32::NEG_INFINITY] {
            assert_eq!(lane(F::splat(below).max_bits(zero)), 0, "{below}");
            assert_eq!(lane(one.min_bits(F::splat(below))), below.to_bits(), "{below}");
        }
        let nan = F::splat(f32::from_bits(0x7fc0_0000));
        assert_eq!(
            lane(nan.min_bits(F::splat(f32::INFINITY))),
            f32::INFINITY.to_bits()
        );
        // Each lane is one of the operands, as the scalar twins pick it.
        assert_eq!(
            lane(F::splat(-2.0).max_bits(F::splat(-1.0))),
            super::max_bits(-2.0, -1.0).to_bits()
        );
    }

    #[test]
    fn min_max_bits_order_lanes_by_their_bits_at_every_width() {
        check_min_max_bits::<f32x4>();
        check_min_max_bits::<f32x8>();
        check_min_max_bits::<f32x16>();
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
