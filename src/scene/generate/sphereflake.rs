//! SPD `balls`, the sphereflake (E. Haines, "A Proposal for Standard Graphics
//! Environments", IEEE CG&A 7(11), 1987): a mirror sphere of radius ½ at the
//! origin carries 9 spheres of a third of its radius, touching it, each of which
//! carries 9 more, `size` levels deep, above a beige square floor; 3 lights.
//!
//! The 9 children sit at cuboctahedron-like directions around the parent's axis
//! (the direction from its own parent, +z for the root): 6 around the equator at
//! azimuths 15°, 75°, … and 3 above it at azimuths 45°, 165°, 285° and 35.26°
//! elevation (`asin(1/√3)`); the 3 missing directions of the 12 point back at
//! the parent. Spheres are written depth first, parent before children, as the
//! SPD writes them; the published camera, lights and surfaces are kept.
//!
//! Size factor `n` gives `Σ_{i=0..n} 9^i` spheres plus the floor:
//! 0 → 1+1, 1 → 10+1, 2 → 91+1, 3 → 820+1, 4 → 7381+1 (the SPD default), 6 → 597,871+1.

use std::f64::consts::{FRAC_1_SQRT_2, TAU};
use std::io::{self, Write};

use glam::{DMat3, DVec3};

use super::nff_writer::{NffWriter, SKY_BLUE, Surface, View, phong_exponent};

/// Primitives for size factor `size`: the spheres and the floor.
pub fn primitive_count(size: u32) -> u64 {
    (9u64.pow(size + 1) - 1) / 8 + 1
}

/// Write the scene for size factor `size`.
pub fn write<W: Write>(size: u32, out: &mut NffWriter<W>) -> io::Result<()> {
    out.background(SKY_BLUE)?;
    out.view(&View::towards_origin(DVec3::new(2.1, 1.3, 1.7)))?;
    for light in [[4.0, 3.0, 2.0], [1.0, -4.0, 4.0], [-3.0, 1.0, 5.0]] {
        out.light(DVec3::from_array(light))?;
    }
    // The floor: a 24 × 24 square half a radius below the root's centre.
    out.surface(&Surface {
        color: DVec3::new(1.0, 0.75, 0.33),
        kd: 0.8,
        ks: 0.0,
        shine: phong_exponent(0.0),
        transmittance: 0.0,
        ior: 1.0,
    })?;
    let (e, z) = (12.0, -0.5);
    out.polygon(&[
        DVec3::new(e, e, z),
        DVec3::new(-e, e, z),
        DVec3::new(-e, -e, z),
        DVec3::new(e, -e, z),
    ])?;
    // The spheres: half diffuse, half mirror, highlight half width 37°.
    out.surface(&Surface {
        color: DVec3::new(1.0, 0.9, 0.7),
        kd: 0.5,
        ks: 0.5,
        shine: phong_exponent(37.0),
        transmittance: 0.0,
        ior: 1.0,
    })?;
    let root = Ball {
        center: DVec3::ZERO,
        radius: 0.5,
        axis: DVec3::Z,
    };
    flake(out, size, root, &child_directions())
}

/// The 9 child directions around +z. Three neighbouring cuboctahedron vertices
/// (one above the equator, two on it once tilted) are tilted by `asin(2/√6)`
/// about `(1, −1, 0)`, then repeated at 120° steps about z.
fn child_directions() -> [DVec3; 9] {
    let s = FRAC_1_SQRT_2;
    let trio = [
        DVec3::new(s, s, 0.0),
        DVec3::new(s, 0.0, -s),
        DVec3::new(0.0, s, -s),
    ];
    let tilt = DMat3::from_axis_angle(DVec3::new(1.0, -1.0, 0.0).normalize(), (2.0 / 6f64.sqrt()).asin());
    std::array::from_fn(|i| DMat3::from_rotation_z((i / 3) as f64 * TAU / 3.0) * (tilt * trio[i % 3]))
}

/// A sphere of the flake and the axis its children are placed around.
#[derive(Clone, Copy, Debug)]
struct Ball {
    center: DVec3,
    radius: f64,
    axis: DVec3,
}

/// Write `ball` and, `depth` levels down, its children around its axis.
fn flake<W: Write>(
    out: &mut NffWriter<W>,
    depth: u32,
    ball: Ball,
    directions: &[DVec3; 9],
) -> io::Result<()> {
    out.sphere(ball.center, ball.radius)?;
    if depth == 0 {
        return Ok(());
    }
    let to_axis = rotation_from_z(ball.axis);
    // A child of radius r/3 touches its parent: centres r + r/3 apart.
    let distance = ball.radius * (1.0 + 1.0 / 3.0);
    for d in directions {
        let axis = to_axis * *d;
        let child = Ball {
            center: ball.center + distance * axis,
            radius: ball.radius / 3.0,
            axis,
        };
        flake(out, depth - 1, child, directions)?;
    }
    Ok(())
}

/// The rotation taking +z to the unit vector `axis`, about `z × axis`.
fn rotation_from_z(axis: DVec3) -> DMat3 {
    if axis.z >= 1.0 {
        DMat3::IDENTITY
    } else if axis.z <= -1.0 {
        DMat3::from_rotation_y(std::f64::consts::PI)
    } else {
        DMat3::from_axis_angle(DVec3::Z.cross(axis).normalize(), axis.z.acos())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn children_are_nine_unit_directions_six_on_the_equator() {
        let dirs = child_directions();
        assert!(dirs.iter().all(|d| (d.length() - 1.0).abs() < 1e-12));
        assert_eq!(dirs.iter().filter(|d| d.z.abs() < 1e-12).count(), 6);
        let upper: Vec<_> = dirs.iter().filter(|d| d.z > 1e-12).collect();
        assert_eq!(upper.len(), 3);
        assert!(upper.iter().all(|d| (d.z - 2.0 / 6f64.sqrt()).abs() < 1e-12));
        // The first one is (1, 1, 2)/√6, as in the published file.
        assert!((dirs[0] - DVec3::new(1.0, 1.0, 2.0) / 6f64.sqrt()).length() < 1e-12);
        // Neighbouring children of a parent touch or leave room: no overlap.
        for (i, a) in dirs.iter().enumerate() {
            for b in &dirs[i + 1..] {
                assert!((a - b).length() * (4.0 / 3.0) >= 2.0 / 3.0 - 1e-12);
            }
        }
    }

    #[test]
    fn rotation_from_z_reaches_its_axis() {
        for axis in [
            DVec3::Z,
            -DVec3::Z,
            DVec3::X,
            DVec3::new(1.0, 2.0, -3.0).normalize(),
        ] {
            assert!(
                (rotation_from_z(axis) * DVec3::Z - axis).length() < 1e-12,
                "{axis}"
            );
        }
    }
}
