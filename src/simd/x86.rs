//! [`SimdFloat`] over x86 registers, with their u32 twins: [`Sse4`] and
//! [`Sse8`] (one and two SSE4.2 registers: the AVX levels' 4-lane type and
//! its 8-lane view), [`Avx8`] and [`Avx8x2`] (one and two AVX2 registers),
//! [`Avx8Vl`] (one AVX2 register, compared through AVX-512 mask registers)
//! and [`Avx16`] (one AVX-512 register).
//!
//! Every operation is an `#[inline(always)]` wrapper round one intrinsic (or a
//! few), so code generic over [`SimdFloat`] becomes straight vector code once
//! it is inlined into a function compiled for the instruction set
//! (`#[target_feature]`). The types are only used inside such functions
//! (`accel::bvh::dispatch`), which are entered after [`Isa`] checked the CPU;
//! that is what makes the `unsafe` calls below sound.
//!
//! Each operation computes what `wide`'s operation of the same name computes
//! (the same instruction, or for `min`/`max` the same NaN rule), so every
//! instruction set gives the same bits; `tests/kernel/isa.rs` holds them to it.
//!
//! [`Isa`]: super::Isa

use std::arch::x86_64::*;
use std::fmt::{self, Debug};
use std::ops::{Add, BitAnd, BitOr, BitXor, Div, Mul, Neg, Sub};

use crate::simd::{SimdFloat, SimdU32};

/// Implements [`SimdFloat`] and [`SimdU32`] for a float and a u32 vector type
/// that each wrap one register, from a table of the operations' intrinsics
/// (or the helper functions below that combine a few).
macro_rules! x86_lanes {
    (
        $(#[doc = $doc:literal])*
        $f:ident($fr:ty), $u:ident($ur:ty), $n:literal, lanes8: $lanes8:ty,
        f32: { splat: $splat:path, load: $load:path, store: $store:path,
               add: $add:path, sub: $sub:path, mul: $mul:path, div: $div:path,
               and: $and:path, or: $or:path, xor: $xor:path, andnot: $andnot:path,
               lt: $lt:path, le: $le:path, gt: $gt:path, ge: $ge:path, eq: $eq:path, ne: $ne:path,
               unordered: $unord:path, blend: $blend:path, movemask: $movemask:path,
               sqrt: $sqrt:path, min: $min:path, max: $max:path,
               min_bits: $imin:path, max_bits: $imax:path,
               to_int: $to_int:path, from_int: $from_int:path },
        u32: { splat: $usplat:path, load: $uload:path, store: $ustore:path,
               lt: $ult:path, blend: $ublend:path, from_bits: $from_bits:path }
    ) => {
        #[doc = concat!("`", stringify!($n), "` f32 lanes in one `", stringify!($fr), "`.")]
        $(#[doc = $doc])*
        #[derive(Clone, Copy)]
        #[repr(transparent)]
        pub struct $f($fr);

        #[doc = concat!("`", stringify!($n), "` u32 lanes in one `", stringify!($ur), "`.")]
        #[derive(Clone, Copy)]
        #[repr(transparent)]
        pub struct $u($ur);

        impl Debug for $f {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                write!(f, "{}({:?})", stringify!($f), self.to_array())
            }
        }

        impl Debug for $u {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                write!(f, "{}({:?})", stringify!($u), self.to_array())
            }
        }

        x86_lanes!(@binary $f, Add, add, $add);
        x86_lanes!(@binary $f, Sub, sub, $sub);
        x86_lanes!(@binary $f, Mul, mul, $mul);
        x86_lanes!(@binary $f, Div, div, $div);
        x86_lanes!(@binary $f, BitAnd, bitand, $and);
        x86_lanes!(@binary $f, BitOr, bitor, $or);
        x86_lanes!(@binary $f, BitXor, bitxor, $xor);

        impl Neg for $f {
            type Output = Self;
            /// Flips the sign bit, as `wide` does (so `-0.0` for `+0.0`).
            #[inline(always)]
            fn neg(self) -> Self {
                self ^ Self::splat(-0.0)
            }
        }

        // SAFETY: one register of `$n` plain f32 (u32) lanes, lane 0 first.
        unsafe impl SimdFloat for $f {
            const LANES: usize = $n;
            type U32 = $u;
            type Array = [f32; $n];
            type Lanes8 = $lanes8;

            #[inline(always)]
            fn splat(x: f32) -> Self {
                // SAFETY: the instruction set is present (module doc).
                Self(unsafe { $splat(x) })
            }
            #[inline(always)]
            fn from_array(a: Self::Array) -> Self {
                // SAFETY: the instruction set is present; unaligned load of `$n` floats.
                Self(unsafe { $load(a.as_ptr()) })
            }
            #[inline(always)]
            fn to_array(self) -> Self::Array {
                let mut a = [0.0; $n];
                // SAFETY: the instruction set is present; unaligned store of `$n` floats.
                unsafe { $store(a.as_mut_ptr(), self.0) };
                a
            }
            #[inline(always)]
            fn lt(self, rhs: Self) -> Self {
                // SAFETY: the instruction set is present.
                Self(unsafe { $lt(self.0, rhs.0) })
            }
            #[inline(always)]
            fn le(self, rhs: Self) -> Self {
                // SAFETY: the instruction set is present.
                Self(unsafe { $le(self.0, rhs.0) })
            }
            #[inline(always)]
            fn gt(self, rhs: Self) -> Self {
                // SAFETY: the instruction set is present.
                Self(unsafe { $gt(self.0, rhs.0) })
            }
            #[inline(always)]
            fn ge(self, rhs: Self) -> Self {
                // SAFETY: the instruction set is present.
                Self(unsafe { $ge(self.0, rhs.0) })
            }
            #[inline(always)]
            fn eq(self, rhs: Self) -> Self {
                // SAFETY: the instruction set is present.
                Self(unsafe { $eq(self.0, rhs.0) })
            }
            #[inline(always)]
            fn ne(self, rhs: Self) -> Self {
                // SAFETY: the instruction set is present.
                Self(unsafe { $ne(self.0, rhs.0) })
            }
            #[inline(always)]
            fn select(self, if_true: Self, if_false: Self) -> Self {
                // SAFETY: the instruction set is present.
                Self(unsafe { $blend(if_false.0, if_true.0, self.0) })
            }
            #[inline(always)]
            fn and_not(self, rhs: Self) -> Self {
                // SAFETY: the instruction set is present.
                Self(unsafe { $andnot(rhs.0, self.0) })
            }
            #[inline(always)]
            fn bitmask(self) -> u32 {
                // SAFETY: the instruction set is present.
                unsafe { $movemask(self.0) }
            }
            #[inline(always)]
            fn any(self) -> bool {
                self.bitmask() != 0
            }
            #[inline(always)]
            fn none(self) -> bool {
                self.bitmask() == 0
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                // SAFETY: the instruction set is present.
                Self(unsafe { $sqrt(self.0) })
            }
            #[inline(always)]
            fn abs(self) -> Self {
                self & Self::splat(f32::from_bits(i32::MAX as u32))
            }
            /// `wide`'s rule: the x86 minimum, but `self` where `rhs` is NaN.
            #[inline(always)]
            fn min(self, rhs: Self) -> Self {
                // SAFETY: the instruction set is present.
                let rhs_nan = Self(unsafe { $unord(rhs.0, rhs.0) });
                rhs_nan.select(self, self.fast_min(rhs))
            }
            /// `wide`'s rule: the x86 maximum, but `self` where `rhs` is NaN.
            #[inline(always)]
            fn max(self, rhs: Self) -> Self {
                // SAFETY: the instruction set is present.
                let rhs_nan = Self(unsafe { $unord(rhs.0, rhs.0) });
                rhs_nan.select(self, self.fast_max(rhs))
            }
            #[inline(always)]
            fn fast_min(self, rhs: Self) -> Self {
                // SAFETY: the instruction set is present.
                Self(unsafe { $min(self.0, rhs.0) })
            }
            #[inline(always)]
            fn fast_max(self, rhs: Self) -> Self {
                // SAFETY: the instruction set is present.
                Self(unsafe { $max(self.0, rhs.0) })
            }
            #[inline(always)]
            fn max_bits(self, rhs: Self) -> Self {
                // SAFETY: the instruction set is present.
                Self(unsafe { $from_int($imax($to_int(self.0), $to_int(rhs.0))) })
            }
            #[inline(always)]
            fn min_bits(self, rhs: Self) -> Self {
                // SAFETY: the instruction set is present.
                Self(unsafe { $from_int($imin($to_int(self.0), $to_int(rhs.0))) })
            }
            #[inline(always)]
            fn all_true() -> Self {
                Self::splat(f32::from_bits(u32::MAX))
            }
            #[inline(always)]
            fn mask_from_bits(bits: u32) -> Self {
                // SAFETY: the instruction set is present.
                Self(unsafe { $from_int($from_bits(bits)) })
            }
            #[inline(always)]
            fn to_u32_mask(self) -> $u {
                // SAFETY: the instruction set is present.
                $u(unsafe { $to_int(self.0) })
            }
        }

        // SAFETY: as above.
        unsafe impl SimdU32 for $u {
            type Mask = $f;
            type Array = [u32; $n];

            #[inline(always)]
            fn splat(x: u32) -> Self {
                // SAFETY: the instruction set is present.
                Self(unsafe { $usplat(x as i32) })
            }
            #[inline(always)]
            fn from_array(a: Self::Array) -> Self {
                // SAFETY: the instruction set is present; unaligned load of `$n` u32s.
                Self(unsafe { $uload(a.as_ptr().cast()) })
            }
            #[inline(always)]
            fn to_array(self) -> Self::Array {
                let mut a = [0; $n];
                // SAFETY: the instruction set is present; unaligned store of `$n` u32s.
                unsafe { $ustore(a.as_mut_ptr().cast(), self.0) };
                a
            }
            #[inline(always)]
            fn lt(self, rhs: Self) -> $f {
                // SAFETY: the instruction set is present.
                $f(unsafe { $from_int($ult(self.0, rhs.0)) })
            }
            #[inline(always)]
            fn select(mask: $f, if_true: Self, if_false: Self) -> Self {
                // SAFETY: the instruction set is present.
                Self(unsafe { $ublend(if_false.0, if_true.0, $to_int(mask.0)) })
            }
        }
    };
    (@binary $f:ident, $trait:ident, $method:ident, $intrinsic:path) => {
        impl $trait for $f {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                // SAFETY: the instruction set is present (module doc).
                Self(unsafe { $intrinsic(self.0, rhs.0) })
            }
        }
    };
}

// ---- SSE4.2: 4 lanes per register, two registers for 8 lanes ----

/// Unsigned `a < b` on 32-bit lanes (SSE has only signed compares: flip the sign bits).
#[inline(always)]
unsafe fn sse_lt_epu32(a: __m128i, b: __m128i) -> __m128i {
    // SAFETY: the caller runs with SSE4.2.
    unsafe {
        let sign = _mm_set1_epi32(i32::MIN);
        _mm_cmplt_epi32(_mm_xor_si128(a, sign), _mm_xor_si128(b, sign))
    }
}

/// Lane `i` all-ones where bit `i` of `bits` is set (lanes 0..4).
#[inline(always)]
unsafe fn sse_bits_to_lanes(bits: u32) -> __m128i {
    // SAFETY: the caller runs with SSE4.2.
    unsafe {
        let lane_bits = _mm_setr_epi32(1, 2, 4, 8);
        _mm_cmpeq_epi32(_mm_and_si128(_mm_set1_epi32(bits as i32), lane_bits), lane_bits)
    }
}

/// One bit per lane.
#[inline(always)]
unsafe fn sse_movemask(a: __m128) -> u32 {
    // SAFETY: the caller runs with SSE4.2.
    unsafe { _mm_movemask_ps(a) as u32 }
}

x86_lanes!(
    Sse4(__m128), SseU4(__m128i), 4, lanes8: Sse8,
    f32: { splat: _mm_set1_ps, load: _mm_loadu_ps, store: _mm_storeu_ps,
           add: _mm_add_ps, sub: _mm_sub_ps, mul: _mm_mul_ps, div: _mm_div_ps,
           and: _mm_and_ps, or: _mm_or_ps, xor: _mm_xor_ps, andnot: _mm_andnot_ps,
           lt: _mm_cmplt_ps, le: _mm_cmple_ps, gt: _mm_cmpgt_ps, ge: _mm_cmpge_ps,
           eq: _mm_cmpeq_ps, ne: _mm_cmpneq_ps, unordered: _mm_cmpunord_ps,
           blend: _mm_blendv_ps, movemask: sse_movemask,
           sqrt: _mm_sqrt_ps, min: _mm_min_ps, max: _mm_max_ps,
           min_bits: _mm_min_epi32, max_bits: _mm_max_epi32,
           to_int: _mm_castps_si128, from_int: _mm_castsi128_ps },
    u32: { splat: _mm_set1_epi32, load: _mm_loadu_si128, store: _mm_storeu_si128,
           lt: sse_lt_epu32, blend: _mm_blendv_epi8, from_bits: sse_bits_to_lanes }
);

/// Implements [`SimdFloat`] and [`SimdU32`] for a pair of half-width vectors
/// (`lo` holds lanes `0..n/2`), each operation done on both halves.
macro_rules! pair_lanes {
    ($f:ident, $u:ident, $half:ident, $uhalf:ident, $n:literal, lanes8: $lanes8:ty) => {
        #[doc = concat!("`", stringify!($n), "` f32 lanes in two `", stringify!($half), "`s.")]
        #[derive(Clone, Copy, Debug)]
        #[repr(C)]
        pub struct $f {
            lo: $half,
            hi: $half,
        }

        #[doc = concat!("`", stringify!($n), "` u32 lanes in two `", stringify!($uhalf), "`s.")]
        #[derive(Clone, Copy, Debug)]
        #[repr(C)]
        pub struct $u {
            lo: $uhalf,
            hi: $uhalf,
        }

        impl $f {
            #[inline(always)]
            fn both(self, rhs: Self, op: impl Fn($half, $half) -> $half) -> Self {
                Self { lo: op(self.lo, rhs.lo), hi: op(self.hi, rhs.hi) }
            }
        }

        pair_lanes!(@binary $f, Add, add);
        pair_lanes!(@binary $f, Sub, sub);
        pair_lanes!(@binary $f, Mul, mul);
        pair_lanes!(@binary $f, Div, div);
        pair_lanes!(@binary $f, BitAnd, bitand);
        pair_lanes!(@binary $f, BitOr, bitor);
        pair_lanes!(@binary $f, BitXor, bitxor);

        impl Neg for $f {
            type Output = Self;
            #[inline(always)]
            fn neg(self) -> Self {
                Self { lo: -self.lo, hi: -self.hi }
            }
        }

        // SAFETY: two plain halves in `repr(C)` order, lanes 0.. first.
        unsafe impl SimdFloat for $f {
            const LANES: usize = $n;
            type U32 = $u;
            type Array = [f32; $n];
            type Lanes8 = $lanes8;

            #[inline(always)]
            fn splat(x: f32) -> Self {
                Self { lo: $half::splat(x), hi: $half::splat(x) }
            }
            #[inline(always)]
            fn from_array(a: Self::Array) -> Self {
                let (lo, hi) = a.split_at($n / 2);
                Self {
                    lo: $half::from_array(lo.try_into().expect("half")),
                    hi: $half::from_array(hi.try_into().expect("half")),
                }
            }
            #[inline(always)]
            fn to_array(self) -> Self::Array {
                let mut a = [0.0; $n];
                a[..$n / 2].copy_from_slice(&self.lo.to_array());
                a[$n / 2..].copy_from_slice(&self.hi.to_array());
                a
            }
            #[inline(always)]
            fn lt(self, rhs: Self) -> Self {
                self.both(rhs, $half::lt)
            }
            #[inline(always)]
            fn le(self, rhs: Self) -> Self {
                self.both(rhs, $half::le)
            }
            #[inline(always)]
            fn gt(self, rhs: Self) -> Self {
                self.both(rhs, $half::gt)
            }
            #[inline(always)]
            fn ge(self, rhs: Self) -> Self {
                self.both(rhs, $half::ge)
            }
            #[inline(always)]
            fn eq(self, rhs: Self) -> Self {
                self.both(rhs, $half::eq)
            }
            #[inline(always)]
            fn ne(self, rhs: Self) -> Self {
                self.both(rhs, $half::ne)
            }
            #[inline(always)]
            fn select(self, if_true: Self, if_false: Self) -> Self {
                Self {
                    lo: self.lo.select(if_true.lo, if_false.lo),
                    hi: self.hi.select(if_true.hi, if_false.hi),
                }
            }
            #[inline(always)]
            fn and_not(self, rhs: Self) -> Self {
                self.both(rhs, $half::and_not)
            }
            #[inline(always)]
            fn bitmask(self) -> u32 {
                self.lo.bitmask() | self.hi.bitmask() << ($n / 2)
            }
            #[inline(always)]
            fn any(self) -> bool {
                (self.lo | self.hi).any()
            }
            #[inline(always)]
            fn none(self) -> bool {
                (self.lo | self.hi).none()
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                Self { lo: self.lo.sqrt(), hi: self.hi.sqrt() }
            }
            #[inline(always)]
            fn abs(self) -> Self {
                Self { lo: self.lo.abs(), hi: self.hi.abs() }
            }
            #[inline(always)]
            fn min(self, rhs: Self) -> Self {
                self.both(rhs, $half::min)
            }
            #[inline(always)]
            fn max(self, rhs: Self) -> Self {
                self.both(rhs, $half::max)
            }
            #[inline(always)]
            fn fast_min(self, rhs: Self) -> Self {
                self.both(rhs, $half::fast_min)
            }
            #[inline(always)]
            fn fast_max(self, rhs: Self) -> Self {
                self.both(rhs, $half::fast_max)
            }
            #[inline(always)]
            fn max_bits(self, rhs: Self) -> Self {
                self.both(rhs, $half::max_bits)
            }
            #[inline(always)]
            fn min_bits(self, rhs: Self) -> Self {
                self.both(rhs, $half::min_bits)
            }
            #[inline(always)]
            fn all_true() -> Self {
                Self { lo: $half::all_true(), hi: $half::all_true() }
            }
            #[inline(always)]
            fn mask_from_bits(bits: u32) -> Self {
                Self { lo: $half::mask_from_bits(bits), hi: $half::mask_from_bits(bits >> ($n / 2)) }
            }
            #[inline(always)]
            fn to_u32_mask(self) -> $u {
                $u { lo: self.lo.to_u32_mask(), hi: self.hi.to_u32_mask() }
            }
        }

        // SAFETY: as above.
        unsafe impl SimdU32 for $u {
            type Mask = $f;
            type Array = [u32; $n];

            #[inline(always)]
            fn splat(x: u32) -> Self {
                Self { lo: $uhalf::splat(x), hi: $uhalf::splat(x) }
            }
            #[inline(always)]
            fn from_array(a: Self::Array) -> Self {
                let (lo, hi) = a.split_at($n / 2);
                Self {
                    lo: $uhalf::from_array(lo.try_into().expect("half")),
                    hi: $uhalf::from_array(hi.try_into().expect("half")),
                }
            }
            #[inline(always)]
            fn to_array(self) -> Self::Array {
                let mut a = [0; $n];
                a[..$n / 2].copy_from_slice(&self.lo.to_array());
                a[$n / 2..].copy_from_slice(&self.hi.to_array());
                a
            }
            #[inline(always)]
            fn lt(self, rhs: Self) -> $f {
                $f { lo: self.lo.lt(rhs.lo), hi: self.hi.lt(rhs.hi) }
            }
            #[inline(always)]
            fn select(mask: $f, if_true: Self, if_false: Self) -> Self {
                Self {
                    lo: $uhalf::select(mask.lo, if_true.lo, if_false.lo),
                    hi: $uhalf::select(mask.hi, if_true.hi, if_false.hi),
                }
            }
        }
    };
    (@binary $f:ident, $trait:ident, $method:ident) => {
        impl $trait for $f {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                self.both(rhs, $trait::$method)
            }
        }
    };
}

pair_lanes!(Sse8, SseU8, Sse4, SseU4, 8, lanes8: Sse8);

// ---- AVX2: 8 lanes per register ----

/// Compares with the predicates `wide` uses (ordered, but unordered for `!=`).
macro_rules! avx_compares {
    ($($name:ident: $predicate:ident),*) => {$(
        #[inline(always)]
        unsafe fn $name(a: __m256, b: __m256) -> __m256 {
            // SAFETY: the caller runs with AVX2.
            unsafe { _mm256_cmp_ps::<$predicate>(a, b) }
        }
    )*};
}

avx_compares!(
    avx_lt: _CMP_LT_OQ, avx_le: _CMP_LE_OQ, avx_gt: _CMP_GT_OQ, avx_ge: _CMP_GE_OQ,
    avx_eq: _CMP_EQ_OQ, avx_ne: _CMP_NEQ_UQ, avx_unordered: _CMP_UNORD_Q
);

/// Unsigned `a < b` on 32-bit lanes (flip the sign bits, compare signed).
#[inline(always)]
unsafe fn avx_lt_epu32(a: __m256i, b: __m256i) -> __m256i {
    // SAFETY: the caller runs with AVX2.
    unsafe {
        let sign = _mm256_set1_epi32(i32::MIN);
        _mm256_cmpgt_epi32(_mm256_xor_si256(b, sign), _mm256_xor_si256(a, sign))
    }
}

/// Lane `i` all-ones where bit `i` of `bits` is set (lanes 0..8).
#[inline(always)]
unsafe fn avx_bits_to_lanes(bits: u32) -> __m256i {
    // SAFETY: the caller runs with AVX2.
    unsafe {
        let lane_bits = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
        _mm256_cmpeq_epi32(
            _mm256_and_si256(_mm256_set1_epi32(bits as i32), lane_bits),
            lane_bits,
        )
    }
}

/// One bit per lane.
#[inline(always)]
unsafe fn avx_movemask(a: __m256) -> u32 {
    // SAFETY: the caller runs with AVX2.
    unsafe { _mm256_movemask_ps(a) as u32 }
}

/// [`x86_lanes!`] for a type of one `__m256` (its own 8-lane type): AVX2's
/// arithmetic, loads and stores, with the compares, bit mask, u32 compare and
/// lane mask given (AVX2's, or AVX-512VL's through mask registers).
macro_rules! avx256_lanes {
    (
        $(#[doc = $doc:literal])*
        $f:ident, $u:ident,
        compares: { lt: $lt:path, le: $le:path, gt: $gt:path, ge: $ge:path, eq: $eq:path,
                    ne: $ne:path, unordered: $unord:path, movemask: $movemask:path },
        u32: { lt: $ult:path, from_bits: $from_bits:path }
    ) => {
        x86_lanes!(
            $(#[doc = $doc])*
            $f(__m256), $u(__m256i), 8, lanes8: $f,
            f32: { splat: _mm256_set1_ps, load: _mm256_loadu_ps, store: _mm256_storeu_ps,
                   add: _mm256_add_ps, sub: _mm256_sub_ps, mul: _mm256_mul_ps, div: _mm256_div_ps,
                   and: _mm256_and_ps, or: _mm256_or_ps, xor: _mm256_xor_ps, andnot: _mm256_andnot_ps,
                   lt: $lt, le: $le, gt: $gt, ge: $ge, eq: $eq, ne: $ne,
                   unordered: $unord, blend: _mm256_blendv_ps, movemask: $movemask,
                   sqrt: _mm256_sqrt_ps, min: _mm256_min_ps, max: _mm256_max_ps,
                   min_bits: _mm256_min_epi32, max_bits: _mm256_max_epi32,
                   to_int: _mm256_castps_si256, from_int: _mm256_castsi256_ps },
            u32: { splat: _mm256_set1_epi32, load: _mm256_loadu_si256, store: _mm256_storeu_si256,
                   lt: $ult, blend: _mm256_blendv_epi8, from_bits: $from_bits }
        );
    };
}

avx256_lanes!(
    Avx8, AvxU8,
    compares: { lt: avx_lt, le: avx_le, gt: avx_gt, ge: avx_ge, eq: avx_eq, ne: avx_ne,
                unordered: avx_unordered, movemask: avx_movemask },
    u32: { lt: avx_lt_epu32, from_bits: avx_bits_to_lanes }
);

pair_lanes!(Avx8x2, AvxU8x2, Avx8, AvxU8, 16, lanes8: Avx8);

// ---- AVX-512: 16 lanes per register; compares give bit masks, widened to lanes ----

/// Compares with `wide`'s predicates into a mask register (`$compare`),
/// widened to all-ones lanes (`$widen`, then `$cast` back to floats): of 16
/// lanes ([`Avx16`]) or, with VL, of 8 ([`Avx8Vl`]).
macro_rules! mask_compares {
    ($vector:ty, $compare:ident, $widen:ident, $cast:ident: $($name:ident: $predicate:ident),*) => {$(
        #[inline(always)]
        unsafe fn $name(a: $vector, b: $vector) -> $vector {
            // SAFETY: the caller runs with AVX-512 F and DQ (and VL for 8 lanes).
            unsafe { $cast($widen($compare::<$predicate>(a, b))) }
        }
    )*};
}

mask_compares!(
    __m512, _mm512_cmp_ps_mask, _mm512_movm_epi32, _mm512_castsi512_ps:
    avx512_lt: _CMP_LT_OQ, avx512_le: _CMP_LE_OQ, avx512_gt: _CMP_GT_OQ, avx512_ge: _CMP_GE_OQ,
    avx512_eq: _CMP_EQ_OQ, avx512_ne: _CMP_NEQ_UQ, avx512_unordered: _CMP_UNORD_Q
);

/// The bit mask of a lane mask (its lanes' sign bits).
#[inline(always)]
unsafe fn avx512_movemask(a: __m512) -> u32 {
    // SAFETY: the caller runs with AVX-512 DQ.
    unsafe { u32::from(_mm512_movepi32_mask(_mm512_castps_si512(a))) }
}

/// `blendv`: lanes of `if_true` where the mask's sign bit is set.
#[inline(always)]
unsafe fn avx512_blend(if_false: __m512, if_true: __m512, mask: __m512) -> __m512 {
    // SAFETY: the caller runs with AVX-512 F and DQ.
    unsafe { _mm512_mask_blend_ps(_mm512_movepi32_mask(_mm512_castps_si512(mask)), if_false, if_true) }
}

/// `blendv` on u32 lanes.
#[inline(always)]
unsafe fn avx512_blend_epi32(if_false: __m512i, if_true: __m512i, mask: __m512i) -> __m512i {
    // SAFETY: the caller runs with AVX-512 F and DQ.
    unsafe { _mm512_mask_blend_epi32(_mm512_movepi32_mask(mask), if_false, if_true) }
}

/// Unsigned `a < b` on 32-bit lanes, as all-ones lanes.
#[inline(always)]
unsafe fn avx512_lt_epu32(a: __m512i, b: __m512i) -> __m512i {
    // SAFETY: the caller runs with AVX-512 F and DQ.
    unsafe { _mm512_movm_epi32(_mm512_cmplt_epu32_mask(a, b)) }
}

/// Lane `i` all-ones where bit `i` of `bits` is set (lanes 0..16).
#[inline(always)]
unsafe fn avx512_bits_to_lanes(bits: u32) -> __m512i {
    // SAFETY: the caller runs with AVX-512 DQ.
    unsafe { _mm512_movm_epi32(bits as u16) }
}

/// Loads 16 u32 lanes (the intrinsic takes a pointer to `i32`s).
#[inline(always)]
unsafe fn avx512_load_epi32(p: *const __m512i) -> __m512i {
    // SAFETY: the caller runs with AVX-512 F and passes 64 readable bytes.
    unsafe { _mm512_loadu_si512(p) }
}

/// Stores 16 u32 lanes.
#[inline(always)]
unsafe fn avx512_store_epi32(p: *mut __m512i, a: __m512i) {
    // SAFETY: the caller runs with AVX-512 F and passes 64 writable bytes.
    unsafe { _mm512_storeu_si512(p, a) }
}

x86_lanes!(
    Avx16(__m512), AvxU16(__m512i), 16, lanes8: Avx8Vl,
    f32: { splat: _mm512_set1_ps, load: _mm512_loadu_ps, store: _mm512_storeu_ps,
           add: _mm512_add_ps, sub: _mm512_sub_ps, mul: _mm512_mul_ps, div: _mm512_div_ps,
           and: _mm512_and_ps, or: _mm512_or_ps, xor: _mm512_xor_ps, andnot: _mm512_andnot_ps,
           lt: avx512_lt, le: avx512_le, gt: avx512_gt, ge: avx512_ge, eq: avx512_eq, ne: avx512_ne,
           unordered: avx512_unordered, blend: avx512_blend, movemask: avx512_movemask,
           sqrt: _mm512_sqrt_ps, min: _mm512_min_ps, max: _mm512_max_ps,
           min_bits: _mm512_min_epi32, max_bits: _mm512_max_epi32,
           to_int: _mm512_castps_si512, from_int: _mm512_castsi512_ps },
    u32: { splat: _mm512_set1_epi32, load: avx512_load_epi32, store: avx512_store_epi32,
           lt: avx512_lt_epu32, blend: avx512_blend_epi32, from_bits: avx512_bits_to_lanes }
);

// ---- AVX-512VL: 8 lanes per register, compares through mask registers ----

// A bit mask taken of these compares ([`SimdFloat::bitmask`]) is the
// compare's own mask register: two 8-lane halves' masks join in mask or
// general registers, where LLVM fused AVX2's `movemask`s of two halves into
// one 512-bit instruction (see [`Avx8Vl`]).
mask_compares!(
    __m256, _mm256_cmp_ps_mask, _mm256_movm_epi32, _mm256_castsi256_ps:
    avx512vl_lt: _CMP_LT_OQ, avx512vl_le: _CMP_LE_OQ, avx512vl_gt: _CMP_GT_OQ,
    avx512vl_ge: _CMP_GE_OQ, avx512vl_eq: _CMP_EQ_OQ, avx512vl_ne: _CMP_NEQ_UQ,
    avx512vl_unordered: _CMP_UNORD_Q
);

/// The bit mask of a lane mask (its lanes' sign bits), in a mask register.
#[inline(always)]
unsafe fn avx512vl_movemask(a: __m256) -> u32 {
    // SAFETY: the caller runs with AVX-512 VL and DQ.
    unsafe { u32::from(_mm256_movepi32_mask(_mm256_castps_si256(a))) }
}

/// Unsigned `a < b` on 32-bit lanes, as all-ones lanes.
#[inline(always)]
unsafe fn avx512vl_lt_epu32(a: __m256i, b: __m256i) -> __m256i {
    // SAFETY: the caller runs with AVX-512 F, VL and DQ.
    unsafe { _mm256_movm_epi32(_mm256_cmplt_epu32_mask(a, b)) }
}

/// Lane `i` all-ones where bit `i` of `bits` is set (lanes 0..8).
#[inline(always)]
unsafe fn avx512vl_bits_to_lanes(bits: u32) -> __m256i {
    // SAFETY: the caller runs with AVX-512 VL and DQ.
    unsafe { _mm256_movm_epi32(bits as u8) }
}

avx256_lanes!(
    /// The AVX-512 level's 8-lane type: AVX2's arithmetic, AVX-512VL's
    /// compares into mask registers. With [`Avx8`] the 16-wide node test of
    /// single rays, in two halves, ran one 512-bit instruction a visit
    /// (LLVM's fusion of the halves' `movemask`s), which on an Intel Xeon
    /// slowed single rays by about a fifth (`docs/measurements.md`,
    /// "Instruction sets at run time").
    Avx8Vl, AvxU8Vl,
    compares: { lt: avx512vl_lt, le: avx512vl_le, gt: avx512vl_gt, ge: avx512vl_ge,
                eq: avx512vl_eq, ne: avx512vl_ne, unordered: avx512vl_unordered,
                movemask: avx512vl_movemask },
    u32: { lt: avx512vl_lt_epu32, from_bits: avx512vl_bits_to_lanes }
);
