//! Sphere: the lecture's quadratic (section 7), scalar and packet kernels.
//!
//! Substituting the ray into `⟨p − c, p − c⟩ = r²` gives
//! `t²⟨v,v⟩ + 2t⟨v, p0 − c⟩ + ⟨p0 − c, p0 − c⟩ − r² = 0`. With `|v| = 1` and
//! `b = ⟨v, c − p0⟩` the roots are `t = b ± √(D/4)`. We evaluate the quarter
//! discriminant as `D/4 = r² − |l|²`, where `l = (p0 − c) + b·v` is the vector from
//! the centre to the point of closest approach: the same number, without the
//! cancellation of `b² − (|p0 − c|² − r²)` for distant origins (Haines et al.,
//! "Precision improvements for ray/sphere intersection", Ray Tracing Gems, 2019).
//!
//! An *inside-only* sphere (NFF's negative radius) shows only its inside: the
//! kernels always take the far root `b + √(D/4)`, so a ray from outside passes
//! through the front and sees the back from within, and the normal points inwards.
//!
//! Besides the one-sphere kernels, [`Spheres`] holds a few spheres in
//! structure-of-arrays form for one ray to test at once, as BVH leaves store them.

use glam::Vec3;

use crate::bounds::Aabb;
use crate::geometry::{BlockIntersect, BlockRay, Intersect, ShapeLanes, block_lanes};
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, Ray};
use crate::simd::{SimdFloat, SimdU32, V3};

/// A sphere. Kernels need unit ray directions. 20 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre.
    pub center: Vec3,
    /// Radius (positive).
    pub radius: f32,
    /// Only the inside is visible (far root only, inward normal).
    pub inside_only: bool,
}

impl Sphere {
    /// A sphere of centre `center` and radius `|radius|`.
    pub fn new(center: Vec3, radius: f32) -> Self {
        Self {
            center,
            radius: radius.abs(),
            inside_only: false,
        }
    }

    /// A sphere of centre `center` and radius `|radius|` of which only the
    /// inside is visible (NFF's negative radius).
    pub fn inside_only(center: Vec3, radius: f32) -> Self {
        Self {
            inside_only: true,
            ..Self::new(center, radius)
        }
    }

    /// Bounding box.
    pub fn bounds(&self) -> Aabb {
        Aabb::new(self.center - self.radius, self.center + self.radius)
    }

    /// Unit normal at surface point `p`: outward, or inward for an inside-only sphere.
    #[inline]
    pub fn normal_at(&self, p: Vec3) -> Vec3 {
        let outward = (p - self.center) / self.radius;
        if self.inside_only { -outward } else { outward }
    }
}

impl Intersect for Sphere {
    /// Scalar kernel: the nearest root in the ray's interval (the far root when
    /// the ray starts inside, and always for an inside-only sphere); tangent rays
    /// (`D = 0`) hit.
    #[inline]
    fn intersect(&self, ray: &Ray, prim: u32, hit: &mut Hit) -> bool {
        let oc = ray.origin - self.center;
        let b = -oc.dot(ray.dir);
        let l = oc + b * ray.dir;
        let quarter_disc = self.radius * self.radius - l.dot(l);
        // A miss, or NaN from non-finite input.
        if quarter_disc.is_nan() || quarter_disc < 0.0 {
            return false;
        }
        let s = quarter_disc.sqrt();
        let near = if self.inside_only { b + s } else { b - s };
        let t = if near >= ray.t_min { near } else { b + s };
        hit.offer(t, ray.t_min, prim)
    }

    /// Packet kernel: [`Sphere::intersect`] on every active lane.
    #[inline(always)]
    fn intersect_packet<F: SimdFloat>(&self, rays: &RayPacket<F>, prim: u32, hits: &mut HitPacket<F>) {
        intersect_packet_lane(self, 0, rays, prim, hits);
    }
}

/// Where the packet kernel reads a sphere: a [`Sphere`], or one lane of a
/// [`Spheres`] block, read in place (as the triangle kernels do, to keep the
/// lane out of a stack copy).
trait SphereLane {
    /// Lane `i`'s centre.
    fn center(&self, i: usize) -> Vec3;
    /// Lane `i`'s squared radius.
    fn radius_squared(&self, i: usize) -> f32;
    /// Whether lane `i`'s sphere shows only its inside.
    fn inside_only(&self, i: usize) -> bool;
}

impl SphereLane for Sphere {
    #[inline(always)]
    fn center(&self, _: usize) -> Vec3 {
        self.center
    }

    #[inline(always)]
    fn radius_squared(&self, _: usize) -> f32 {
        self.radius * self.radius
    }

    #[inline(always)]
    fn inside_only(&self, _: usize) -> bool {
        self.inside_only
    }
}

/// The packet kernel: the sphere in lane `i` of `sphere` against every active lane of `rays`.
#[inline(always)]
fn intersect_packet_lane<F: SimdFloat, S: SphereLane>(
    sphere: &S,
    i: usize,
    rays: &RayPacket<F>,
    prim: u32,
    hits: &mut HitPacket<F>,
) {
    // The scalar kernel's steps. (`c − o` would save the negation, but gives
    // +0 where the scalar kernel's −⟨o − c, d⟩ gives −0: a ray from the centre
    // of a point sphere.)
    let oc = rays.origin - V3::splat(sphere.center(i));
    let b = -oc.dot(rays.dir);
    let l = oc + rays.dir.scale(b);
    let quarter_disc = F::splat(sphere.radius_squared(i)) - l.dot(l);
    // Most rays of a packet miss most spheres: skip the roots when none crosses.
    let crosses = rays.active & quarter_disc.ge(F::splat(0.0));
    if crosses.none() {
        return;
    }
    let s = quarter_disc.sqrt();
    let near = if sphere.inside_only(i) { b + s } else { b - s };
    let t = near.ge(rays.t_min).select(near, b + s);
    let mask = hits.accepts_among(crosses, rays, t, prim);
    hits.record_without_uv(mask, t, prim);
}

/// Up to `F::LANES` spheres in structure-of-arrays form, each lane with the
/// primitive index its hit reports, so one ray tests them all in one SIMD pass
/// with no branch per sphere (the triangle blocks' layout,
/// [`ProjectedTriangles`](crate::geometry::triangle::ProjectedTriangles)). A
/// BVH leaf of spheres stores them this way. With `f32x4`: 6 × 16 = 96 bytes,
/// padded to 128 so that a block spans exactly two cache lines.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct Spheres<F: SimdFloat> {
    /// Centres, one row per axis, lane by lane.
    center: [F::Array; 3],
    /// Squared radii; `-∞` in an unused lane, which no ray crosses.
    radius_squared: F::Array,
    /// 1.0 where the sphere shows only its inside, else 0.0.
    inside_only: F::Array,
    /// Primitive index each lane's hit reports.
    ids: <F::U32 as SimdU32>::Array,
}

impl<F: SimdFloat> Spheres<F> {
    block_lanes!();

    /// Lanes `0..spheres.len()` hold `spheres` (shape and primitive index), the rest nothing.
    ///
    /// # Panics
    /// If `spheres` has more than `F::LANES` entries.
    pub fn new(spheres: &[(Sphere, u32)]) -> Self {
        let lanes = ShapeLanes::new::<F>(spheres);
        Self {
            center: [0, 1, 2].map(|k| lanes.row::<F>(|s| s.center[k], 0.0)),
            radius_squared: lanes.row::<F>(|s| s.radius_squared(0), f32::NEG_INFINITY),
            inside_only: lanes.row::<F>(|s| f32::from(u8::from(s.inside_only)), 0.0),
            ids: lanes.ids::<F>(|_, id| id, 0),
        }
    }
}

impl<F: SimdFloat> BlockIntersect for Spheres<F> {
    type Lanes = F;

    #[inline(always)]
    fn id(&self, i: usize) -> u32 {
        self.ids.as_ref()[i]
    }

    /// One ray against every lane (the scalar kernel's arithmetic, lane by
    /// lane, so each lane's t is bit for bit the scalar one): records in `hit`
    /// what the scalar kernel run over the lanes in any order would, and
    /// returns true if any lane's hit was recorded.
    #[inline(always)]
    fn intersect_with<N: SimdFloat<Array = F::Array>>(&self, ray: &BlockRay, hit: &mut Hit) -> bool {
        let ray = ray.ray;
        let (x, y, z) = (
            N::from_array(self.center[0]),
            N::from_array(self.center[1]),
            N::from_array(self.center[2]),
        );
        let dir = V3::splat(ray.dir);
        // The scalar kernel's steps, in its order of operations (dots sum x, y, then z, as glam's).
        let oc = V3::splat(ray.origin) - V3 { x, y, z };
        let b = -oc.dot(dir);
        let l = oc + dir.scale(b);
        let quarter_disc = N::from_array(self.radius_squared) - l.dot(l);
        let crosses = quarter_disc.ge(N::splat(0.0));
        if crosses.none() {
            return false;
        }
        let s = quarter_disc.sqrt();
        let inside_only = N::from_array(self.inside_only).ne(N::splat(0.0));
        let near = inside_only.select(b + s, b - s);
        let t_min = N::splat(ray.t_min);
        let t = near.ge(t_min).select(near, b + s);
        // Lanes hit within [t_min, hit.t]; the record's own rule settles among them.
        let candidates = crosses & t.ge(t_min) & t.le(N::splat(hit.t));
        let zero = N::splat(0.0);
        hit.record_nearest_lane(candidates.bitmask(), t, zero, zero, |i| self.id(i), ray.t_min)
    }
}

impl<F: SimdFloat> SphereLane for Spheres<F> {
    #[inline(always)]
    fn center(&self, i: usize) -> Vec3 {
        Vec3::new(
            self.center[0].as_ref()[i],
            self.center[1].as_ref()[i],
            self.center[2].as_ref()[i],
        )
    }

    #[inline(always)]
    fn radius_squared(&self, i: usize) -> f32 {
        self.radius_squared.as_ref()[i]
    }

    #[inline(always)]
    fn inside_only(&self, i: usize) -> bool {
        self.inside_only.as_ref()[i] != 0.0
    }
}
