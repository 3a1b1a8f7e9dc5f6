//! Random triangles: `count` triangles with centres uniform in `[−1, 1]³` and
//! corners at distance `s = ½·(8/count)^⅓` from the centre in uniform random
//! directions (on the sphere of radius `s` about it), so they stay about as large as their share of the cube. A
//! triangle thinner than 1% of `s²` in area is drawn again, so every triangle
//! has a well-defined plane. Seeded with [`Rng`]. `--size` is the triangle count.

use std::io::{self, Write};

use glam::DVec3;

use super::nff_writer::{NffWriter, Surface, phong_exponent};
use super::studio;
use crate::rng::Rng;

/// Write `count` random triangles drawn with `seed`.
pub fn write<W: Write>(count: u32, seed: u64, out: &mut NffWriter<W>) -> io::Result<()> {
    studio::write(out)?;
    out.surface(&Surface {
        color: DVec3::new(0.4, 0.6, 0.8),
        kd: 0.9,
        ks: 0.0,
        shine: phong_exponent(0.0),
        transmittance: 0.0,
        ior: 1.0,
    })?;
    let mut rng = Rng::new(seed);
    let s = 0.5 * (8.0 / f64::from(count.max(1))).cbrt();
    for _ in 0..count {
        let center = rng.point_in(glam::Vec3::NEG_ONE, glam::Vec3::ONE).as_dvec3();
        let corners = loop {
            let c: [DVec3; 3] = std::array::from_fn(|_| center + s * rng.unit_vector().as_dvec3());
            // Twice the area is |(b − a) × (c − a)|.
            if (c[1] - c[0]).cross(c[2] - c[0]).length() >= 0.02 * s * s {
                break c;
            }
        };
        out.polygon(&corners)?;
    }
    Ok(())
}
