//! The ray sets engines are compared on.
//!
//! - *primary*: one ray through the centre of every pixel of the camera, row by
//!   row (the lecture's camera, [`Camera::pixel_ray`]);
//! - *random*: seeded rays of two kinds, alternating: rays that start at a
//!   uniform point of the scene's box (enlarged by 10%) in a uniform direction,
//!   which start inside objects, graze them and leave the scene; and rays from a
//!   sphere around the box aimed at a uniform point in it, which hit often;
//! - *uniform*: the `random` ray kind of `bench traversal` and `bench scene`
//!   (Aila and Laine 2009): a uniform point of the box, a uniform direction.

use glam::Vec3;

use crate::bounds::Aabb;
use crate::camera::Camera;
use crate::ray::Ray;
use crate::rng::Rng;

/// Which rays `raypack check` traces: the `rays` of its JSON report.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum CheckRays {
    /// One ray per pixel centre.
    Primary,
    /// Seeded random rays in and around the scene.
    Random,
}

/// One ray through the centre of every pixel, in row order.
pub fn primary_rays(camera: &Camera) -> Vec<Ray> {
    (0..camera.height)
        .flat_map(|j| (0..camera.width).map(move |i| camera.pixel_ray(i, j)))
        .collect()
}

/// The same rays as [`primary_rays`], ordered in blocks of 4×2 pixels (row by
/// row inside a block), so that 8 consecutive rays make a coherent packet, the
/// way Embree's examples trace `rtcIntersect8`. Pixels past the right or bottom
/// edge of the image are left out.
pub fn primary_rays_in_blocks(camera: &Camera) -> Vec<Ray> {
    let (w, h) = (camera.width, camera.height);
    let mut rays = Vec::with_capacity((w * h) as usize);
    for by in (0..h).step_by(2) {
        for bx in (0..w).step_by(4) {
            for j in by..(by + 2).min(h) {
                for i in bx..(bx + 4).min(w) {
                    rays.push(camera.pixel_ray(i, j));
                }
            }
        }
    }
    rays
}

/// `n` seeded random rays in and around `bounds` (see the module docs).
pub fn random_rays(bounds: Aabb, n: usize, seed: u64) -> Vec<Ray> {
    let (center, half) = if bounds.is_empty() {
        (Vec3::ZERO, Vec3::ONE)
    } else {
        (bounds.center(), (0.55 * bounds.extent()).max(Vec3::splat(1e-3)))
    };
    let (lo, hi) = (center - half, center + half);
    let radius = 1.5 * half.length();
    let mut rng = Rng::new(seed);
    (0..n)
        .map(|i| {
            if i % 2 == 0 {
                Ray::unbounded(rng.point_in(lo, hi), rng.unit_vector())
            } else {
                let origin = center + radius * rng.unit_vector();
                let aim = rng.point_in(lo, hi);
                Ray::unbounded(origin, (aim - origin).normalize())
            }
        })
        .collect()
}

/// `n` seeded incoherent rays: origins uniform in `bounds`, directions
/// uniform on the sphere.
pub fn uniform_rays(bounds: Aabb, n: usize, seed: u64) -> Vec<Ray> {
    let mut rng = Rng::new(seed);
    (0..n)
        .map(|_| Ray::unbounded(rng.point_in(bounds.min, bounds.max), rng.unit_vector()))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn primary_rays_are_the_cameras_pixel_rays_in_row_order() {
        let camera = Camera::new(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 40.0, 30.0, 4, 3).unwrap();
        let rays = primary_rays(&camera);
        assert_eq!(rays.len(), 12);
        assert_eq!(rays[5], camera.pixel_ray(1, 1));
        assert_eq!(rays[11], camera.pixel_ray(3, 2));
    }

    #[test]
    fn block_order_holds_every_pixel_ray_once_with_4x2_blocks() {
        let camera = Camera::new(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 40.0, 30.0, 9, 5).unwrap();
        let blocks = primary_rays_in_blocks(&camera);
        let mut rows = primary_rays(&camera);
        assert_eq!(blocks.len(), rows.len());
        assert_eq!(
            &blocks[..8],
            &[(0, 0), (1, 0), (2, 0), (3, 0), (0, 1), (1, 1), (2, 1), (3, 1)]
                .map(|(i, j)| camera.pixel_ray(i, j))
        );
        let key = |r: &Ray| (r.dir.x.to_bits(), r.dir.y.to_bits(), r.dir.z.to_bits());
        let mut blocks = blocks;
        blocks.sort_by_key(key);
        rows.sort_by_key(key);
        assert_eq!(blocks, rows);
    }

    #[test]
    fn random_rays_are_seeded_unit_and_around_the_box() {
        let b = Aabb::new(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(3.0, 1.0, 4.0));
        let rays = random_rays(b, 1000, 3);
        assert_eq!(rays, random_rays(b, 1000, 3));
        assert_ne!(rays, random_rays(b, 1000, 4));
        for (i, r) in rays.iter().enumerate() {
            assert!((r.dir.length() - 1.0).abs() < 1e-5);
            let inside = r.origin.cmpge(b.min - 0.06 * b.extent()).all()
                && r.origin.cmple(b.max + 0.06 * b.extent()).all();
            assert_eq!(inside, i % 2 == 0, "even rays start in the box, odd ones outside");
        }
    }
}
