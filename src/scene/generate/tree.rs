//! SPD `tree` (E. Haines, IEEE CG&A 7(11), 1987, with the corrected image in
//! IEEE CG&A 8(1), 1988): a binary tree grown by the method of M. Aono and T. L.
//! Kunii ("Botanical Tree Image Generation", IEEE CG&A 4(5), 1984), standing on
//! a green square field; 7 lights, so the scene is dominated by shadow rays.
//!
//! Every branch is a cone of unit length along its own z axis, base radius
//! 0.15 times the branch's scale, apex radius 0.67 times its base radius, capped
//! by a sphere of the apex radius at its tip. A branch carries two children at
//! its tip, each in the branch's frame rotated about x by the branching angle
//! (40°, 25°), then about z by 90° plus the divergence (0°, 140°), shrunk by the
//! contraction (0.65, 0.70) and moved to the tip; a child's scale (and so its
//! radii) is 0.67 times its parent's. The trunk is the unit branch at the origin.
//! Branches are written depth first, a cone before its sphere, as the SPD
//! writes them; the published camera and lights are kept.
//!
//! Size factor `n` (the SPD's: the levels below the trunk) gives
//! `2^(n+1) − 1` cones and as many spheres, plus the field:
//! 0 → 3, 1 → 7, 2 → 15, 11 → 8191 (the SPD default), 18 → 1,048,575.

use std::io::{self, Write};

use glam::{DAffine3, DMat3, DVec3};

use super::nff_writer::{NffWriter, SKY_BLUE, Surface, View, phong_exponent};

/// Branching angle in degrees, divergence about the parent's axis (on top of a
/// quarter turn) in degrees, and length contraction, for each of the two children.
const CHILDREN: [(f64, f64, f64); 2] = [(40.0, 0.0, 0.65), (25.0, 140.0, 0.70)];

/// Ratio of a branch's apex radius to its base radius, and of a child's scale to its parent's.
const DIAMETER_RATIO: f64 = 0.67;

/// Base radius of a branch of scale 1 (its length is 1).
const WIDTH_TO_HEIGHT: f64 = 0.15;

/// Primitives for size factor `size`: the cones, the spheres and the field.
pub fn primitive_count(size: u32) -> u64 {
    2 * ((1u64 << (size + 1)) - 1) + 1
}

/// Write the scene for size factor `size`.
pub fn write<W: Write>(size: u32, out: &mut NffWriter<W>) -> io::Result<()> {
    out.background(SKY_BLUE)?;
    out.view(&View::looking_at(
        DVec3::new(4.5, 0.4, 2.0),
        DVec3::new(0.0, 0.0, 1.5),
    ))?;
    for light in [
        [-5.0, 5.0, 50.0],
        [30.0, -30.0, 30.0],
        [-40.0, -30.0, 20.0],
        [10.0, 30.0, 40.0],
        [-30.0, 40.0, 10.0],
        [50.0, 25.0, 20.0],
        [-10.0, -60.0, 30.0],
    ] {
        out.light(DVec3::from_array(light))?;
    }
    // The field: a green 100 × 100 square at z = 0, matte.
    out.surface(&matte(DVec3::new(0.2, 0.7, 0.2)))?;
    out.polygon(
        &[[1.0, 1.0], [-1.0, 1.0], [-1.0, -1.0], [1.0, -1.0]]
            .map(|[x, y]| DVec3::new(50.0 * x, 50.0 * y, 0.0)),
    )?;
    // The tree: brown, matte.
    out.surface(&matte(DVec3::new(0.55, 0.4, 0.2)))?;
    grow(out, DAffine3::IDENTITY, 1.0, size, &child_frames())
}

/// The frames of the two children in their parent's frame: tilted about x,
/// turned about z, shrunk, moved to the parent's tip.
fn child_frames() -> [DAffine3; 2] {
    CHILDREN.map(|(angle, divergence, contraction)| {
        DAffine3::from_translation(DVec3::Z)
            * DAffine3::from_scale(DVec3::splat(contraction))
            * DAffine3::from_mat3(DMat3::from_rotation_z((90.0 + divergence).to_radians()))
            * DAffine3::from_mat3(DMat3::from_rotation_x(angle.to_radians()))
    })
}

/// The SPD's opaque matte surface: fully diffuse, no highlight, index 0 as it writes it.
fn matte(color: DVec3) -> Surface {
    Surface {
        color,
        kd: 1.0,
        ks: 0.0,
        shine: phong_exponent(0.0),
        transmittance: 0.0,
        ior: 0.0,
    }
}

/// Write the branch whose frame is `frame` and, `depth` levels down, its children.
fn grow<W: Write>(
    out: &mut NffWriter<W>,
    frame: DAffine3,
    scale: f64,
    depth: u32,
    children: &[DAffine3; 2],
) -> io::Result<()> {
    let base = frame.transform_point3(DVec3::ZERO);
    let apex = frame.transform_point3(DVec3::Z);
    let base_radius = scale * WIDTH_TO_HEIGHT;
    let apex_radius = base_radius * DIAMETER_RATIO;
    out.cone(base, base_radius, apex, apex_radius)?;
    out.sphere(apex, apex_radius)?;
    if depth == 0 {
        return Ok(());
    }
    for child in children {
        grow(out, frame * *child, scale * DIAMETER_RATIO, depth - 1, children)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_follow_the_spd_table() {
        assert_eq!(primitive_count(0), 3);
        assert_eq!(primitive_count(1), 7);
        assert_eq!(primitive_count(3), 31);
        assert_eq!(primitive_count(11), 8191);
    }

    #[test]
    fn children_start_at_the_tip_shrunk_and_tilted() {
        for (child, (angle, _, contraction)) in child_frames().iter().zip(CHILDREN) {
            assert!((child.transform_point3(DVec3::ZERO) - DVec3::Z).length() < 1e-12);
            let axis = child.transform_vector3(DVec3::Z);
            assert!((axis.length() - contraction).abs() < 1e-12);
            assert!((axis.z / contraction - angle.to_radians().cos()).abs() < 1e-12);
        }
        // The first child leans towards +x (its tilt towards −y turned a quarter), the second back and aside.
        let [first, second] = child_frames().map(|c| c.transform_vector3(DVec3::Z));
        assert!(first.x > 0.0 && first.y.abs() < 1e-12, "{first}");
        assert!(second.x < 0.0, "{second}");
    }
}
