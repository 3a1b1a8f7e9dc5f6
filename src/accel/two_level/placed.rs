//! An instance as the two-level walk reads it, and the rays it brings into
//! its mesh's space (lecture section 7: transform the ray, not the object).

use crate::geometry::transformed::Affine;
use crate::packet::RayPacket;
use crate::ray::Ray;
use crate::simd::{SimdFloat, V3};

/// An instance as the walk reads it. 56 bytes.
#[derive(Clone, Copy, Debug)]
pub(super) struct Placed {
    /// M⁻¹.
    pub to_object: Affine,
    /// The mesh's bottom structure.
    pub mesh: u32,
    /// The scene id of the mesh's primitive 0 in this instance.
    pub first_id: u32,
    /// Whether the mesh's kernels need unit directions.
    pub unit: bool,
}

impl Placed {
    /// `ray` in the mesh's space over `[t_min, t_max]`, and the factor from
    /// world to object t (1 unless the direction was renormalised); None where
    /// M⁻¹ leaves no usable direction.
    #[inline(always)]
    pub fn object_ray(&self, ray: &Ray, t_max: f32) -> Option<(Ray, f32)> {
        let origin = self.to_object.point(ray.origin);
        let dir = self.to_object.vector(ray.dir);
        let s = if self.unit { dir.length() } else { 1.0 };
        if !(s > 0.0 && s < f32::INFINITY) {
            return None;
        }
        let local = Ray {
            origin,
            dir: dir / s,
            t_min: ray.t_min * s,
            t_max: t_max * s,
        };
        Some((local, s))
    }

    /// The packet in the mesh's space, its lanes `lanes` active and bounded
    /// by the hits so far, and the factor from world to object t per lane.
    #[inline(always)]
    pub fn object_packet<F: SimdFloat>(&self, rays: &RayPacket<F>, lanes: F, t_max: F) -> (RayPacket<F>, F) {
        let origin = self.to_object.point_packet(&rays.origin);
        let d = self.to_object.vector_packet(&rays.dir);
        let (dir, s, usable) = if self.unit {
            let s = d.dot(d).sqrt();
            let usable = s.gt(F::splat(0.0)) & s.lt(F::splat(f32::INFINITY));
            let dir = V3 {
                x: d.x / s,
                y: d.y / s,
                z: d.z / s,
            };
            (dir, s, usable)
        } else {
            (d, F::splat(1.0), F::all_true())
        };
        let local = RayPacket {
            origin,
            dir,
            t_min: rays.t_min * s,
            t_max: t_max * s,
            active: lanes & usable,
        };
        (local, s)
    }
}
