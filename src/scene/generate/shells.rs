//! SPD `shells` (E. Haines, after C. Pickover's seashells, IEEE CG&A 9(6),
//! 1989): a conical spiral of overlapping spheres that grow exponentially along
//! it, one light. Many tiny and overlapping primitives make it a pathological
//! case for acceleration structures.
//!
//! With `s = 180·2^n` steps per unit of the sweep, sphere `i` (for
//! `−2s/3 ≤ i ≤ s/3`) sits at angle `θ = 18π·i/s` on the logarithmic spiral
//! `r = e^(0.15·θ)`, at `(r·sin θ, r·cos θ, −2r)`, with radius `r`: nine turns,
//! the spheres shrinking towards the tip. Size factor `n` gives `s + 1` spheres:
//! 1 → 361, 2 → 721, 5 → 5761 (the SPD default), 10 → 184,321.

use std::f64::consts::PI;
use std::io::{self, Write};

use glam::DVec3;

use super::nff_writer::{NffWriter, Surface, View, phong_exponent};

/// Growth rate of the spiral per radian.
const GROWTH: f64 = 0.15;

/// Primitives for size factor `size`: the spheres.
pub fn primitive_count(size: u32) -> u64 {
    180 * (1u64 << size) + 1
}

/// Write the scene for size factor `size`.
pub fn write<W: Write>(size: u32, out: &mut NffWriter<W>) -> io::Result<()> {
    // Step 1: background, camera, one light.
    out.background(DVec3::new(0.078, 0.361, 0.753))?;
    out.view(&View {
        from: DVec3::new(-6.0, -60.0, 35.0),
        at: DVec3::new(0.0, 8.0, -15.0),
        up: DVec3::Z,
        angle: 45.0,
        hither: 0.5,
        resolution: [512, 512],
    })?;
    out.light(DVec3::new(-100.0, -100.0, 100.0))?;

    // Step 2: one slightly reflective shell colour, then the spheres along the spiral.
    out.surface(&Surface {
        color: DVec3::new(1.0, 0.8, 0.4),
        kd: 0.8,
        ks: 0.2,
        shine: phong_exponent(5.0),
        transmittance: 0.0,
        ior: 1.0,
    })?;
    let steps = 180 * (1i64 << size);
    for i in -2 * steps / 3..=steps / 3 {
        let angle = 18.0 * PI * i as f64 / steps as f64;
        let r = (GROWTH * angle).exp();
        out.sphere(DVec3::new(r * angle.sin(), r * angle.cos(), -2.0 * r), r)?;
    }
    Ok(())
}
