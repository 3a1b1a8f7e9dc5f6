//! Infinite planes in the lecture's three forms (section 5), scalar and packet kernels.
//!
//! - implicit `Ax + By + Cz + D = 0`: `t = −(A·x0 + B·y0 + C·z0 + D) / (A·vx + B·vy + C·vz)`;
//! - point and normal `⟨n, q − q0⟩ = 0`: `t = ⟨n, q0 − p0⟩ / ⟨n, v⟩`;
//! - parametric `s(u, v) = q + u·i + v·j`: the 3×3 system `[−v | i | j]·(t, u, v)ᵀ = p0 − q`
//!   solved by Cramer's rule, which also yields the plane coordinates `(u, v)`.
//!
//! A ray parallel to the plane (`⟨n, v⟩ = 0`) misses, also when it runs inside it;
//! so does a ray whose `⟨n, v⟩` is not finite (an infinite direction would
//! otherwise give `t = 0`).

use glam::Vec3;

use crate::geometry::{GeometryError, Intersect, usable_denominator, usable_denominators};
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, Ray};
use crate::simd::{SimdFloat, V3};

/// A plane, in the form it was given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Plane {
    /// `Ax + By + Cz + D = 0`.
    Implicit(ImplicitPlane),
    /// `⟨n, q − q0⟩ = 0`.
    PointNormal(PointNormalPlane),
    /// `q + u·i + v·j`.
    Parametric(ParametricPlane),
}

/// Implicit plane `⟨n, p⟩ + d = 0` with `n = (A, B, C)`, `d = D`. 16 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImplicitPlane {
    /// `(A, B, C)`, not necessarily unit length.
    pub n: Vec3,
    /// `D`.
    pub d: f32,
}

/// Plane through `q0` with normal `n`. 24 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointNormalPlane {
    /// Normal, not necessarily unit length.
    pub n: Vec3,
    /// A point on the plane.
    pub q0: Vec3,
}

/// Parametric plane `q + u·i + v·j`, with `n = i × j` precomputed. 48 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParametricPlane {
    /// Origin of the plane coordinates.
    pub q: Vec3,
    /// First spanning vector.
    pub i: Vec3,
    /// Second spanning vector.
    pub j: Vec3,
    /// `i × j`.
    pub n: Vec3,
}

fn finite_normal(n: Vec3) -> Result<Vec3, GeometryError> {
    if !n.is_finite() {
        return Err(GeometryError::NotFinite);
    }
    if n.length_squared() == 0.0 {
        return Err(GeometryError::DegeneratePlane);
    }
    Ok(n)
}

impl Plane {
    /// The implicit plane `Ax + By + Cz + D = 0`.
    pub fn implicit(a: f32, b: f32, c: f32, d: f32) -> Result<Self, GeometryError> {
        let n = finite_normal(Vec3::new(a, b, c))?;
        if !d.is_finite() {
            return Err(GeometryError::NotFinite);
        }
        Ok(Plane::Implicit(ImplicitPlane { n, d }))
    }

    /// The plane through `q0` with normal `n`.
    pub fn point_normal(q0: Vec3, n: Vec3) -> Result<Self, GeometryError> {
        let n = finite_normal(n)?;
        if !q0.is_finite() {
            return Err(GeometryError::NotFinite);
        }
        Ok(Plane::PointNormal(PointNormalPlane { n, q0 }))
    }

    /// The plane `q + u·i + v·j`; `i` and `j` must be independent.
    pub fn parametric(q: Vec3, i: Vec3, j: Vec3) -> Result<Self, GeometryError> {
        let n = finite_normal(i.cross(j))?;
        if !q.is_finite() {
            return Err(GeometryError::NotFinite);
        }
        Ok(Plane::Parametric(ParametricPlane { q, i, j, n }))
    }

    /// Unit normal (the direction of `(A, B, C)`, `n` or `i × j`).
    pub fn normal(&self) -> Vec3 {
        match self {
            Plane::Implicit(p) => p.n.normalize(),
            Plane::PointNormal(p) => p.n.normalize(),
            Plane::Parametric(p) => p.n.normalize(),
        }
    }
}

impl Intersect for Plane {
    /// Scalar kernel of whichever form this is.
    #[inline]
    fn intersect(&self, ray: &Ray, prim: u32, hit: &mut Hit) -> bool {
        match self {
            Plane::Implicit(p) => p.intersect(ray, prim, hit),
            Plane::PointNormal(p) => p.intersect(ray, prim, hit),
            Plane::Parametric(p) => p.intersect(ray, prim, hit),
        }
    }

    /// Packet kernel of whichever form this is.
    #[inline(always)]
    fn intersect_packet<F: SimdFloat>(&self, rays: &RayPacket<F>, prim: u32, hits: &mut HitPacket<F>) {
        match self {
            Plane::Implicit(p) => p.intersect_packet(rays, prim, hits),
            Plane::PointNormal(p) => p.intersect_packet(rays, prim, hits),
            Plane::Parametric(p) => p.intersect_packet(rays, prim, hits),
        }
    }
}

/// The scalar kernel of the implicit and point-normal forms: the hit at
/// `t = numerator / ⟨n, v⟩`, the numerator computed (in the form's own
/// order of operations) only where the denominator is usable.
#[inline(always)]
fn hit_plane(n: Vec3, numerator: impl FnOnce() -> f32, ray: &Ray, prim: u32, hit: &mut Hit) -> bool {
    let denom = n.dot(ray.dir);
    usable_denominator(denom) && hit.offer(numerator() / denom, ray.t_min, prim)
}

/// The packet kernel of the implicit and point-normal forms: each lane's hit
/// at `t = numerator / ⟨n, v⟩`.
#[inline(always)]
fn hit_plane_packet<F: SimdFloat>(
    n: Vec3,
    numerator: F,
    rays: &RayPacket<F>,
    prim: u32,
    hits: &mut HitPacket<F>,
) {
    let denom = rays.dir.dot_splat(n);
    let t = numerator / denom;
    let mask = hits.accepts(rays, t, prim) & usable_denominators(denom);
    let zero = F::splat(0.0);
    hits.record(mask, t, prim, zero, zero);
}

impl Intersect for ImplicitPlane {
    /// Scalar kernel.
    #[inline]
    fn intersect(&self, ray: &Ray, prim: u32, hit: &mut Hit) -> bool {
        hit_plane(self.n, || -(self.n.dot(ray.origin) + self.d), ray, prim, hit)
    }

    /// Packet kernel.
    #[inline(always)]
    fn intersect_packet<F: SimdFloat>(&self, rays: &RayPacket<F>, prim: u32, hits: &mut HitPacket<F>) {
        let numerator = -(rays.origin.dot_splat(self.n) + F::splat(self.d));
        hit_plane_packet(self.n, numerator, rays, prim, hits);
    }
}

impl Intersect for PointNormalPlane {
    /// Scalar kernel.
    #[inline]
    fn intersect(&self, ray: &Ray, prim: u32, hit: &mut Hit) -> bool {
        hit_plane(self.n, || self.n.dot(self.q0 - ray.origin), ray, prim, hit)
    }

    /// Packet kernel.
    #[inline(always)]
    fn intersect_packet<F: SimdFloat>(&self, rays: &RayPacket<F>, prim: u32, hits: &mut HitPacket<F>) {
        let numerator = (V3::splat(self.q0) - rays.origin).dot_splat(self.n);
        hit_plane_packet(self.n, numerator, rays, prim, hits);
    }
}

impl Intersect for ParametricPlane {
    /// Scalar kernel. With `r = p0 − q` and `det = det[−v | i | j] = −⟨v, n⟩`,
    /// Cramer's rule gives `t = ⟨r, n⟩/det`, `u = ⟨−v, r × j⟩/det`, `v = ⟨−v, i × r⟩/det`.
    #[inline]
    fn intersect(&self, ray: &Ray, prim: u32, hit: &mut Hit) -> bool {
        let det = -ray.dir.dot(self.n);
        if !usable_denominator(det) {
            return false;
        }
        let r = ray.origin - self.q;
        let inv_det = 1.0 / det;
        let t = r.dot(self.n) * inv_det;
        if !hit.accepts(t, ray.t_min, prim) {
            return false;
        }
        let u = -ray.dir.dot(r.cross(self.j)) * inv_det;
        let v = -ray.dir.dot(self.i.cross(r)) * inv_det;
        hit.record(t, prim, u, v);
        true
    }

    /// Packet kernel.
    #[inline(always)]
    fn intersect_packet<F: SimdFloat>(&self, rays: &RayPacket<F>, prim: u32, hits: &mut HitPacket<F>) {
        let det = -rays.dir.dot_splat(self.n);
        let r = rays.origin - V3::splat(self.q);
        let inv_det = F::splat(1.0) / det;
        let t = r.dot_splat(self.n) * inv_det;
        let mask = hits.accepts(rays, t, prim) & usable_denominators(det);
        if mask.none() {
            return;
        }
        let u = -rays.dir.dot(r.cross(V3::splat(self.j))) * inv_det;
        let v = -rays.dir.dot(V3::splat(self.i).cross(r)) * inv_det;
        hits.record(mask, t, prim, u, v);
    }
}
