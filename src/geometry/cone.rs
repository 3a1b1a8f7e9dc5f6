//! Cone and cylinder without end caps (NFF `c`), scalar and packet kernels.
//!
//! The shape is the lateral surface of a truncated cone: base centre `B` with
//! radius `r0`, apex centre `A` with radius `r1`, height `h = |A − B|`. It is a
//! cylinder when `r0 = r1` and a cone to a point when one radius is 0. In the
//! orthonormal frame `(u, v, w)` with `w = (A − B)/h` and its origin at `B`, the
//! surface is the quadric
//!
//! ```text
//! x² + y² = r(z)²,   r(z) = r0 + k·z,   k = (r1 − r0)/h,   clipped to 0 ≤ z ≤ h.
//! ```
//!
//! Substituting the ray `o + t·d` in frame coordinates gives `a·t² + 2b·t + c = 0` with
//!
//! ```text
//! a = dx² + dy² − k²·dz²
//! b = ox·dx + oy·dy − k·dz·r(oz)
//! c = ox² + oy² − r(oz)²
//! ```
//!
//! Both roots are clipped to the axis segment and the nearest one in the ray's
//! interval is kept; the surface is two-sided (a ray from inside hits the far
//! root, like the sphere). Two steps keep f32 precise for distant rays:
//! the ray is first re-based at its point closest to the axis segment (the
//! idea Haines et al. apply to spheres in "Precision improvements for ray/sphere
//! intersection", Ray Tracing Gems, 2019), and the roots come from the stable
//! form `q = −(b + sgn(b)·√(b² − a·c))`, `t = q/a` and `t = c/q` (Press et al.,
//! Numerical Recipes, §5.6), which also yields the single root of a ray parallel
//! to a side of the cone (`a = 0`) and rejects a ray along a cylinder's axis.
//! Hits record `(u, v) = (0, 0)`; the normal comes from the hit point.

use glam::Vec3;

use crate::bounds::Aabb;
use crate::geometry::{GeometryError, Intersect};
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, Ray};
use crate::simd::{SimdFloat, V3};

/// A truncated cone (or cylinder) without end caps. 76 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cone {
    /// Base centre `B`, the frame's origin.
    base: Vec3,
    /// Base radius `r0`.
    base_radius: f32,
    /// Apex centre `A`.
    apex: Vec3,
    /// Apex radius `r1`.
    apex_radius: f32,
    /// First radial axis of the frame.
    u: Vec3,
    /// Second radial axis of the frame.
    v: Vec3,
    /// Unit axis `(A − B)/h`.
    w: Vec3,
    /// Segment length `h`.
    height: f32,
    /// Radius change per unit of height `k = (r1 − r0)/h`.
    slope: f32,
}

impl Cone {
    /// The cone from base centre `base` (radius `base_radius`) to apex centre
    /// `apex` (radius `apex_radius`). Radii must be ≥ 0 and not both 0, and the
    /// two centres must differ.
    pub fn new(base: Vec3, base_radius: f32, apex: Vec3, apex_radius: f32) -> Result<Self, GeometryError> {
        if !(base.is_finite() && apex.is_finite() && base_radius.is_finite() && apex_radius.is_finite()) {
            return Err(GeometryError::NotFinite);
        }
        for r in [base_radius, apex_radius] {
            if r < 0.0 {
                return Err(GeometryError::NegativeRadius(r));
            }
        }
        let axis = apex - base;
        let height = axis.length();
        if !(height > 0.0 && height.is_finite()) || (base_radius == 0.0 && apex_radius == 0.0) {
            return Err(GeometryError::DegenerateCone);
        }
        let w = axis / height;
        // Orthonormal basis around w: T. Duff et al., "Building an Orthonormal
        // Basis, Revisited", JCGT 6(1), 2017 (exact for coordinate axes).
        let (u, v) = w.any_orthonormal_pair();
        let slope = (apex_radius - base_radius) / height;
        if !slope.is_finite() {
            return Err(GeometryError::DegenerateCone);
        }
        Ok(Self {
            base,
            base_radius,
            apex,
            apex_radius,
            u,
            v,
            w,
            height,
            slope,
        })
    }

    /// Where the kernels re-base `ray`: the ray parameter of its point
    /// closest to the axis segment (the two lines' closest points, the
    /// segment's clamped to `[0, height]`; the base for a ray along the axis).
    /// Far from there, a long thin cone's quadratic loses its radius in
    /// rounding: the fuzzer found a cone 43951 long and 0.1 wide that,
    /// re-based at its midpoint, reported a hit 0.7 off its axis
    /// (tests/data/fuzz/). The packet kernel repeats this lane by lane.
    /// Returns the ray parameter and the axis parameter `s` of that point.
    #[inline(always)]
    fn rebase(&self, ray: &Ray) -> (f32, f32) {
        let r0 = ray.origin - self.base;
        let dw = ray.dir.dot(self.w);
        let s_line = (r0.dot(self.w) - dw * r0.dot(ray.dir)) / (1.0 - dw * dw);
        // NaN (a ray on the axis) goes to 0, as the packet kernel's selects do.
        let s = if s_line > 0.0 { s_line } else { 0.0 };
        let s = if s < self.height { s } else { self.height };
        ((self.base + s * self.w - ray.origin).dot(ray.dir), s)
    }

    /// The end of the axis the kernels measure from, for a ray re-based at
    /// axis parameter `s`: the nearer one, since f32 keeps coordinates near it
    /// to its own scale (a cylinder 958351 long, measured from its base, had
    /// its far end only to 0.06, and took hits 0.03 past it; tests/data/fuzz/).
    /// The end's centre, its radius, and the segment's z range from it.
    #[inline(always)]
    fn nearer_end(&self, s: f32) -> (Vec3, f32, f32, f32) {
        if s > 0.5 * self.height {
            (self.apex, self.apex_radius, -self.height, 0.0)
        } else {
            (self.base, self.base_radius, 0.0, self.height)
        }
    }

    /// Base centre.
    pub fn base(&self) -> Vec3 {
        self.base
    }

    /// Base radius.
    pub fn base_radius(&self) -> f32 {
        self.base_radius
    }

    /// Apex centre.
    pub fn apex(&self) -> Vec3 {
        self.apex
    }

    /// Apex radius.
    pub fn apex_radius(&self) -> f32 {
        self.apex_radius
    }

    /// Unit axis from base to apex.
    pub fn axis(&self) -> Vec3 {
        self.w
    }

    /// Bounding box: the union of the boxes of the two rim circles. A circle of
    /// radius r around axis w reaches `r·√(1 − w_i²)` along world axis i,
    /// computed as `r·√(w_j² + w_k²)`: for an axis within 10⁻⁴ of world axis i,
    /// `1 − w_i²` cancels to 0 in f32 and the box lost the rim's tilt, so a
    /// grazing ray's hit on the rim fell outside it (a fuzzer's finding). The
    /// larger of the two forms is kept, for an axis not exactly of unit length.
    pub fn bounds(&self) -> Aabb {
        let w2 = self.w * self.w;
        let others = Vec3::new(w2.y + w2.z, w2.z + w2.x, w2.x + w2.y);
        let s = (Vec3::ONE - w2).max(others).max(Vec3::ZERO);
        let reach = Vec3::new(s.x.sqrt(), s.y.sqrt(), s.z.sqrt());
        let rim = |c: Vec3, r: f32| Aabb::new(c - r * reach, c + r * reach);
        rim(self.base, self.base_radius).union(rim(self.apex, self.apex_radius))
    }

    /// Outward unit normal (away from the axis) at surface point `p`: the
    /// gradient of `x² + y² − r(z)²`, proportional to `(ρ̂, −k)` with ρ̂ the unit
    /// radial direction. At the tip of a pointed cone it is the axis direction.
    pub fn normal_at(&self, p: Vec3) -> Vec3 {
        let q = p - self.base;
        let radial = q - q.dot(self.w) * self.w;
        (radial.normalize_or_zero() - self.slope * self.w).normalize_or(-self.slope.signum() * self.w)
    }
}

impl Intersect for Cone {
    /// Scalar kernel.
    #[inline]
    fn intersect(&self, ray: &Ray, prim: u32, hit: &mut Hit) -> bool {
        // Step 1: re-base the ray at its point closest to the axis segment.
        let (shift, s) = self.rebase(ray);
        let (end, r_end, z_lo, z_hi) = self.nearer_end(s);
        let o = ray.origin + shift * ray.dir - end;
        // Step 2: origin and direction in the cone's frame.
        let (ox, oy, oz) = (o.dot(self.u), o.dot(self.v), o.dot(self.w));
        let d = ray.dir;
        let (dx, dy, dz) = (d.dot(self.u), d.dot(self.v), d.dot(self.w));
        // Step 3: the quadratic a·t² + 2b·t + c = 0.
        let k = self.slope;
        let r = r_end + k * oz;
        let a = dx * dx + dy * dy - k * k * (dz * dz);
        let b = ox * dx + oy * dy - k * dz * r;
        let c = ox * ox + oy * oy - r * r;
        let disc = b * b - a * c;
        if disc.is_nan() || disc < 0.0 {
            return false;
        }
        // Step 4: both roots in the stable form, ordered.
        let root = disc.sqrt();
        let q = -(b + if b < 0.0 { -root } else { root });
        let (t0, t1) = (q / a, c / q);
        let (near, far) = if t0 <= t1 { (t0, t1) } else { (t1, t0) };
        // Step 5: the near root if it lies on the segment and in the interval, else the far one.
        let z_near = oz + near * dz;
        let near_ok = z_near >= z_lo && z_near <= z_hi && shift + near >= ray.t_min;
        let t_local = if near_ok { near } else { far };
        let z = oz + t_local * dz;
        let t = shift + t_local;
        z >= z_lo && z <= z_hi && hit.offer(t, ray.t_min, prim)
    }

    /// Packet kernel: [`Cone::intersect`] on every active lane.
    #[inline(always)]
    fn intersect_packet<F: SimdFloat>(&self, rays: &RayPacket<F>, prim: u32, hits: &mut HitPacket<F>) {
        let r0 = rays.origin - V3::splat(self.base);
        let dw = rays.dir.dot_splat(self.w);
        let s_line = (r0.dot_splat(self.w) - dw * r0.dot(rays.dir)) / (F::splat(1.0) - dw * dw);
        let height = F::splat(self.height);
        let s = s_line.gt(F::splat(0.0)).select(s_line, F::splat(0.0));
        let s = s.lt(height).select(s, height);
        let anchor = V3::splat(self.base) + V3::splat(self.w).scale(s);
        let shift = (anchor - rays.origin).dot(rays.dir);
        // From the nearer end of the axis, lane by lane (see `nearer_end`).
        let from_apex = s.gt(F::splat(0.5 * self.height));
        let end = V3::select(from_apex, V3::splat(self.apex), V3::splat(self.base));
        let (r_end, z_lo, z_hi) = (
            from_apex.select(F::splat(self.apex_radius), F::splat(self.base_radius)),
            from_apex.select(F::splat(-self.height), F::splat(0.0)),
            from_apex.select(F::splat(0.0), F::splat(self.height)),
        );
        let o = rays.origin + rays.dir.scale(shift) - end;
        let (ox, oy, oz) = (o.dot_splat(self.u), o.dot_splat(self.v), o.dot_splat(self.w));
        let d = rays.dir;
        let (dx, dy, dz) = (d.dot_splat(self.u), d.dot_splat(self.v), d.dot_splat(self.w));
        let k = F::splat(self.slope);
        let r = r_end + k * oz;
        let a = dx * dx + dy * dy - k * k * (dz * dz);
        let b = ox * dx + oy * dy - k * dz * r;
        let c = ox * ox + oy * oy - r * r;
        let zero = F::splat(0.0);
        let disc = b * b - a * c;
        let root = disc.sqrt();
        let q = -(b + b.lt(zero).select(-root, root));
        let (t0, t1) = (q / a, c / q);
        let ordered = t0.le(t1);
        let (near, far) = (ordered.select(t0, t1), ordered.select(t1, t0));
        let z_near = oz + near * dz;
        let near_ok = z_near.ge(z_lo) & z_near.le(z_hi) & (shift + near).ge(rays.t_min);
        let t_local = near_ok.select(near, far);
        let z = oz + t_local * dz;
        let t = shift + t_local;
        let on_segment = disc.ge(zero) & z.ge(z_lo) & z.le(z_hi);
        let mask = hits.accepts(rays, t, prim) & on_segment;
        hits.record(mask, t, prim, zero, zero);
    }
}
