//! Random spheres: the spheres of [`random::spheres`] (centres uniform in
//! `[−1, 1]³`, radii uniform in `[0.1, 0.5]` of the cube's edge over `∛count`,
//! overlaps allowed), so `raypack gen random-spheres --size N --seed S` and the
//! scene argument `gen:spheres:N:S` hold the same spheres (up to the six
//! digits NFF prints). `--size` is the sphere count.

use std::io::{self, Write};

use glam::DVec3;

use super::nff_writer::{NffWriter, Surface, phong_exponent};
use super::random;
use super::studio;

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
    for s in random::spheres(count as usize, seed) {
        out.sphere(s.center.as_dvec3(), f64::from(s.radius))?;
    }
    Ok(())
}
