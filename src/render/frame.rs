//! The traced image: a colour, the primary hit distance and the primary hit's
//! primitive per pixel, and its conversion to 8-bit RGB.

use glam::Vec3;
use image::RgbImage;

/// A rendered image in linear RGB with its primary-ray hit records, row-major.
/// 80 bytes plus 20 bytes per pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Width in pixels (rays per row).
    pub width: u32,
    /// Height in pixels (rays per column).
    pub height: u32,
    /// Colour per pixel.
    pub color: Vec<Vec3>,
    /// Primary hit distance per pixel (`+∞` where the ray hit nothing).
    pub depth: Vec<f32>,
    /// Primary hit primitive per pixel ([`NO_HIT`](crate::ray::NO_HIT) where none).
    pub prim: Vec<u32>,
}

impl Frame {
    /// A black frame with no hits.
    pub fn new(width: u32, height: u32) -> Self {
        let n = width as usize * height as usize;
        Self {
            width,
            height,
            color: vec![Vec3::ZERO; n],
            depth: vec![f32::INFINITY; n],
            prim: vec![crate::ray::NO_HIT; n],
        }
    }

    /// Index of pixel `(x, y)`.
    #[inline]
    pub fn index(&self, x: u32, y: u32) -> usize {
        y as usize * self.width as usize + x as usize
    }

    /// The colours clamped to `[0, 1]` and rounded to 8 bits (NaN becomes 0).
    pub fn to_rgb8(&self) -> RgbImage {
        let to_byte = |c: f32| (c.clamp(0.0, 1.0) * 255.0).round() as u8;
        let bytes = self
            .color
            .iter()
            .flat_map(|c| c.to_array().map(to_byte))
            .collect();
        RgbImage::from_raw(self.width, self.height, bytes).expect("one colour per pixel")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colours_clamp_and_round_to_bytes() {
        let mut f = Frame::new(2, 1);
        f.color[0] = Vec3::new(-1.0, 0.5, 2.0);
        f.color[1] = Vec3::new(f32::NAN, 1.0 / 255.0, 0.999);
        let img = f.to_rgb8();
        assert_eq!(img.get_pixel(0, 0).0, [0, 128, 255]);
        assert_eq!(img.get_pixel(1, 0).0, [0, 1, 255]);
    }
}
