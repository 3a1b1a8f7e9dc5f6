//! SPD `mount`, the fractal mountain (E. Haines, IEEE CG&A 7(11), 1987): a
//! square height field over `[−1, 1]²` grown by midpoint displacement (A.
//! Fournier, D. Fussell & L. Carpenter, "Computer Rendering of Stochastic
//! Models", CACM 25(6), 1982, extended to squares), written as 2 triangles per
//! grid cell, with a pyramid of 4 glass spheres in front of it; 1 light.
//!
//! Each square is split into four: its edge midpoints get the mean of the edge's
//! ends plus a Gaussian offset, its centre the mean of the 4 corners plus √2
//! times one; offsets scale with the square's size and a roughness derived from
//! the fractal dimension 2.2. The offsets are not drawn from a running random
//! stream but looked up by grid position, so the two squares sharing an edge
//! agree on it (no cracks). To reproduce the published scene (and its published
//! ray statistics) this uses the SPD's own position hash, faults included
//! (it repeats), and its portable Gaussian generator, the polar method over the
//! linear congruential generator `x ← (8121·x + 28411) mod 134456` (W. H. Press
//! et al., "Numerical Recipes in C", 1988, §7.1–7.2). `--seed` picks the
//! mountain, as the SPD's mountain number does (default 21, the published one).
//!
//! Size factor `n` gives a `2^(n+2)` square grid, `2·4^(n+2)` triangles plus
//! the 4 spheres: 1 → 128+4, 4 → 8192+4 (the classic scene), 8 → 2,097,152+4.
//! (SPD 3.x counts the same scenes with factors 2 higher: its 6 is this 4.)
//! The SPD hash is defined up to a 128 grid (factor 5); beyond, its shifts
//! become floor divisions, which leaves factors up to 5 unchanged.

use std::f64::consts::TAU;
use std::io::{self, Write};

use glam::{DMat3, DVec3};

use super::nff_writer::{NffWriter, SKY_BLUE, Surface, View, phong_exponent};

/// The mountain the SPD publishes.
pub const DEFAULT_MOUNTAIN: u64 = 21;

/// Largest mountain number: the Gaussian generator's seeds (mountain plus a
/// 16-bit hash) must stay below its modulus to avoid repeating.
pub const MAX_MOUNTAIN: u64 = MODULUS as u64 - 1 - 0xffff;

/// Fractal dimension of the surface, between 2 and 3.
const FRACTAL_DIMENSION: f64 = 2.2;

/// Lower-left corner and width of the height field, in x and y.
const CORNER: f64 = -1.0;
const WIDTH: f64 = 2.0;

/// The Numerical Recipes portable generator: modulus, multiplier, increment.
const MODULUS: i64 = 134_456;
const MULTIPLIER: i64 = 8121;
const INCREMENT: i64 = 28_411;

/// Primitives for size factor `size`.
pub fn primitive_count(size: u32) -> u64 {
    2 * 4u64.pow(size + 2) + 4
}

/// Write the scene for size factor `size` and mountain number `mountain`.
pub fn write<W: Write>(size: u32, mountain: u64, out: &mut NffWriter<W>) -> io::Result<()> {
    out.background(SKY_BLUE)?;
    out.view(&View::towards_origin(DVec3::new(-1.6, 1.6, 1.7)))?;
    out.light(DVec3::new(-100.0, -100.0, 100.0))?;
    // Clear crystal: mostly transmitting, a little mirror, a sharp highlight.
    out.surface(&Surface {
        color: DVec3::ONE,
        kd: 0.1,
        ks: 0.1,
        shine: phong_exponent(6.7),
        transmittance: 0.9,
        ior: 1.5,
    })?;
    crystal_pyramid(out, DVec3::new(-0.8, 0.8, 1.0), 0.17)?;
    out.surface(&Surface::matte(DVec3::new(0.5, 0.45, 0.35)))?;
    let level = size + 2;
    let cells = 1u32 << level;
    // Carpenter's roughness for the fractal dimension: the offset scale that
    // halving a square multiplies the variance by.
    let ratio = 2.0 / (2f64.ln() / (FRACTAL_DIMENSION - 1.0)).exp();
    let field = HeightField {
        cells: cells as f64,
        level,
        mountain: mountain as i64,
        roughness: (ratio * ratio - 1.0).sqrt(),
    };
    field.grow(out, cells, [0, 0], [0.0; 4])
}

/// Four touching spheres of radius `r` stacked as a tetrahedron around `center`:
/// the top one first, then the three below it.
fn crystal_pyramid<W: Write>(out: &mut NffWriter<W>, center: DVec3, r: f64) -> io::Result<()> {
    // From the centre of a regular tetrahedron of edge 2r to a vertex: r·√(3/2).
    let top = DVec3::new(0.0, 0.0, r * 1.5f64.sqrt());
    out.sphere(center + top, r)?;
    // The other vertices: the top one turned by the tetrahedral angle, then about z.
    let base = DMat3::from_axis_angle(DVec3::new(1.0, 1.0, 0.0).normalize(), (-1.0f64 / 3.0).acos()) * top;
    for i in 0..3 {
        out.sphere(center + DMat3::from_rotation_z(i as f64 * TAU / 3.0) * base, r)?;
    }
    Ok(())
}

/// The grid being grown.
struct HeightField {
    /// Cells per side, as a float.
    cells: f64,
    /// `log2` of the cells per side.
    level: u32,
    /// Mountain number (added to every hash).
    mountain: i64,
    /// Offset scale per unit of square size.
    roughness: f64,
}

impl HeightField {
    /// Grow the square of `width` cells with lower-left cell `[x, y]` and corner
    /// heights `[lower-left, lower-right, upper-right, upper-left]`, writing its
    /// triangles once it is one cell wide.
    fn grow<W: Write>(
        &self,
        out: &mut NffWriter<W>,
        width: u32,
        [x, y]: [u32; 2],
        z: [f64; 4],
    ) -> io::Result<()> {
        if width == 1 {
            let at = |i: u32| CORNER + i as f64 * WIDTH / self.cells;
            let (left, right, bottom, top) = (at(x), at(x + 1), at(y), at(y + 1));
            let ll = DVec3::new(left, bottom, z[0]);
            let lr = DVec3::new(right, bottom, z[1]);
            let ur = DVec3::new(right, top, z[2]);
            let ul = DVec3::new(left, top, z[3]);
            out.polygon(&[ll, lr, ur])?;
            return out.polygon(&[ur, ul, ll]);
        }
        let half = width / 2;
        let rise = half as f64 * WIDTH / self.cells * self.roughness;
        let offset = |px: u32, py: u32| rise * gauss(self.mountain + self.hash(px, py));
        let lower = (z[0] + z[1]) / 2.0 + offset(x + half, y);
        let right = (z[1] + z[2]) / 2.0 + offset(x + width, y + half);
        let upper = (z[2] + z[3]) / 2.0 + offset(x + half, y + width);
        let left = (z[3] + z[0]) / 2.0 + offset(x, y + half);
        let middle = (z[0] + z[1] + z[2] + z[3]) / 4.0
            + std::f64::consts::SQRT_2 * rise * gauss(self.mountain + self.hash(x + half, y + half));
        self.grow(out, half, [x, y], [z[0], lower, middle, left])?;
        self.grow(out, half, [x + half, y], [lower, z[1], right, middle])?;
        self.grow(out, half, [x + half, y + half], [middle, right, z[2], upper])?;
        self.grow(out, half, [x, y + half], [left, middle, upper, z[3]])
    }

    /// The SPD's grid-position hash: `(a·2^(23−L) + b·2^(15−L) + a·2^(7−L)) mod 2^16`
    /// for a grid of `2^L` cells, each term floored where its power is negative.
    fn hash(&self, a: u32, b: u32) -> i64 {
        let (a, b, l) = (u64::from(a), u64::from(b), self.level);
        ((((a << 23) >> l) + ((b << 15) >> l) + ((a << 7) >> l)) & 0xffff) as i64
    }
}

/// A standard normal deviate determined by `seed`: the polar method of
/// Marsaglia over pairs of the portable generator started at `seed`.
fn gauss(seed: i64) -> f64 {
    let mut x2 = seed;
    loop {
        let x1 = (INCREMENT + x2 * MULTIPLIER) % MODULUS;
        x2 = (INCREMENT + x1 * MULTIPLIER) % MODULUS;
        let v1 = x1 as f64 * 2.0 / MODULUS as f64 - 1.0;
        let v2 = x2 as f64 * 2.0 / MODULUS as f64 - 1.0;
        let r = v1 * v1 + v2 * v2;
        if r < 1.0 && r > 0.0 {
            return v1 * (-2.0 * r.ln() / r).sqrt();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hash_matches_the_spd_shifts_where_they_are_defined() {
        for level in 1..=7u32 {
            let field = HeightField {
                cells: (1u32 << level) as f64,
                level,
                mountain: 0,
                roughness: 1.0,
            };
            for (a, b) in [(0u32, 0u32), (1, 2), (37, 5), (1 << level, 3)] {
                let (a64, b64) = (u64::from(a), u64::from(b));
                let spd = ((a64 << (23 - level)) + (b64 << (15 - level)) + (a64 << (7 - level))) & 0xffff;
                assert_eq!(field.hash(a, b), spd as i64, "level {level} a {a} b {b}");
            }
        }
    }

    #[test]
    fn gauss_is_deterministic_and_roughly_standard() {
        assert_eq!(gauss(21).to_bits(), gauss(21).to_bits());
        let samples: Vec<f64> = (0..20_000).map(|s| gauss(s * 3 + 1)).collect();
        let mean = samples.iter().sum::<f64>() / samples.len() as f64;
        let var = samples.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / samples.len() as f64;
        assert!(
            mean.abs() < 0.05 && (var - 1.0).abs() < 0.1,
            "mean {mean} variance {var}"
        );
    }

    #[test]
    fn crystal_spheres_touch() {
        let mut w = NffWriter::new(Vec::new());
        crystal_pyramid(&mut w, DVec3::new(-0.8, 0.8, 1.0), 0.17).unwrap();
        let text = String::from_utf8(w.finish().unwrap()).unwrap();
        let centers: Vec<DVec3> = text
            .lines()
            .map(|l| {
                let v: Vec<f64> = l.split_whitespace().skip(1).map(|t| t.parse().unwrap()).collect();
                DVec3::new(v[0], v[1], v[2])
            })
            .collect();
        assert_eq!(centers.len(), 4);
        for i in 0..4 {
            for j in i + 1..4 {
                assert!(((centers[i] - centers[j]).length() - 0.34).abs() < 1e-5);
            }
        }
    }
}
