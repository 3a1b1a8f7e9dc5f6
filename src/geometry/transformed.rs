//! A primitive under an affine 4×4 transform M (lecture section 7).
//!
//! Instead of transforming the object, the ray is brought into object space with
//! M⁻¹ (origin as a point, direction as a vector), intersected there, and the
//! result mapped back: the object-space direction is renormalised, so object-space
//! distances are `s = |M⁻¹·v|` times world distances and `t_world = t_object / s`
//! (an affine map keeps the ray parameter, so this is the world-space distance of
//! the mapped-back hit point `M·q`). Normals go back with `M⁻ᵀ`.

use glam::{Mat3, Mat4, Vec3, Vec4};

use crate::bounds::Aabb;
use crate::geometry::triangle::TriangleTest;
use crate::geometry::{GeometryError, Intersect, Primitive};
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, NO_HIT, Ray};
use crate::simd::{SimdFloat, V3};

/// An affine map stored as its four columns, applied in one fixed order so the
/// scalar and packet kernels compute bit-identical rays. 48 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Affine {
    x: Vec3,
    y: Vec3,
    z: Vec3,
    translation: Vec3,
}

impl Affine {
    /// The map of the affine matrix `m` (its bottom row is not read).
    pub fn from_mat4(m: &Mat4) -> Self {
        Self {
            x: m.x_axis.truncate(),
            y: m.y_axis.truncate(),
            z: m.z_axis.truncate(),
            translation: m.w_axis.truncate(),
        }
    }

    /// `v` as a vector (no translation).
    #[inline(always)]
    pub fn vector(&self, v: Vec3) -> Vec3 {
        self.x * v.x + self.y * v.y + self.z * v.z
    }

    /// `p` as a point.
    #[inline(always)]
    pub fn point(&self, p: Vec3) -> Vec3 {
        self.vector(p) + self.translation
    }

    /// [`vector`](Self::vector) of every lane.
    #[inline(always)]
    pub fn vector_packet<F: SimdFloat>(&self, v: &V3<F>) -> V3<F> {
        V3::splat(self.x).scale(v.x) + V3::splat(self.y).scale(v.y) + V3::splat(self.z).scale(v.z)
    }

    /// [`point`](Self::point) of every lane.
    #[inline(always)]
    pub fn point_packet<F: SimdFloat>(&self, p: &V3<F>) -> V3<F> {
        self.vector_packet(p) + V3::splat(self.translation)
    }
}

/// M⁻¹ of an affine matrix `m`: finite, bottom row `0 0 0 1`, invertible.
/// Inverted in double precision: M⁻¹ feeds every ray, and its rounding shows in t.
pub fn affine_inverse(m: &Mat4) -> Result<Mat4, GeometryError> {
    if !m.is_finite() {
        return Err(GeometryError::NotFinite);
    }
    if m.row(3) != Vec4::W {
        return Err(GeometryError::NotAffine);
    }
    let det = m.determinant();
    if det == 0.0 || !det.is_finite() {
        return Err(GeometryError::SingularTransform);
    }
    let inverse = m.as_dmat4().inverse().as_mat4();
    if !inverse.is_finite() {
        return Err(GeometryError::SingularTransform);
    }
    Ok(inverse)
}

/// A primitive placed in the world by an affine transform. 152 bytes plus the primitive.
#[derive(Clone, Debug, PartialEq)]
pub struct Transformed {
    /// The primitive in object space.
    object: Primitive,
    /// M.
    to_world: Mat4,
    /// M⁻¹, applied to rays.
    to_object: Affine,
    /// M⁻ᵀ (upper 3×3), applied to normals.
    normal_to_world: Mat3,
}

impl Transformed {
    /// `object` under the affine matrix `m` (bottom row `0 0 0 1`, invertible).
    pub fn new(object: Primitive, m: Mat4) -> Result<Self, GeometryError> {
        let inverse = affine_inverse(&m)?;
        Ok(Self {
            object,
            to_world: m,
            to_object: Affine::from_mat4(&inverse),
            normal_to_world: Mat3::from_mat4(inverse).transpose(),
        })
    }

    /// The object-space primitive.
    pub fn object(&self) -> &Primitive {
        &self.object
    }

    /// The object-to-world matrix M.
    pub fn matrix(&self) -> Mat4 {
        self.to_world
    }

    /// Put every triangle of the object under `test` (the same shape under
    /// another kernel: the transform and bounds stay valid).
    pub fn set_triangle_test(&mut self, test: TriangleTest) {
        self.object.set_triangle_test(test);
    }

    /// World bounds: the object's box corners mapped by M (None for unbounded objects).
    pub fn bounds(&self) -> Option<Aabb> {
        let b = self.object.bounds()?;
        Some(Aabb::from_points(
            b.corners().map(|c| self.to_world.transform_point3(c)),
        ))
    }

    /// The ray in object space with a unit direction, and the scale `s` from
    /// world to object distances (None when M⁻¹ maps the direction to nothing usable).
    #[inline]
    fn object_ray(&self, ray: &Ray) -> Option<(Ray, f32)> {
        let d = self.to_object.vector(ray.dir);
        let s = d.length();
        if !(s > 0.0 && s < f32::INFINITY) {
            return None;
        }
        let origin = self.to_object.point(ray.origin);
        Some((Ray::new(origin, d / s, ray.t_min * s, ray.t_max * s), s))
    }

    /// Unit geometric normal at the hit: the object's normal taken through M⁻ᵀ.
    pub fn geometric_normal(&self, ray: &Ray, hit: &Hit) -> Vec3 {
        let Some((local_ray, s)) = self.object_ray(ray) else {
            return Vec3::ZERO;
        };
        let local = Hit { t: hit.t * s, ..*hit };
        let n = self.object.geometric_normal(&local_ray, &local);
        (self.normal_to_world * n).normalize_or_zero()
    }
}

impl Intersect for Transformed {
    /// Scalar kernel.
    #[inline]
    fn intersect(&self, ray: &Ray, prim: u32, hit: &mut Hit) -> bool {
        let Some((local_ray, s)) = self.object_ray(ray) else {
            return false;
        };
        let mut local = Hit {
            t: hit.t * s,
            prim: NO_HIT,
            ..*hit
        };
        if !self.object.intersect(&local_ray, prim, &mut local) {
            return false;
        }
        let t = local.t / s;
        if !hit.accepts(t, ray.t_min, prim) {
            return false;
        }
        hit.record(t, prim, local.u, local.v);
        true
    }

    /// Packet kernel.
    #[inline(always)]
    fn intersect_packet<F: SimdFloat>(&self, rays: &RayPacket<F>, prim: u32, hits: &mut HitPacket<F>) {
        let d = self.to_object.vector_packet(&rays.dir);
        let s = d.dot(d).sqrt();
        let usable = s.gt(F::splat(0.0)) & s.lt(F::splat(f32::INFINITY));
        let local_rays = RayPacket {
            origin: self.to_object.point_packet(&rays.origin),
            dir: V3 {
                x: d.x / s,
                y: d.y / s,
                z: d.z / s,
            },
            t_min: rays.t_min * s,
            t_max: rays.t_max * s,
            active: rays.active & usable,
        };
        let mut local = HitPacket {
            t: hits.t * s,
            prim: <F::U32 as crate::simd::SimdU32>::splat(NO_HIT),
            ..*hits
        };
        self.object.intersect_packet_object(&local_rays, prim, &mut local);
        let t = local.t / s;
        let mask = local.hit_mask() & hits.accepts(rays, t, prim);
        hits.record(mask, t, prim, local.u, local.v);
    }
}
