//! Each x86 lane type computes every [`SimdFloat`] operation as the `wide`
//! type of its width does, bit for bit, on random values mixed with the
//! special ones (NaN, ±0, ±∞, subnormals, ±f32::MAX), so kernels written
//! against the trait give the same bits on every instruction set (#18).
//! Types whose instructions this CPU lacks are skipped, and the test says so.

#![cfg(target_arch = "x86_64")]

use raypack::rng::Rng;
use raypack::simd::x86::{Avx8, Avx8Vl, Avx8x2, Avx16, Sse4, Sse8};
use raypack::simd::{Isa, SimdFloat, SimdU32};
use wide::{f32x4, f32x8, f32x16};

const SPECIAL: [f32; 12] = [
    f32::NAN,
    0.0,
    -0.0,
    f32::INFINITY,
    f32::NEG_INFINITY,
    1e-40,
    -1e-40,
    f32::MAX,
    f32::MIN,
    1.0,
    -1.0,
    f32::MIN_POSITIVE,
];

fn value(rng: &mut Rng) -> f32 {
    if rng.below(3) == 0 {
        SPECIAL[rng.below(SPECIAL.len() as u32) as usize]
    } else {
        rng.range(-4.0, 4.0)
    }
}

fn lanes<F: SimdFloat>(rng: &mut Rng) -> F::Array {
    let mut a = F::Array::default();
    a.as_mut().iter_mut().for_each(|x| *x = value(rng));
    a
}

fn bits<F: SimdFloat>(v: F) -> Vec<u32> {
    v.to_array().as_ref().iter().map(|x| x.to_bits()).collect()
}

/// Every operation of `X` against `W`'s on 20 000 random pairs of vectors.
fn agrees<W: SimdFloat, X: SimdFloat>() {
    assert_eq!(W::LANES, X::LANES);
    let mut rng = Rng::new(W::LANES as u64);
    for _ in 0..20_000 {
        let (a, b, m) = (lanes::<W>(&mut rng), lanes::<W>(&mut rng), rng.below(u32::MAX));
        let (wa, wb) = (W::from_array(a), W::from_array(b));
        let (xa, xb): (X, X) = (wa.convert(), wb.convert());
        let (wm, xm) = (W::mask_from_bits(m), X::mask_from_bits(m));
        let same = |w: W, x: X, op: &str| assert_eq!(bits(w), bits(x), "{op} of {a:?}, {b:?}");
        same(wa + wb, xa + xb, "add");
        same(wa - wb, xa - xb, "sub");
        same(wa * wb, xa * xb, "mul");
        same(wa / wb, xa / xb, "div");
        same(-wa, -xa, "neg");
        same(wa & wb, xa & xb, "and");
        same(wa | wb, xa | xb, "or");
        same(wa ^ wb, xa ^ xb, "xor");
        same(wa.lt(wb), xa.lt(xb), "lt");
        same(wa.le(wb), xa.le(xb), "le");
        same(wa.gt(wb), xa.gt(xb), "gt");
        same(wa.ge(wb), xa.ge(xb), "ge");
        same(wa.eq(wb), xa.eq(xb), "eq");
        same(wa.ne(wb), xa.ne(xb), "ne");
        same(wm.select(wa, wb), xm.select(xa, xb), "select");
        same(wm.and_not(wa.lt(wb)), xm.and_not(xa.lt(xb)), "and_not");
        same(wa.sqrt(), xa.sqrt(), "sqrt");
        same(wa.abs(), xa.abs(), "abs");
        same(wa.min(wb), xa.min(xb), "min");
        same(wa.max(wb), xa.max(xb), "max");
        same(wa.fast_min(wb), xa.fast_min(xb), "fast_min");
        same(wa.fast_max(wb), xa.fast_max(xb), "fast_max");
        same(wa.min_bits(wb), xa.min_bits(xb), "min_bits");
        same(wa.max_bits(wb), xa.max_bits(xb), "max_bits");
        same(W::all_true(), X::all_true(), "all_true");
        same(W::splat(a.as_ref()[0]), X::splat(a.as_ref()[0]), "splat");
        same(wm, xm, "mask_from_bits");
        let lt = wa.lt(wb);
        assert_eq!(lt.bitmask(), xa.lt(xb).bitmask(), "bitmask");
        assert_eq!(
            (lt.any(), lt.none()),
            (xa.lt(xb).any(), xa.lt(xb).none()),
            "any/none"
        );
        // u32 lanes: the primitive indices a packet records.
        let (ua, ub) = ((wa ^ W::splat(f32::from_bits(m))).to_u32_mask(), wb.to_u32_mask());
        let (xua, xub): (X::U32, X::U32) = (ua.convert(), ub.convert());
        let u_same = |w: W::U32, x: X::U32, op: &str| {
            assert_eq!(w.to_array().as_ref(), x.to_array().as_ref(), "u32 {op}")
        };
        u_same(ua, xua, "convert");
        u_same(W::U32::select(wm, ua, ub), X::U32::select(xm, xua, xub), "select");
        assert_eq!(bits(ua.lt(ub)), bits(xua.lt(xub)), "u32 lt");
    }
}

#[test]
fn x86_lane_types_compute_what_wide_computes() {
    let mut skipped = Vec::new();
    if Isa::Avx2.is_available() {
        // The AVX levels' 4-lane type, and its 8-lane view.
        agrees::<f32x4, Sse4>();
        agrees::<f32x8, Sse8>();
        agrees::<f32x8, Avx8>();
        agrees::<f32x16, Avx8x2>();
    } else {
        skipped.push("avx2");
    }
    if Isa::Avx512.is_available() {
        agrees::<f32x8, Avx8Vl>();
        agrees::<f32x16, Avx16>();
    } else {
        skipped.push("avx512");
    }
    eprintln!("skipped (this CPU lacks them): {skipped:?}");
}
