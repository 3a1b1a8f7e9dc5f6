//! Random spheres: `count` spheres with centres uniform in `[−1, 1]³` and radii
//! uniform in `[½, 1½]·r₀`, where `r₀ = (0.6 / (π·count))^⅓` makes them fill
//! about a tenth of the cube whatever their number (overlaps allowed). Seeded
//! with [`Rng`], so a seed names one scene. `--size` is the sphere count.

use std::f64::consts::PI;
use std::io::{self, Write};

use glam::DVec3;

use super::nff_writer::{NffWriter, Surface, phong_exponent};
use super::studio;
use crate::rng::Rng;

/// Write `count` random spheres drawn with `seed`.
pub fn write<W: Write>(count: u32, seed: u64, out: &mut NffWriter<W>) -> io::Result<()> {
    studio::write(out)?;
    out.surface(&Surface {
        color: DVec3::new(0.8, 0.6, 0.4),
        kd: 0.8,
        ks: 0.2,
        shine: phong_exponent(20.0),
        transmittance: 0.0,
        ior: 1.0,
    })?;
    let mut rng = Rng::new(seed);
    let r0 = (0.6 / (PI * f64::from(count.max(1)))).cbrt();
    for _ in 0..count {
        let center = rng.point_in(glam::Vec3::NEG_ONE, glam::Vec3::ONE).as_dvec3();
        let radius = r0 * f64::from(rng.range(0.5, 1.5));
        out.sphere(center, radius)?;
    }
    Ok(())
}
