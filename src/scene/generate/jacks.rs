//! SPD `jacks` (A. Enzmann): a recursive jack, a little like a Menger sponge.
//! A jack is three crossed cylinders along the axes (from −0.75 to 0.75,
//! radius 0.075) with a sphere of radius 0.15 at each of the six ends; in each of
//! the eight octants between its arms sits a half-size copy, centred at
//! `(±½, ±½, ±½)` of the parent's scale, and so on down to the size factor's
//! depth. The whole is turned 30° about x and 20° about y, seen from
//! (0, 0, −8) with a 25° view, pink and shiny on dark purple, one light.
//!
//! Size factor `n` gives `9·(8ⁿ − 1)/7` primitives (3 cylinders and 6 spheres
//! per jack): 1 → 9 (the SPD default), 2 → 81, 3 → 657, 4 → 5265, 5 → 42,129.

use std::io::{self, Write};

use glam::{DMat3, DVec3};

use super::nff_writer::{NffWriter, Surface, View, phong_exponent};

/// Half length of a jack's arms at scale 1.
const ARM: f64 = 0.75;

/// Primitives for size factor `size`: nine per jack, `Σ_{d<n} 8^d` jacks.
pub fn primitive_count(size: u32) -> u64 {
    9 * ((1u64 << (3 * size)) - 1) / 7
}

/// Write the scene for size factor `size` (at least 1).
pub fn write<W: Write>(size: u32, out: &mut NffWriter<W>) -> io::Result<()> {
    // Step 1: background, camera, one light.
    out.background(DVec3::new(0.2, 0.05, 0.2))?;
    out.view(&View {
        from: DVec3::new(0.0, 0.0, -8.0),
        at: DVec3::ZERO,
        up: DVec3::Y,
        angle: 25.0,
        hither: 0.001,
        resolution: [256, 256],
    })?;
    out.light(DVec3::new(-10.0, 3.0, -20.0))?;
    out.surface(&Surface {
        color: DVec3::new(0.737, 0.561, 0.561),
        kd: 0.7,
        ks: 0.7,
        shine: phong_exponent(10.0),
        transmittance: 0.0,
        ior: 1.0,
    })?;
    // Step 2: the jacks, recursively, all in the turned frame.
    let turn = DMat3::from_rotation_x(-30f64.to_radians()) * DMat3::from_rotation_y(-20f64.to_radians());
    jack(out, &turn, DVec3::ZERO, 1.0, size)
}

/// One jack of `scale` at `center` (in the unturned frame) and its `levels − 1`
/// levels of smaller copies.
fn jack<W: Write>(
    out: &mut NffWriter<W>,
    turn: &DMat3,
    center: DVec3,
    scale: f64,
    levels: u32,
) -> io::Result<()> {
    if levels == 0 {
        return Ok(());
    }
    let arm = ARM * scale;
    let place = |p: DVec3| *turn * (center + p);
    for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
        let r = 0.1 * arm;
        out.cone(place(-arm * axis), r, place(arm * axis), r)?;
    }
    for end in [DVec3::X, DVec3::Y, DVec3::Z, -DVec3::X, -DVec3::Y, -DVec3::Z] {
        out.sphere(place(arm * end), 0.2 * arm)?;
    }
    // A half-size copy in each octant between the arms.
    for octant in 0..8 {
        let sign = |bit: u32| if octant >> bit & 1 == 1 { 0.5 } else { -0.5 };
        let offset = DVec3::new(sign(0), sign(1), sign(2)) * scale;
        jack(out, turn, center + offset, 0.5 * scale, levels - 1)?;
    }
    Ok(())
}
