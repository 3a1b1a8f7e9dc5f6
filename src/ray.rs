//! A single ray and its hit record.

use glam::Vec3;

use crate::simd::SimdFloat;

/// Primitive index of a hit record that has hit nothing.
pub const NO_HIT: u32 = u32::MAX;

/// How far [`Ray::spawn`] moves a secondary ray's origin off its surface,
/// relative to the coordinates' magnitude: 2⁻¹⁷, 128 f32 ulps of 1. A hit
/// point `o + t·d` carries a few ulps of the magnitudes it was computed from
/// (the vertices, the origin), off the surface in any direction; 128 keeps
/// a wide margin over that while a neighbour 10⁻⁴ of the scene away stays
/// 13 times further.
pub const SPAWN_OFFSET: f32 = 1.0 / (1 << 17) as f32;

/// A ray `p(t) = origin + t·dir` with the parameter interval `[t_min, t_max]`.
///
/// `dir` is a unit vector for rays the engine makes (camera, reflection,
/// refraction, shadow); kernels do not rely on it except where noted.
/// 32 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Start point `p0`.
    pub origin: Vec3,
    /// Direction `v` (unit length).
    pub dir: Vec3,
    /// Smallest accepted t (a small positive value avoids self-hits of secondary rays).
    pub t_min: f32,
    /// Largest accepted t.
    pub t_max: f32,
}

impl Ray {
    /// A secondary ray leaving the surface point `point` (with geometric
    /// normal `normal`, either side) along `dir`, which must not hit the
    /// surface it starts on: the origin moves off the surface, to the side
    /// `dir` leaves by, by [`SPAWN_OFFSET`] times the largest coordinate of
    /// `point` and of `scale` (the origin of the ray that found the point,
    /// whose rounding the point carries), and t starts at 0. A fixed `t_min`
    /// instead loses hits on neighbours closer than it, and fails on
    /// grazing directions, where the ray stays within rounding of the surface
    /// far longer than `t_min`.
    #[inline]
    pub fn spawn(point: Vec3, normal: Vec3, dir: Vec3, scale: Vec3, t_max: f32) -> Self {
        let magnitude = point.abs().max(scale.abs()).max_element();
        let side = if normal.dot(dir) < 0.0 { -normal } else { normal };
        Self::new(point + side * (SPAWN_OFFSET * magnitude), dir, 0.0, t_max)
    }

    /// A ray over `[t_min, t_max]`.
    #[inline]
    pub fn new(origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Self {
        Self {
            origin,
            dir,
            t_min,
            t_max,
        }
    }

    /// A ray over `[0, ∞)`.
    #[inline]
    pub fn unbounded(origin: Vec3, dir: Vec3) -> Self {
        Self::new(origin, dir, 0.0, f32::INFINITY)
    }

    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + t * self.dir
    }
}

/// The nearest hit found so far along a ray.
///
/// Kernels write `t`, `prim`, `u` and `v`; the geometric normal `ng` is filled
/// once per ray, after the nearest hit is known, by
/// [`Primitive::geometric_normal`](crate::geometry::Primitive::geometric_normal).
/// `(u, v)` are barycentric for triangles (`p = (1-u-v)·a + u·b + v·c`), the
/// plane coordinates for parametric planes, and 0 where a shape has no cheap
/// parameterisation (spheres, other planes, polygons).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit (`t_max` of the ray while nothing is hit).
    pub t: f32,
    /// Index of the primitive hit, [`NO_HIT`] for none.
    pub prim: u32,
    /// First surface parameter.
    pub u: f32,
    /// Second surface parameter.
    pub v: f32,
    /// Geometric normal (unit length) once filled in; zero before.
    pub ng: Vec3,
}

impl Hit {
    /// The empty record for `ray`: nothing hit, `t = ray.t_max`.
    #[inline]
    pub fn none(ray: &Ray) -> Self {
        Self {
            t: ray.t_max,
            prim: NO_HIT,
            u: 0.0,
            v: 0.0,
            ng: Vec3::ZERO,
        }
    }

    /// True once a primitive was hit.
    #[inline]
    pub fn is_hit(&self) -> bool {
        self.prim != NO_HIT
    }

    /// Whether a candidate at `t` on primitive `prim` replaces this record.
    ///
    /// The candidate must lie in `[t_min, hit.t]` and be finite; on equal `t` the
    /// lower primitive index wins, so the nearest hit is the same whatever order
    /// the primitives are tested in (brute force, BVH, packet or scalar).
    #[inline(always)]
    pub fn accepts(&self, t: f32, t_min: f32, prim: u32) -> bool {
        t >= t_min && t < f32::INFINITY && (t < self.t || (t == self.t && prim < self.prim))
    }

    /// Settle the lanes of a block kernel: of the lanes set in `candidates`
    /// (hits within `[t_min, self.t]`), record each one [`Hit::accepts`], in
    /// lane order, with its `t`, `u`, `v` and primitive index (`lane_id` of
    /// its lane); true if any was recorded. The result is the
    /// nearest by the tie rule, whatever the lane order.
    #[inline(always)]
    pub fn record_nearest_lane<F: SimdFloat>(
        &mut self,
        candidates: u32,
        t: F,
        u: F,
        v: F,
        lane_id: impl Fn(usize) -> u32,
        t_min: f32,
    ) -> bool {
        if candidates == 0 {
            return false;
        }
        let (t, u, v) = (t.to_array(), u.to_array(), v.to_array());
        let (mut lanes, mut recorded) = (candidates, false);
        while lanes != 0 {
            let i = lanes.trailing_zeros() as usize;
            lanes &= lanes - 1;
            let (t, id) = (t.as_ref()[i], lane_id(i));
            if self.accepts(t, t_min, id) {
                self.record(t, id, u.as_ref()[i], v.as_ref()[i]);
                recorded = true;
            }
        }
        recorded
    }

    /// Record a hit at `t` on `prim`, with no surface coordinates, if the
    /// record [accepts](Hit::accepts) it; true if recorded. The last step of
    /// the kernels whose hits carry no `u, v`.
    #[inline(always)]
    pub fn offer(&mut self, t: f32, t_min: f32, prim: u32) -> bool {
        let accepted = self.accepts(t, t_min, prim);
        if accepted {
            self.record(t, prim, 0.0, 0.0);
        }
        accepted
    }

    /// Record a hit (the caller has checked [`Hit::accepts`]).
    #[inline(always)]
    pub fn record(&mut self, t: f32, prim: u32, u: f32, v: f32) {
        self.t = t;
        self.prim = prim;
        self.u = u;
        self.v = v;
    }
}
