//! SPD `rings` (E. Haines, "A Proposal for Standard Graphics Environments",
//! IEEE CG&A 7(11), 1987): objects of 6 pentagonal rings that join the 30 edge
//! midpoints of a dodecahedron, stacked in a square pyramid whose apex faces the
//! camera, against a white wall that catches their shadows; 3 lights.
//!
//! A ring is 5 cylinders along the sides of a regular pentagon with a sphere of
//! the same radius (0.07412) at each corner, so the joints are smooth. The first
//! ring lies in the xy plane, its corners at angles 0°, 72°, … on a circle of
//! radius `1/(1 + 0.07412)` (the object then fits the unit sphere); the other
//! five are that ring tilted about x by the angle between the normals of two
//! neighbouring dodecahedron faces, `2·acos(cos 60° / sin 36°)` ≈ 63.43°, then
//! turned about z by 36°, 108°, 180°, 252° and 324°. Pyramid layer `d`
//! (`d = 0, 1, …`) holds `(d+1)²` objects in the plane `y = (d+1)/sin 22.5°`, on
//! a grid of step 2 in x and z centred on the camera's axis; the eye sits one
//! step before the apex, looking along +y, and the wall just fills the 45° view
//! at the back. The published camera, lights and garish colours are kept.
//!
//! Size factor `n` (the SPD's) gives `Σ_{d=1..n} d²` objects of 30 cylinders
//! and 30 spheres, `5·n(n+1)(2n+1)` of each, plus the wall:
//! 1 → 61, 2 → 301, 3 → 841, 7 → 8401 (the SPD default), 30 → 283,051.

use std::f64::consts::{FRAC_PI_8, PI, TAU};
use std::io::{self, Write};

use glam::{DMat3, DVec3};

use super::nff_writer::{NffWriter, SKY_BLUE, Surface, View, phong_exponent};

/// Radius of the cylinders and of the spheres at their joints.
const RADIUS: f64 = 0.07412;

/// The colours of the 6 rings: red, green, blue and their complements.
const RING_COLORS: [[f64; 3]; 6] = [
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [0.0, 1.0, 1.0],
    [1.0, 0.0, 1.0],
    [1.0, 1.0, 0.0],
];

/// Primitives for size factor `size`: the cylinders, the spheres and the wall.
pub fn primitive_count(size: u32) -> u64 {
    let n = u64::from(size);
    10 * n * (n + 1) * (2 * n + 1) + 1
}

/// Write the scene for size factor `size`.
pub fn write<W: Write>(size: u32, out: &mut NffWriter<W>) -> io::Result<()> {
    // Layers are this far apart in y; objects 2 apart in x and z.
    let layer_step = 1.0 / FRAC_PI_8.sin();
    out.background(SKY_BLUE)?;
    let from = DVec3::new(-1.0, -layer_step, 0.5);
    out.view(&View::looking_at(from, from + DVec3::Y))?;
    for light in [
        [3.0, -layer_step, 3.0],
        [-4.0, -layer_step, 1.0],
        [2.0, -layer_step, -4.0],
    ] {
        out.light(DVec3::from_array(light))?;
    }
    // The wall: white, matte, behind the last layer, just spanning the 45° view plus 1%.
    out.surface(&Surface {
        color: DVec3::ONE,
        kd: 1.0,
        ks: 0.0,
        shine: phong_exponent(0.0),
        transmittance: 0.0,
        ior: 0.0,
    })?;
    let wall_y = layer_step * f64::from(size + 1);
    let half = 1.01 * (wall_y - from.y) * FRAC_PI_8.tan();
    out.polygon(
        &[[1.0, 1.0], [-1.0, 1.0], [-1.0, -1.0], [1.0, -1.0]]
            .map(|[x, z]| DVec3::new(from.x + x * half, wall_y, from.z + z * half)),
    )?;
    // The pyramid, layer by layer from the apex, each layer row by row in z.
    let corners = ring_corners();
    for depth in 0..size {
        let y = layer_step * f64::from(depth + 1);
        for row in 0..=depth {
            let z = f64::from(2 * row) - f64::from(depth);
            for column in 0..=depth {
                let x = f64::from(2 * column) - f64::from(depth);
                object(out, &corners, DVec3::new(x, y, z))?;
            }
        }
    }
    Ok(())
}

/// Write one object of 6 rings centred at `center`: for each corner, the
/// cylinder from it back to the previous corner of its ring, then its sphere.
fn object<W: Write>(out: &mut NffWriter<W>, corners: &[DVec3; 30], center: DVec3) -> io::Result<()> {
    for (ring, color) in RING_COLORS.iter().enumerate() {
        // Half diffuse, a fifth mirror, highlight half width 10°.
        out.surface(&Surface {
            color: DVec3::from_array(*color),
            kd: 0.5,
            ks: 0.2,
            shine: phong_exponent(10.0),
            transmittance: 0.0,
            ior: 0.0,
        })?;
        let ring_corners = &corners[5 * ring..5 * ring + 5];
        for (i, &corner) in ring_corners.iter().enumerate() {
            let previous = ring_corners[(i + 4) % 5];
            out.cone(center + corner, RADIUS, center + previous, RADIUS)?;
            out.sphere(center + corner, RADIUS)?;
        }
    }
    Ok(())
}

/// The 30 ring corners (the dodecahedron's edge midpoints), 5 per ring, each
/// ring's in order around it.
fn ring_corners() -> [DVec3; 30] {
    let radius = 1.0 / (1.0 + RADIUS);
    let first: [DVec3; 5] = std::array::from_fn(|k| {
        let angle = k as f64 * TAU / 5.0;
        radius * DVec3::new(angle.cos(), angle.sin(), 0.0)
    });
    // Tilt: the angle between the normals of neighbouring dodecahedron faces.
    let tilt = DMat3::from_rotation_x(2.0 * ((PI / 3.0).cos() / (PI / 5.0).sin()).acos());
    std::array::from_fn(|i| {
        let (ring, k) = (i / 5, i % 5);
        if ring == 0 {
            first[k]
        } else {
            let turn = PI * (2 * ring - 1) as f64 / 5.0;
            DMat3::from_rotation_z(turn) * (tilt * first[k])
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corners_fit_the_unit_sphere_and_rings_meet_at_dodecahedron_edges() {
        let corners = ring_corners();
        let radius = 1.0 / (1.0 + RADIUS);
        assert!(corners.iter().all(|c| (c.length() - radius).abs() < 1e-12));
        // The 30 corners are distinct.
        for (i, a) in corners.iter().enumerate() {
            for b in &corners[i + 1..] {
                assert!((a - b).length() > 0.1, "{a} {b}");
            }
        }
        // Each ring is a regular pentagon: all 30 sides equally long.
        let side = (corners[1] - corners[0]).length();
        for ring in corners.chunks(5) {
            for k in 0..5 {
                assert!(((ring[k] - ring[(k + 4) % 5]).length() - side).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn counts_follow_the_spd_table() {
        assert_eq!(primitive_count(1), 61);
        assert_eq!(primitive_count(2), 301);
        assert_eq!(primitive_count(3), 841);
        assert_eq!(primitive_count(7), 8401);
    }
}
