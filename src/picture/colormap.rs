//! The heat map's colour scale: a piecewise-linear approximation of "inferno"
//! (S. van der Walt and N. Smith's perceptually uniform matplotlib maps, 2015),
//! dark for cheap, bright for expensive; monotonic in lightness, so it still
//! reads in grey.

use image::Rgb;

/// Control points of the scale at 0, 1/6, …, 1.
const STOPS: [[f32; 3]; 7] = [
    [0.001, 0.000, 0.014],
    [0.159, 0.042, 0.365],
    [0.397, 0.083, 0.433],
    [0.623, 0.165, 0.388],
    [0.846, 0.297, 0.236],
    [0.976, 0.557, 0.035],
    [0.988, 0.998, 0.645],
];

/// The colour of `x` in `[0, 1]` (clamped; NaN maps to 0).
pub fn heat(x: f32) -> Rgb<u8> {
    let x = if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
    let f = x * (STOPS.len() - 1) as f32;
    let i = (f as usize).min(STOPS.len() - 2);
    let w = f - i as f32;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    Rgb(std::array::from_fn(|c| {
        ((a[c] + w * (b[c] - a[c])) * 255.0).round() as u8
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scale_is_dark_to_bright_and_monotonic_in_luma() {
        let luma = |c: Rgb<u8>| 0.299 * c.0[0] as f32 + 0.587 * c.0[1] as f32 + 0.114 * c.0[2] as f32;
        let mut last = -1.0;
        for k in 0..=100 {
            let l = luma(heat(k as f32 / 100.0));
            assert!(l >= last, "luma drops at {k}");
            last = l;
        }
        assert_eq!(heat(-3.0), heat(0.0));
        assert_eq!(heat(7.0), heat(1.0));
        assert_eq!(heat(f32::NAN), heat(0.0));
        assert!(luma(heat(0.0)) < 10.0 && luma(heat(1.0)) > 200.0);
    }
}
