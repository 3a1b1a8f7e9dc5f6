//! Sphere: the lecture's quadratic (section 7), scalar and packet kernels.
//!
//! Substituting the ray into `⟨p − c, p − c⟩ = r²` gives
//! `t²⟨v,v⟩ + 2t⟨v, p0 − c⟩ + ⟨p0 − c, p0 − c⟩ − r² = 0`. With `|v| = 1` and
//! `b = ⟨v, c − p0⟩` the roots are `t = b ± √(D/4)`. We evaluate the quarter
//! discriminant as `D/4 = r² − |l|²`, where `l = (p0 − c) + b·v` is the vector from
//! the centre to the point of closest approach: the same number, without the
//! cancellation of `b² − (|p0 − c|² − r²)` for distant origins (Haines et al.,
//! "Precision improvements for ray/sphere intersection", Ray Tracing Gems, 2019).

use glam::Vec3;

use crate::bounds::Aabb;
use crate::geometry::Intersect;
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, Ray};
use crate::simd::{SimdFloat, V3};

/// A sphere. Kernels need unit ray directions. 16 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre.
    pub center: Vec3,
    /// Radius (positive).
    pub radius: f32,
}

impl Sphere {
    /// A sphere of centre `center` and radius `|radius|`.
    pub fn new(center: Vec3, radius: f32) -> Self {
        Self {
            center,
            radius: radius.abs(),
        }
    }

    /// Bounding box.
    pub fn bounds(&self) -> Aabb {
        Aabb::new(self.center - self.radius, self.center + self.radius)
    }

    /// Outward unit normal at surface point `p`.
    #[inline]
    pub fn normal_at(&self, p: Vec3) -> Vec3 {
        (p - self.center) / self.radius
    }
}

impl Intersect for Sphere {
    /// Scalar kernel: the nearest root in the ray's interval (the far root when
    /// the ray starts inside); tangent rays (`D = 0`) hit.
    #[inline]
    fn intersect(&self, ray: &Ray, prim: u32, hit: &mut Hit) -> bool {
        let oc = ray.origin - self.center;
        let b = -oc.dot(ray.dir);
        let l = oc + b * ray.dir;
        let quarter_disc = self.radius * self.radius - l.dot(l);
        // Rejects negative and NaN discriminants alike.
        if quarter_disc.is_nan() || quarter_disc < 0.0 {
            return false;
        }
        let s = quarter_disc.sqrt();
        let near = b - s;
        let t = if near >= ray.t_min { near } else { b + s };
        if !hit.accepts(t, ray.t_min, prim) {
            return false;
        }
        hit.record(t, prim, 0.0, 0.0);
        true
    }

    /// Packet kernel: [`Sphere::intersect`] on every active lane.
    #[inline]
    fn intersect_packet<F: SimdFloat>(&self, rays: &RayPacket<F>, prim: u32, hits: &mut HitPacket<F>) {
        let oc = rays.origin - V3::splat(self.center);
        let b = -oc.dot(rays.dir);
        let l = oc + rays.dir.scale(b);
        let quarter_disc = F::splat(self.radius * self.radius) - l.dot(l);
        let s = quarter_disc.sqrt();
        let near = b - s;
        let t = near.ge(rays.t_min).select(near, b + s);
        let mask = hits.accepts(rays, t, prim) & quarter_disc.ge(F::splat(0.0));
        let zero = F::splat(0.0);
        hits.record(mask, t, prim, zero, zero);
    }
}
