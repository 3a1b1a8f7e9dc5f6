//! Terrain: a height field over `[−1, 1]²` of `2^level × 2^level` cells (2
//! triangles each, `2·4^level` in all), grown with the diamond-square algorithm
//! (A. Fournier, D. Fussell & L. Carpenter, "Computer Rendering of Stochastic
//! Models", CACM 25(6), 1982; G. S. P. Miller, "The Definition and Rendering of
//! Terrain Maps", SIGGRAPH 1986) from a seeded [`Rng`]: unlike the SPD mountain
//! it has no repeating hash and grows to any size. `--size` is the level:
//! 6 → 8192 triangles, 9 → 524,288, 10 → 2,097,152.

use std::io::{self, Write};

use glam::DVec3;

use super::nff_writer::{NffWriter, SKY_BLUE, Surface, View};
use crate::rng::Rng;

/// Offset amplitude of the first level, in height units.
const AMPLITUDE: f64 = 0.5;

/// Hurst exponent: each pass scales the offsets by `2^−H` (rougher for smaller `H`).
const HURST: f64 = 0.8;

/// Primitives for `level`.
pub fn primitive_count(level: u32) -> u64 {
    2 * 4u64.pow(level)
}

/// Write the terrain of `level` grown with `seed`.
pub fn write<W: Write>(level: u32, seed: u64, out: &mut NffWriter<W>) -> io::Result<()> {
    out.background(SKY_BLUE)?;
    out.view(&View::towards_origin(DVec3::new(-1.6, 1.6, 1.7)))?;
    out.light(DVec3::new(-100.0, -100.0, 100.0))?;
    out.surface(&Surface::matte(DVec3::new(0.45, 0.5, 0.35)))?;
    let n = 1usize << level;
    let heights = diamond_square(n, &mut Rng::new(seed));
    let point = |x: usize, y: usize| {
        let at = |i: usize| -1.0 + 2.0 * i as f64 / n as f64;
        DVec3::new(at(x), at(y), heights[y * (n + 1) + x])
    };
    for y in 0..n {
        for x in 0..n {
            let (ll, lr, ur, ul) = (point(x, y), point(x + 1, y), point(x + 1, y + 1), point(x, y + 1));
            out.polygon(&[ll, lr, ur])?;
            out.polygon(&[ur, ul, ll])?;
        }
    }
    Ok(())
}

/// Heights at the `(n+1)²` grid points, row by row; corners at 0. Each pass
/// sets the centres of the current squares (the mean of 4 corners), then the
/// midpoints of their edges (the mean of their up to 4 diamond neighbours),
/// each plus a uniform offset whose amplitude shrinks by `2^−H` per pass.
fn diamond_square(n: usize, rng: &mut Rng) -> Vec<f64> {
    let stride = n + 1;
    let mut h = vec![0.0; stride * stride];
    let decay = 2f64.powf(-HURST);
    let mut amplitude = AMPLITUDE;
    let mut step = n;
    while step > 1 {
        let half = step / 2;
        // Square step: square centres.
        for y in (half..n).step_by(step) {
            for x in (half..n).step_by(step) {
                let mean = (h[(y - half) * stride + x - half]
                    + h[(y - half) * stride + x + half]
                    + h[(y + half) * stride + x - half]
                    + h[(y + half) * stride + x + half])
                    / 4.0;
                h[y * stride + x] = mean + amplitude * f64::from(rng.range(-1.0, 1.0));
            }
        }
        // Diamond step: edge midpoints, on odd multiples of `half` in x or y.
        for y in (0..=n).step_by(half) {
            let first = if (y / half).is_multiple_of(2) { half } else { 0 };
            for x in (first..=n).step_by(step) {
                let neighbours = [
                    (x >= half).then(|| h[y * stride + x - half]),
                    (x + half <= n).then(|| h[y * stride + x + half]),
                    (y >= half).then(|| h[(y - half) * stride + x]),
                    (y + half <= n).then(|| h[(y + half) * stride + x]),
                ];
                let (sum, count) = neighbours
                    .iter()
                    .flatten()
                    .fold((0.0, 0.0), |(s, c), v| (s + v, c + 1.0));
                h[y * stride + x] = sum / count + amplitude * f64::from(rng.range(-1.0, 1.0));
            }
        }
        amplitude *= decay;
        step = half;
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_grid_point_is_set_and_corners_stay_flat() {
        let n = 16;
        let h = diamond_square(n, &mut Rng::new(3));
        let stride = n + 1;
        for corner in [0, n, n * stride, n * stride + n] {
            assert_eq!(h[corner], 0.0);
        }
        let nonzero = h.iter().filter(|v| **v != 0.0).count();
        assert_eq!(nonzero, h.len() - 4, "all but the corners get an offset");
        assert!(h.iter().all(|v| v.abs() < 2.0));
    }
}
