//! Triangle: the watertight test of S. Woop, C. Benthin and I. Wald,
//! "Watertight Ray/Triangle Intersection", JCGT 2(1), 2013; scalar, packet and
//! block kernels side by side.
//!
//! The ray's frame is sheared so that the ray runs along +z from the origin:
//! its dominant axis becomes `kz` and the other two `kx`, `ky` (swapped when
//! `d_kz < 0`, which keeps the winding), and each vertex relative to the
//! origin maps to
//!
//! ```text
//! (x, y, z) = (p_kx − S_x·p_kz,  p_ky − S_y·p_kz,  S_z·p_kz),   S = (d_kx/d_kz, d_ky/d_kz, 1/d_kz)
//! ```
//!
//! The hit is then a 2-D point-in-triangle test at the origin with the edge
//! functions `U = e(c, b)`, `V = e(a, c)`, `W = e(b, a)`, `e(p, q) = p_x·q_y − p_y·q_x`,
//! and the barycentrics `V / (U + V + W)`, `W / (U + V + W)`; t is the
//! plane's distance, computed from the same relative vertices (see
//! `edge_functions` for why not the paper's sheared sum). It is watertight because
//! two triangles sharing an edge compute that edge's function from the same
//! sheared vertices with the same operations in swapped order, which rounds
//! to exactly the negated value: a ray either side of the edge, or on it, is
//! inside one of them (or both), never neither. A hit requires the signs of
//! `U, V, W` not to differ (zero counts as either), so a ray through an edge
//! or a vertex hits every triangle there: a nearest-hit query keeps the lowest
//! index, [`all hits`](crate::accel) merges them.
//!
//! No product here is fused into an add (`a·b − c·d` would otherwise round
//! differently from `c·d − a·b`), so the kernels compile to the same
//! arithmetic with and without FMA, and the scalar, packet and block kernels
//! agree bit for bit.

use std::ops::{Add, Mul, Sub};

use glam::Vec3;

use crate::geometry::{
    BlockIntersect, BlockRay, ShapeLanes, block_lanes, usable_denominator, usable_denominators,
};
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, Ray};
use crate::simd::{SimdFloat, SimdU32, V3};

/// The two axes other than `k`, in cyclic order: `(k + 1) % 3`, `(k + 2) % 3`.
const OTHER_AXES: [[usize; 2]; 3] = [[1, 2], [2, 0], [0, 1]];

/// A triangle for the watertight test: its vertices, all the kernel reads. 36 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WatertightTriangle {
    /// Vertices `a, b, c`; NaN for a triangle no ray may hit (zero area or
    /// non-finite), which every comparison then rejects.
    vertices: [Vec3; 3],
}

impl WatertightTriangle {
    /// A triangle no ray hits.
    pub const NEVER_HIT: WatertightTriangle = WatertightTriangle {
        vertices: [Vec3::NAN; 3],
    };

    /// The test of triangle `a, b, c`.
    pub fn new(a: Vec3, b: Vec3, c: Vec3) -> Self {
        Self { vertices: [a, b, c] }
    }

    /// Vertex `corner` (0 = a, 1 = b, 2 = c), component `axis`.
    #[inline(always)]
    fn coordinate(&self, corner: usize, axis: usize) -> f32 {
        self.vertices[corner][axis]
    }
}

/// A ray in its shear frame (see the module documentation): all the
/// watertight kernels derive from the ray alone, computed once per ray
/// ([`BlockRay`] carries it to every block the ray
/// meets). 64 bytes.
#[derive(Clone, Copy, Debug)]
pub struct ShearedRay {
    /// The axes that become x, y and z.
    axes: [usize; 3],
    /// `S_x, S_y, S_z`.
    shear: [f32; 3],
    /// The origin's components in the frame's axis order.
    origin: [f32; 3],
    /// The direction's components in the frame's axis order.
    dir: [f32; 3],
}

impl ShearedRay {
    /// `ray` in its shear frame.
    #[inline(always)]
    pub fn new(ray: &Ray) -> Self {
        let abs = ray.dir.abs();
        // The dominant axis; NaN directions fall to z, and every test then misses.
        let kz = if abs.x >= abs.y && abs.x >= abs.z {
            0
        } else if abs.y >= abs.z {
            1
        } else {
            2
        };
        let [mut kx, mut ky] = OTHER_AXES[kz];
        let (o, d) = (ray.origin.to_array(), ray.dir.to_array());
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        Self {
            axes: [kx, ky, kz],
            shear: [d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]],
            origin: [o[kx], o[ky], o[kz]],
            dir: [d[kx], d[ky], d[kz]],
        }
    }

    /// False for a direction with an infinite (or zero) dominant component,
    /// whose frame flattens every triangle onto the origin and would report
    /// hits at t = 0; NaN directions need no check (they make t NaN).
    #[inline(always)]
    pub fn is_usable(&self) -> bool {
        usable_denominator(self.shear[2])
    }

    /// Point `p` relative to the origin, in the frame's axis order.
    #[inline(always)]
    fn relative(&self, p: Vec3) -> [f32; 3] {
        let ([kx, ky, kz], p) = (self.axes, p.to_array());
        [
            p[kx] - self.origin[0],
            p[ky] - self.origin[1],
            p[kz] - self.origin[2],
        ]
    }
}

/// The edge functions `U, V, W` of the origin against the triangle's edges,
/// from the vertices relative to the ray's origin, in the frame's axis order
/// `(kx, ky, kz)`: the arithmetic all three kernels share, written once over
/// scalars and lanes. Whether the ray passes inside needs only these; the
/// distance ([`plane_distance`]) is left to the triangles it does.
#[inline(always)]
fn edge_functions<T>(a: [T; 3], b: [T; 3], c: [T; 3], shear: [T; 3]) -> [T; 3]
where
    T: Copy + Sub<Output = T> + Mul<Output = T>,
{
    // (No closures or array maps in the kernels: they are compiled into each
    // instruction set's entry point only if everything inlines.)
    // Shear each vertex into the plane across the ray (x, y only: t comes from the plane).
    let ([ax, ay], [bx, by], [cx, cy]) = (sheared(a, shear), sheared(b, shear), sheared(c, shear));
    [cx * by - cy * bx, ax * cy - ay * cx, bx * ay - by * ax]
}

/// The plane distance's numerator `⟨n, a⟩` and denominator `⟨n, d⟩`
/// (`n = (b − a) × (c − a)`), from the vertices relative to the ray's origin
/// and the direction, in the frame's axis order; `t = ⟨n, a⟩ / ⟨n, d⟩`.
///
/// The paper's `t = (U·a_z + V·b_z + W·c_z) / (U + V + W)` sums products of
/// the sheared vertices, whose rounding grows with the vertices' distance
/// from the origin: from 10⁻⁶ in front of a triangle 2 long it came out
/// behind the origin, and a ray from just outside a mesh went in without a
/// hit. The plane distance rounds with the distance itself, so t comes from it.
#[inline(always)]
fn plane_distance<T>(a: [T; 3], b: [T; 3], c: [T; 3], dir: [T; 3]) -> [T; 2]
where
    T: Copy + Add<Output = T> + Sub<Output = T> + Mul<Output = T>,
{
    let (e1, e2) = (
        [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
        [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
    );
    let n = [
        e1[1] * e2[2] - e1[2] * e2[1],
        e1[2] * e2[0] - e1[0] * e2[2],
        e1[0] * e2[1] - e1[1] * e2[0],
    ];
    [dot(n, a), dot(n, dir)]
}

/// `p` sheared into the plane across the ray: `(p_x − S_x·p_z, p_y − S_y·p_z)`.
#[inline(always)]
fn sheared<T>(p: [T; 3], shear: [T; 3]) -> [T; 2]
where
    T: Copy + Sub<Output = T> + Mul<Output = T>,
{
    [p[0] - shear[0] * p[2], p[1] - shear[1] * p[2]]
}

/// `⟨n, p⟩`, summed x, y, then z.
#[inline(always)]
fn dot<T>(n: [T; 3], p: [T; 3]) -> T
where
    T: Copy + Add<Output = T> + Mul<Output = T>,
{
    n[0] * p[0] + n[1] * p[1] + n[2] * p[2]
}

impl WatertightTriangle {
    /// The scalar kernel in `frame`, `ray`'s shear frame
    /// ([`ShearedRay::new`]), made once for several triangles (a polygon's
    /// pieces).
    #[inline]
    pub fn intersect_in(&self, frame: &ShearedRay, ray: &Ray, prim: u32, hit: &mut Hit) -> bool {
        if !frame.is_usable() {
            return false;
        }
        // Spelled out, not `array::map`, which the tests' level-1 builds leave
        // out of line: it was half of the brute-force oracle's time there.
        let [p, q, r] = self.vertices;
        let [a, b, c] = [frame.relative(p), frame.relative(q), frame.relative(r)];
        let [u, v, w] = edge_functions(a, b, c, frame.shear);
        // Inside when no two edge functions have opposite signs.
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return false;
        }
        let [distance, slope] = plane_distance(a, b, c, frame.dir);
        // The sum of the edge functions and its reciprocal must be finite and
        // not zero: zero is a ray along the plane (or a triangle of no area),
        // infinite or NaN an overflow of the products, and a subnormal sum's
        // reciprocal overflows (and the barycentrics would be NaN).
        let inverse = 1.0 / (u + v + w);
        if !(usable_denominator(inverse) && usable_denominator(slope)) {
            return false;
        }
        let t = distance / slope;
        if !hit.accepts(t, ray.t_min, prim) {
            return false;
        }
        hit.record(t, prim, v * inverse, w * inverse);
        true
    }
}

impl crate::geometry::Intersect for WatertightTriangle {
    /// Scalar kernel.
    #[inline]
    fn intersect(&self, ray: &Ray, prim: u32, hit: &mut Hit) -> bool {
        self.intersect_in(&ShearedRay::new(ray), ray, prim, hit)
    }

    /// Packet kernel: one triangle against every active lane.
    #[inline(always)]
    fn intersect_packet<F: SimdFloat>(&self, rays: &RayPacket<F>, prim: u32, hits: &mut HitPacket<F>) {
        intersect_packet_lane(self, 0, rays, prim, hits);
    }
}

/// Where the packet kernel reads a triangle's vertices: a
/// [`WatertightTriangle`] or one lane of a [`WatertightTriangles`] block, in place.
trait TriangleVertices {
    /// Lane `i`'s vertex `corner`, component `axis`.
    fn coordinate(&self, i: usize, corner: usize, axis: usize) -> f32;
}

impl TriangleVertices for WatertightTriangle {
    #[inline(always)]
    fn coordinate(&self, _: usize, corner: usize, axis: usize) -> f32 {
        WatertightTriangle::coordinate(self, corner, axis)
    }
}

/// The packet kernel: the triangle in lane `i` of `tri` against every active
/// lane of `rays`, each lane in its own ray's frame (chosen by selects, the
/// scalar kernel's choice lane by lane).
#[inline(always)]
fn intersect_packet_lane<F: SimdFloat, T: TriangleVertices>(
    tri: &T,
    i: usize,
    rays: &RayPacket<F>,
    prim: u32,
    hits: &mut HitPacket<F>,
) {
    let (o, d) = (&rays.origin, &rays.dir);
    // Each lane's dominant axis, as `ShearedRay::new` picks it, and whether it
    // points backwards (which swaps the other two).
    let (ax, ay, az) = (d.x.abs(), d.y.abs(), d.z.abs());
    let frame = LaneFrame {
        on_x: ax.ge(ay) & ax.ge(az),
        on_y: ay.ge(az),
        flip: F::splat(0.0),
    };
    let frame = LaneFrame {
        flip: frame.permute([d.x, d.y, d.z])[2].lt(F::splat(0.0)),
        ..frame
    };
    let dir = frame.permute([d.x, d.y, d.z]);
    // (A lane whose dominant component is infinite is refused below, as
    // `ShearedRay::is_usable` refuses it.)
    let shear = [dir[0] / dir[2], dir[1] / dir[2], F::splat(1.0) / dir[2]];
    let a = frame.relative(tri, i, 0, o);
    let b = frame.relative(tri, i, 1, o);
    let c = frame.relative(tri, i, 2, o);
    let [u, v, w] = edge_functions(a, b, c, shear);
    let inside = rays.active.and_not(straddles(u, v, w));
    if inside.none() {
        return;
    }
    let [distance, slope] = plane_distance(a, b, c, dir);
    let inverse = F::splat(1.0) / (u + v + w);
    let t = distance / slope;
    let mask = hits.accepts_among(inside, rays, t, prim)
        & usable_denominators(inverse)
        & usable_denominators(slope)
        & usable_denominators(shear[2]);
    if mask.none() {
        return;
    }
    hits.record(mask, t, prim, v * inverse, w * inverse);
}

/// The lanes whose edge functions have opposite signs (zero counts as
/// either): the ray passes outside the triangle.
#[inline(always)]
fn straddles<F: SimdFloat>(u: F, v: F, w: F) -> F {
    let zero = F::splat(0.0);
    let negative = u.lt(zero) | v.lt(zero) | w.lt(zero);
    let positive = u.gt(zero) | v.gt(zero) | w.gt(zero);
    negative & positive
}

/// Each lane's shear frame in a packet: masks of the lanes whose dominant
/// axis is x, and (read where it is not) y, and of those whose dominant
/// component is negative.
#[derive(Clone, Copy)]
struct LaneFrame<F> {
    on_x: F,
    on_y: F,
    flip: F,
}

impl<F: SimdFloat> LaneFrame<F> {
    /// Each lane's components of `v` in its frame's order `(kx, ky, kz)`.
    #[inline(always)]
    fn permute(self, [x, y, z]: [F; 3]) -> [F; 3] {
        let (on_x, on_y) = (self.on_x, self.on_y);
        let k = on_x.select(x, on_y.select(y, z));
        let k1 = on_x.select(y, on_y.select(z, x));
        let k2 = on_x.select(z, on_y.select(x, y));
        [self.flip.select(k2, k1), self.flip.select(k1, k2), k]
    }

    /// Vertex `corner` of lane `i` of `tri`, relative to each lane's origin `o`, in its frame.
    #[inline(always)]
    fn relative<T: TriangleVertices>(self, tri: &T, i: usize, corner: usize, o: &V3<F>) -> [F; 3] {
        self.permute([
            F::splat(tri.coordinate(i, corner, 0)) - o.x,
            F::splat(tri.coordinate(i, corner, 1)) - o.y,
            F::splat(tri.coordinate(i, corner, 2)) - o.z,
        ])
    }
}

/// Up to `F::LANES` triangles' vertices in structure-of-arrays form, each lane
/// with the primitive index its hit reports, for one ray to test at once (as
/// [`ProjectedTriangles`](crate::geometry::triangle::ProjectedTriangles) for
/// the projected test). The ray's frame is the same in every lane, so each of
/// its axes picks a whole row. With `f32x8`: 10 × 32 = 320 bytes, five cache
/// lines; with `f32x4`: 160, padded to 192.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct WatertightTriangles<F: SimdFloat> {
    /// Row `3·corner + axis`: vertex `corner`'s component `axis`, lane by lane
    /// (NaN in an unused lane).
    vertices: [F::Array; 9],
    /// Primitive index each lane's hit reports.
    ids: <F::U32 as SimdU32>::Array,
}

impl<F: SimdFloat> WatertightTriangles<F> {
    block_lanes!();

    /// Lanes `0..tris.len()` hold `tris` (triangle and primitive index), the rest nothing.
    ///
    /// # Panics
    /// If `tris` has more than `F::LANES` entries.
    pub fn new(tris: &[(WatertightTriangle, u32)]) -> Self {
        let lanes = ShapeLanes::new::<F>(tris);
        Self {
            vertices: std::array::from_fn(|row| lanes.row::<F>(|t| t.coordinate(row / 3, row % 3), f32::NAN)),
            ids: lanes.ids::<F>(|_, id| id, 0),
        }
    }
}

impl<F: SimdFloat> WatertightTriangles<F> {
    /// Every lane's vertex `corner` relative to the ray's origin, in its frame's axis order.
    #[inline(always)]
    fn relative<N: SimdFloat<Array = F::Array>>(&self, corner: usize, ray: &ShearedRay) -> [N; 3] {
        [
            self.relative_row(corner, ray, 0),
            self.relative_row(corner, ray, 1),
            self.relative_row(corner, ray, 2),
        ]
    }

    /// Every lane's vertex `corner`, the frame's component `k` (0: x, 1: y, 2: z),
    /// relative to the ray's origin.
    #[inline(always)]
    fn relative_row<N: SimdFloat<Array = F::Array>>(&self, corner: usize, ray: &ShearedRay, k: usize) -> N {
        N::from_array(self.vertices[3 * corner + ray.axes[k]]) - N::splat(ray.origin[k])
    }
}

impl<F: SimdFloat> BlockIntersect for WatertightTriangles<F> {
    type Lanes = F;

    #[inline(always)]
    fn id(&self, i: usize) -> u32 {
        self.ids.as_ref()[i]
    }

    /// One ray against every lane (the scalar kernel's arithmetic, lane by
    /// lane): records in `hit` what the scalar kernel run over the lanes in
    /// any order would, and returns true if any lane's hit was recorded.
    #[inline(always)]
    fn intersect_with<N: SimdFloat<Array = F::Array>>(&self, ray: &BlockRay, hit: &mut Hit) -> bool {
        // The frame was made once for the ray ([`BlockRay`]): a block holds a
        // leaf of 4 triangles or fewer on most meshes, and a ray meets several.
        let frame = &ray.sheared;
        if !frame.is_usable() {
            return false;
        }
        let shear = [
            N::splat(frame.shear[0]),
            N::splat(frame.shear[1]),
            N::splat(frame.shear[2]),
        ];
        let (a, b, c) = (
            self.relative(0, frame),
            self.relative(1, frame),
            self.relative(2, frame),
        );
        let [u, v, w] = edge_functions(a, b, c, shear);
        // Most blocks a ray meets hold no triangle it passes inside: they end
        // here, before the plane's arithmetic and the two divisions.
        let inside = straddles(u, v, w).bitmask() ^ ((1 << N::LANES) - 1);
        if inside == 0 {
            return false;
        }
        let dir = [
            N::splat(frame.dir[0]),
            N::splat(frame.dir[1]),
            N::splat(frame.dir[2]),
        ];
        let [distance, slope] = plane_distance(a, b, c, dir);
        let inverse = N::splat(1.0) / (u + v + w);
        let t = distance / slope;
        // Lanes hit within [t_min, hit.t]; the record's own rule (ties, t < ∞)
        // settles among them.
        let ray = ray.ray;
        let candidates = usable_denominators(inverse)
            & usable_denominators(slope)
            & t.ge(N::splat(ray.t_min))
            & t.le(N::splat(hit.t));
        hit.record_nearest_lane(
            candidates.bitmask() & inside,
            t,
            v * inverse,
            w * inverse,
            |i| self.id(i),
            ray.t_min,
        )
    }
}

impl<F: SimdFloat> TriangleVertices for WatertightTriangles<F> {
    #[inline(always)]
    fn coordinate(&self, i: usize, corner: usize, axis: usize) -> f32 {
        self.vertices[3 * corner + axis].as_ref()[i]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Intersect;
    use wide::f32x8;

    /// A needle from 10⁻³⁸ to 10³⁸ whose edge functions overflow: every
    /// kernel misses it (the block kernel once took a NaN sum for a hit).
    #[test]
    fn a_needle_of_extreme_coordinates_is_missed_by_every_kernel() {
        let tri = WatertightTriangle::new(
            Vec3::new(1.175_494_4e-38, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 1e38),
            Vec3::new(0.0, 0.010_560_456, 0.0),
        );
        let ray = Ray::unbounded(
            Vec3::new(-0.589_454_05, 0.0, -7.231_158),
            Vec3::new(0.478_378_12, 0.551_014_54, -0.683_767),
        );
        assert!(!tri.intersect(&ray, 0, &mut Hit::none(&ray)));
        let packet = RayPacket::<f32x8>::from_rays(&[ray]);
        let mut hits = HitPacket::none(&packet);
        tri.intersect_packet(&packet, 0, &mut hits);
        assert!(!hits.hit(0).is_hit());
        let block = WatertightTriangles::<f32x8>::new(&[(tri, 0)]);
        assert!(!block.intersect(&ray, &mut Hit::none(&ray)));
    }
}
