//! The setting shared by the generators that are not SPD scenes: the SPD's sky,
//! a camera that frames the cube `[−1, 1]³` from the sphereflake's direction,
//! and the sphereflake's three lights moved out to match.

use std::io::{self, Write};

use glam::DVec3;

use super::nff_writer::{NffWriter, SKY_BLUE, View};

/// Write the background, camera and lights for content inside `[−1, 1]³`.
pub fn write<W: Write>(out: &mut NffWriter<W>) -> io::Result<()> {
    out.background(SKY_BLUE)?;
    // At distance 4.8 a 45° view is 2·4.8·tan(22.5°) ≈ 4 wide: the cube's
    // circumscribed sphere (radius √3) fits.
    out.view(&View::towards_origin(1.6 * DVec3::new(2.1, 1.3, 1.7)))?;
    for light in [[4.0, 3.0, 2.0], [1.0, -4.0, 4.0], [-3.0, 1.0, 5.0]] {
        out.light(2.0 * DVec3::from_array(light))?;
    }
    Ok(())
}
