//! What the instanced generators (`forest`, `city`) share: `n` lots on a
//! square grid over a ground of two triangles, and plain diffuse materials.

use glam::Vec3;

use crate::geometry::{Primitive, Triangle};
use crate::scene::{Material, Scene};

/// `n` lots on a square grid, `spacing` apart, row after row from the origin. 12 bytes.
#[derive(Clone, Copy, Debug)]
pub(super) struct Lots {
    /// Lots in a row.
    side: usize,
    /// Distance between neighbouring lots.
    spacing: f32,
    /// The grid's width: `side · spacing`.
    pub extent: f32,
}

impl Lots {
    /// The grid of `n` lots, `spacing` apart.
    pub fn new(n: usize, spacing: f32) -> Self {
        let side = (n as f32).sqrt().ceil().max(1.0) as usize;
        Self {
            side,
            spacing,
            extent: side as f32 * spacing,
        }
    }

    /// The centre of lot `k`, on the ground (y = 0).
    pub fn centre(&self, k: usize) -> Vec3 {
        let (i, j) = ((k % self.side) as f32, (k / self.side) as f32);
        Vec3::new(i * self.spacing, 0.0, j * self.spacing)
    }

    /// Add the ground, two triangles of `material` under the whole grid (a
    /// lot's width beyond its first row and column), to `scene`.
    pub fn push_ground(&self, scene: &mut Scene, material: u32) {
        let corner = |x: f32, z: f32| Vec3::new(x, 0.0, z);
        let (lo, hi) = (-self.spacing, self.extent);
        for t in [
            Triangle::new(corner(lo, lo), corner(lo, hi), corner(hi, lo)),
            Triangle::new(corner(hi, lo), corner(lo, hi), corner(hi, hi)),
        ] {
            scene.push(Primitive::Triangle(t), material);
        }
    }
}

/// A diffuse material of `color`.
pub(super) fn diffuse(color: Vec3) -> Material {
    Material {
        color,
        ..Material::default()
    }
}
