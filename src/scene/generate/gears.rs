//! SPD `gears` (E. Haines, "A Proposal for Standard Graphics Environments",
//! IEEE CG&A 7(11), 1987; the SPD 2.3 layout, which moved the gears apart so
//! they no longer interpenetrate): an `n × n × n` array of meshed gears over a
//! reflective square floor, 5 lights. One gear in five is glass (T = 0.8,
//! index 1.1), the others diffuse.
//!
//! A gear is a slab of thickness `min(0.1, 1/(2n))`: a top and a bottom face,
//! each one concave polygon of 4 vertices per tooth (36 teeth, 144 vertices;
//! the first three span a convex corner, so the NFF normal rule holds), and one
//! rectangle per outline edge around its rim, all facing outwards. Neighbouring
//! gears turn by half a tooth so their teeth interlock with a small gap (outer
//! radius 0.995 of the pitch), and the layers step down by `1/n`.
//!
//! Size factor `n` gives `n³·(2 + 144)` polygons plus the floor:
//! 1 → 147, 2 → 1169, 3 → 3943, 4 → 9345 (the SPD default), 10 → 146,001.

use std::f64::consts::{PI, TAU};
use std::io::{self, Write};

use glam::{DMat3, DVec3};

use super::nff_writer::{NffWriter, SKY_BLUE, Surface, View, phong_exponent};

/// Teeth per gear (the SPD's value; a multiple of 4).
const TEETH: usize = 36;

/// Outer radius of the teeth as a fraction of the pitch radius: slightly less
/// than 1 so meshing gears keep a gap instead of sharing surfaces.
const OUTER_EDGE_RATIO: f64 = 0.995;

/// Radius of the roots between the teeth, as a fraction of the pitch radius.
const INNER_EDGE_RATIO: f64 = 0.9;

/// Largest gear thickness.
const DEPTH_RATIO: f64 = 0.1;

/// Primitives for size factor `size`: two faces and a rim rectangle per
/// outline edge for each gear, and the floor.
pub fn primitive_count(size: u32) -> u64 {
    u64::from(size).pow(3) * (2 + 4 * TEETH as u64) + 1
}

/// Write the scene for size factor `size` (at least 1).
pub fn write<W: Write>(size: u32, out: &mut NffWriter<W>) -> io::Result<()> {
    out.background(SKY_BLUE)?;
    out.view(&View {
        hither: 1.0,
        ..View::towards_origin(DVec3::new(-1.1, -2.1, 2.6))
    })?;
    for light in [
        [2.0, 4.0, 4.0],
        [-2.0, 4.0, 3.0],
        [2.0, -2.5, 2.5],
        [-1.0, -4.0, 2.0],
        // Just behind the eye.
        [-1.111, -2.121, 2.626],
    ] {
        out.light(DVec3::from_array(light))?;
    }
    // The floor: an off-white, partly mirroring 4 × 4 square under the gears.
    out.surface(&Surface {
        color: DVec3::new(1.0, 0.85, 0.7),
        kd: 0.3,
        ks: 0.6,
        shine: phong_exponent(37.0),
        transmittance: 0.0,
        ior: 1.0,
    })?;
    out.polygon(
        &[
            [2.0, 2.0, 0.0],
            [-2.0, 2.0, 0.0],
            [-2.0, -2.0, 0.0],
            [2.0, -2.0, 0.0],
        ]
        .map(DVec3::from_array),
    )?;

    // Lay the gears out so that n of them, meshed, span [−1, 1] in x and y.
    let n = f64::from(size);
    let edge_diff = 1.0 - INNER_EDGE_RATIO;
    let radius = 1.0 / (n - (n - 1.0) * edge_diff / 2.0);
    let first = DVec3::new(-1.0 + radius, -1.0 + radius, 1.0);
    let step = DVec3::new(radius * (2.0 - edge_diff), radius * (2.0 - edge_diff), -1.0 / n);
    let thickness = DEPTH_RATIO.min(1.0 / (2.0 * n));
    for iz in 0..size {
        for iy in 0..size {
            for ix in 0..size {
                let center = first + DVec3::new(f64::from(ix), f64::from(iy), f64::from(iz)) * step;
                out.surface(&gear_surface(ix, iy, iz))?;
                // Neighbours turn by half a tooth, so their teeth interlock.
                let offset = PI * f64::from((ix + iy + iz) % 2) / TEETH as f64;
                gear(out, center, offset, radius, thickness)?;
            }
        }
    }
    Ok(())
}

/// The surface of gear `(ix, iy, iz)`: a pseudo-random saturated colour; one
/// gear in five is glass.
fn gear_surface(ix: u32, iy: u32, iz: u32) -> Surface {
    let channel = |k: u32, scale: f64| 0.01 + (f64::from(k) * scale).fract();
    let color = DVec3::new(
        channel(ix * 3 + iy * 2 + iz + 1, 5.0 / 7.0),
        channel(iy * 3 + iz * 2 + ix + 1, 3.0 / 7.0),
        channel(iz * 3 + ix * 2 + iy + 1, 2.0 / 7.0),
    );
    let color = color / color.max_element();
    if (ix * 4 + iy * 2 + iz).is_multiple_of(5) {
        Surface {
            color,
            kd: 0.2,
            ks: 0.0,
            shine: phong_exponent(0.0),
            transmittance: 0.8,
            ior: 1.1,
        }
    } else {
        Surface::matte(color)
    }
}

/// One gear whose top face lies in `z = center.z`, turned by `offset` radians.
fn gear<W: Write>(
    out: &mut NffWriter<W>,
    center: DVec3,
    offset: f64,
    radius: f64,
    thickness: f64,
) -> io::Result<()> {
    let top = outline(center, offset, radius);
    out.polygon(&top)?;
    // The rim: one rectangle per outline edge, counter-clockwise seen from outside.
    let down = DVec3::new(0.0, 0.0, thickness);
    for (i, &a) in top.iter().enumerate() {
        let b = top[(i + 1) % top.len()];
        out.polygon(&[a, a - down, b - down, b])?;
    }
    // The bottom: the same outline one thickness lower, wound the other way so
    // it faces down, starting at the first tooth's tip (top[1], top[0], then
    // backwards) so its first three vertices still span a convex corner.
    let n = top.len();
    let bottom: Vec<DVec3> = (0..n).map(|k| top[(n + 1 - k) % n] - down).collect();
    out.polygon(&bottom)?;
    Ok(())
}

/// The outline of a gear's top face, counter-clockwise seen from above: per
/// tooth, the two corners of its tip on the outer radius, then the two ends of
/// the root arc that follows on the inner radius.
fn outline(center: DVec3, offset: f64, radius: f64) -> Vec<DVec3> {
    let tooth = TAU / TEETH as f64;
    let outer = OUTER_EDGE_RATIO * radius;
    let inner = INNER_EDGE_RATIO * radius;
    let point = |angle: f64, r: f64| center + DMat3::from_rotation_z(angle) * DVec3::new(r, 0.0, 0.0);
    (0..TEETH)
        .flat_map(|i| {
            let a = offset + tooth * i as f64;
            [
                point(a - 0.19 * tooth, outer),
                point(a + 0.19 * tooth, outer),
                point(a + 0.3 * tooth, inner),
                point(a + 0.7 * tooth, inner),
            ]
        })
        .collect()
}
