//! [`SimdFloat`] for the `wide` crate's vectors: the portable lane types, whose
//! instructions are chosen when the crate is compiled (SSE2 on a baseline
//! x86-64 build, NEON on aarch64). They are the instruction set
//! [`Isa::Portable`](super::Isa::Portable) and the storage of the packets
//! callers build.

use wide::{f32x4, f32x8, f32x16, u32x4, u32x8, u32x16};

use crate::simd::{SimdFloat, SimdU32};

/// `op` of `a` and `b` lane by lane: the scalar rule of an operation the
/// portable lanes have no instruction for.
#[inline(always)]
fn lanewise<const N: usize>(mut a: [f32; N], b: [f32; N], op: impl Fn(f32, f32) -> f32) -> [f32; N] {
    for (x, y) in a.iter_mut().zip(b) {
        *x = op(*x, y);
    }
    a
}

macro_rules! impl_simd_float {
    ($f:ident, $u:ident, $n:literal) => {
        // SAFETY: `wide`'s vectors are `$n` plain f32 (u32) lanes in lane order.
        unsafe impl SimdFloat for $f {
            const LANES: usize = $n;
            type U32 = $u;
            type Array = [f32; $n];
            type Lanes8 = f32x8;

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
                // x86 `minps` is the rule itself. Elsewhere `wide` follows the
                // target's (NEON's `fmin` returns the NaN, and a ray lying in
                // a box face would miss it), so the rule is spelled out: a
                // comparison with a NaN is false and picks `rhs`.
                if cfg!(target_arch = "x86_64") {
                    $f::fast_min(self, rhs)
                } else {
                    SimdFloat::lt(self, rhs).select(self, rhs)
                }
            }
            #[inline(always)]
            fn fast_max(self, rhs: Self) -> Self {
                if cfg!(target_arch = "x86_64") {
                    $f::fast_max(self, rhs)
                } else {
                    SimdFloat::gt(self, rhs).select(self, rhs)
                }
            }
            #[inline(always)]
            fn max_bits(self, rhs: Self) -> Self {
                $f::new(lanewise(
                    self.to_array(),
                    rhs.to_array(),
                    crate::simd::max_bits,
                ))
            }
            #[inline(always)]
            fn min_bits(self, rhs: Self) -> Self {
                $f::new(lanewise(
                    self.to_array(),
                    rhs.to_array(),
                    crate::simd::min_bits,
                ))
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

        // SAFETY: as above.
        unsafe impl SimdU32 for $u {
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
