//! SPD `tetra`, a Sierpinski tetrahedron (E. Haines, IEEE CG&A 7(11), 1987;
//! after the scenes of Glassner 1984 and Kay & Kajiya 1986): a tetrahedron
//! inscribed in the cube `[−1, 1]³` is replaced by the 4 half-size tetrahedra at
//! its corners, recursively; the smallest are written as 4 triangles (`p 3`)
//! each, counter-clockwise seen from outside. Red, diffuse only, 1 light; the
//! published camera looks at it from below.
//!
//! Size factor `n` gives `4^(n+2)` triangles: 1 → 64, 2 → 256, 3 → 1024,
//! 4 → 4096 (the classic scene), 8 → 1,048,576. (SPD 3.x counts the same
//! scenes with factors 2 higher: its 6 is this 4.)

use std::io::{self, Write};

use glam::DVec3;

use super::nff_writer::{NffWriter, SKY_BLUE, Surface, View};

/// The corners of the tetrahedron in the cube `[−1, 1]³`: the cube corners whose
/// coordinate signs multiply to +1, in x-major order.
const CORNERS: [[f64; 3]; 4] = [
    [-1.0, -1.0, 1.0],
    [-1.0, 1.0, -1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, 1.0],
];

/// Each face leaves out one corner and winds counter-clockwise seen from outside.
const FACES: [[usize; 3]; 4] = [[0, 1, 2], [3, 2, 1], [2, 3, 0], [1, 0, 3]];

/// Primitives for size factor `size`.
pub fn primitive_count(size: u32) -> u64 {
    4u64.pow(size + 2)
}

/// Write the scene for size factor `size`.
pub fn write<W: Write>(size: u32, out: &mut NffWriter<W>) -> io::Result<()> {
    out.background(SKY_BLUE)?;
    out.view(&View {
        from: DVec3::new(1.022846, -3.177154, -2.174512),
        at: DVec3::new(-0.004103, -0.004103, 0.216539),
        up: DVec3::new(-0.816497, -0.816497, 0.816497),
        angle: 45.0,
        hither: 1.0,
        resolution: [512, 512],
    })?;
    out.light(DVec3::new(2.0, -18.0, -5.0))?;
    out.surface(&Surface::matte(DVec3::new(1.0, 0.2, 0.2)))?;
    subdivide(out, size + 2, DVec3::ZERO, 1.0)
}

/// The tetrahedron in the cube of centre `center` and half width `half`,
/// subdivided `levels − 1` times.
fn subdivide<W: Write>(out: &mut NffWriter<W>, levels: u32, center: DVec3, half: f64) -> io::Result<()> {
    let corners = CORNERS.map(DVec3::from_array);
    if levels <= 1 {
        let points = corners.map(|c| center + half * c);
        for face in FACES {
            out.polygon(&face.map(|i| points[i]))?;
        }
        return Ok(());
    }
    for c in corners {
        subdivide(out, levels - 1, center + 0.5 * half * c, 0.5 * half)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn faces_wind_outwards() {
        let corners = CORNERS.map(DVec3::from_array);
        for (face, left_out) in FACES.iter().zip([3, 0, 1, 2]) {
            let [a, b, c] = face.map(|i| corners[i]);
            let normal = (b - a).cross(c - a);
            assert!(normal.dot(-corners[left_out]) > 0.0, "face {face:?}");
        }
    }
}
