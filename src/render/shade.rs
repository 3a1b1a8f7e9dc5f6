//! The one-bounce shading modes: the lecture's ray casting (`cast`) and the
//! diagnostic views `normals`, `depth` and `id`. None of them spawns rays.

use glam::Vec3;

use crate::ray::{Hit, Ray};
use crate::render::surface::Surface;
use crate::scene::Scene;

/// Share of a surface's colour lit regardless of the angle in `cast` mode.
const CAST_AMBIENT: f32 = 0.2;

/// Ray casting (lecture section 1): the colour of the nearest object, lit by a
/// headlight at the eye, `C·(0.2 + 0.8·⟨n, −d⟩)`; the background colour where
/// nothing is hit. Needs no lights, so every scene shows something.
#[inline]
pub fn cast(scene: &Scene, ray: &Ray, hit: &Hit) -> Vec3 {
    if !hit.is_hit() {
        return scene.background;
    }
    let s = Surface::at(scene, ray, hit);
    let lambert = s.normal.dot(-ray.dir).max(0.0);
    s.material.color * (CAST_AMBIENT + (1.0 - CAST_AMBIENT) * lambert)
}

/// The shading normal (facing the ray) mapped from `[-1, 1]³` to `[0, 1]³`; black for no hit.
#[inline]
pub fn normals(scene: &Scene, ray: &Ray, hit: &Hit) -> Vec3 {
    if !hit.is_hit() {
        return Vec3::ZERO;
    }
    0.5 * (Surface::at(scene, ray, hit).normal + Vec3::ONE)
}

/// A colour per primitive index, from an integer hash (the finaliser of
/// S. Vigna's SplitMix64), bright enough to tell neighbours apart; black for no hit.
#[inline]
pub fn id(hit: &Hit) -> Vec3 {
    if !hit.is_hit() {
        return Vec3::ZERO;
    }
    let mut z = u64::from(hit.prim).wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^= z >> 31;
    let channel = |shift: u32| 0.25 + 0.75 * ((z >> shift) & 0xff) as f32 / 255.0;
    Vec3::new(channel(0), channel(8), channel(16))
}

/// Grey levels for hit distances: white at the nearest `t` of the image, dark
/// grey at the farthest, black for no hit (`t` not finite). Normalised per image
/// so every scene uses the whole range.
pub fn depth(t: &[f32]) -> Vec<Vec3> {
    let finite = t.iter().copied().filter(|t| t.is_finite());
    let near = finite.clone().fold(f32::INFINITY, f32::min);
    let far = finite.fold(f32::NEG_INFINITY, f32::max);
    let range = far - near;
    t.iter()
        .map(|&t| {
            if !t.is_finite() {
                Vec3::ZERO
            } else if range > 0.0 {
                Vec3::splat(1.0 - 0.85 * (t - near) / range)
            } else {
                Vec3::ONE
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depth_maps_near_to_white_far_to_dark_and_misses_to_black() {
        let g = depth(&[2.0, 4.0, f32::INFINITY, 3.0]);
        assert_eq!(g[0], Vec3::ONE);
        assert!((g[1].x - 0.15).abs() < 1e-6);
        assert_eq!(g[2], Vec3::ZERO);
        assert!((g[3].x - 0.575).abs() < 1e-6);
        assert_eq!(depth(&[5.0, 5.0]), vec![Vec3::ONE; 2]);
    }

    #[test]
    fn ids_give_distinct_colours_and_black_background() {
        let hit = |prim| Hit {
            t: 1.0,
            prim,
            u: 0.0,
            v: 0.0,
            ng: Vec3::ZERO,
        };
        let colours: std::collections::HashSet<[u32; 3]> = (0..1000)
            .map(|p| id(&hit(p)).to_array().map(f32::to_bits))
            .collect();
        assert_eq!(colours.len(), 1000);
        assert_eq!(id(&Hit::none(&Ray::unbounded(Vec3::ZERO, Vec3::Z))), Vec3::ZERO);
    }
}
