//! Triangle: the lecture's projected barycentric test (section 6), scalar and
//! packet kernels, and its half-plane test as the scalar reference.
//!
//! The plane equation is divided by the normal's dominant component `n_k`, and the
//! hit point is projected onto the coordinate plane that drops axis `k`, where the
//! triangle's projection is largest. With `(ku, kv) = (k+1, k+2) mod 3`:
//!
//! ```text
//! t = (n_d − o_k − n_u·o_ku − n_v·o_kv) / (d_k + n_u·d_ku + n_v·d_kv)
//! h = (o_ku + t·d_ku − a_ku,  o_kv + t·d_kv − a_kv)
//! β = h_u·b_nu + h_v·b_nv,   γ = h_u·c_nu + h_v·c_nv
//! ```
//!
//! inside iff `β ≥ 0, γ ≥ 0, β + γ ≤ 1` (edges and vertices count as inside).
//! This is the lecture's `λ` formulas with `a` as the reference vertex; all the
//! per-triangle constants are precomputed once, a layout introduced by I. Wald,
//! "Realtime Ray Tracing and Interactive Global Illumination", PhD thesis, 2004, §7.1.

use glam::Vec3;

use crate::bounds::Aabb;
use crate::geometry::triangle_watertight::WatertightTriangle;
use crate::geometry::{
    BlockIntersect, BlockRay, Intersect, ShapeLanes, block_lanes, usable_denominator, usable_denominators,
};
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, Ray};
use crate::simd::{SimdFloat, SimdU32};

/// How far outside its edges, in barycentric units, a triangle still counts as
/// hit. Two triangles sharing an edge compute its barycentrics in their own
/// projection frames and may round a ray through the shared edge or vertex
/// outside both; this margin (a few f32 ulps of 1) closes those cracks.
const EDGE_EPSILON: f32 = 1.0 / (1 << 20) as f32;

/// Dropped-axis value marking a zero-area triangle, which every ray misses.
const DEGENERATE: u32 = 3;

/// The two axes kept by the projection that drops axis `k`: `(k + 1) % 3`, `(k + 2) % 3`.
const OTHER_AXES: [[usize; 2]; 3] = [[1, 2], [2, 0], [0, 1]];

/// Which ray/triangle test a triangle's kernels run.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, clap::ValueEnum, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum TriangleTest {
    /// The lecture's projected barycentric test (this file), with an edge
    /// margin of `EDGE_EPSILON` (2⁻²⁰): fewest operations, but a ray through a
    /// shared edge or vertex may slip between the two triangles' roundings.
    /// Polygons run the lecture's crossing test.
    Barycentric,
    /// The watertight test of Woop, Benthin and Wald 2013
    /// ([`triangle_watertight`](crate::geometry::triangle_watertight)): no ray
    /// passes between triangles that share an edge. Polygons are tested as
    /// their surface cut into such triangles.
    #[default]
    Watertight,
}

impl TriangleTest {
    /// The name on the command line and in results.
    pub fn name(self) -> &'static str {
        match self {
            Self::Barycentric => "barycentric",
            Self::Watertight => "watertight",
        }
    }
}

/// A triangle: its vertices, its projected-barycentric constants, the scale
/// of its normal and the test its kernels run. 84 bytes (36 of vertices, 40
/// of constants, 4 of scale, 1 of test, 3 of padding).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    /// Vertices `a, b, c` as given.
    vertices: [Vec3; 3],
    /// What the projected test reads.
    projected: ProjectedTriangle,
    /// Scale of the unit normal: `n_k / |n|` (its sign fixes the orientation).
    n_scale: f32,
    /// The test the kernels run.
    test: TriangleTest,
}

/// The constants of the projected barycentric test, all the kernels read: a
/// BVH leaf stores these alone (Wald's layout, 40 bytes with no padding).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProjectedTriangle {
    /// Dominant normal axis `k` (dropped in the projection), or [`DEGENERATE`].
    k: u32,
    /// `n_ku / n_k`.
    n_u: f32,
    /// `n_kv / n_k`.
    n_v: f32,
    /// `⟨n, a⟩ / n_k`.
    n_d: f32,
    /// Vertex `a` projected: `a_ku`.
    a_u: f32,
    /// `a_kv`.
    a_v: f32,
    /// Row of the inverse 2×2 edge matrix giving β.
    b_nu: f32,
    /// See `b_nu`.
    b_nv: f32,
    /// Row of the inverse 2×2 edge matrix giving γ.
    c_nu: f32,
    /// See `c_nu`.
    c_nv: f32,
}

impl ProjectedTriangle {
    /// The constants of a zero-area triangle, which every ray misses.
    pub const ZERO_AREA: ProjectedTriangle = ProjectedTriangle {
        k: DEGENERATE,
        n_u: 0.0,
        n_v: 0.0,
        n_d: 0.0,
        a_u: 0.0,
        a_v: 0.0,
        b_nu: 0.0,
        b_nv: 0.0,
        c_nu: 0.0,
        c_nv: 0.0,
    };
}

impl Triangle {
    /// Triangle `a, b, c` under the default test ([`TriangleTest::default`]),
    /// with the projected-barycentric constants precomputed. A zero-area (or
    /// non-finite) triangle is kept but never hit.
    pub fn new(a: Vec3, b: Vec3, c: Vec3) -> Self {
        let e1 = b - a;
        let e2 = c - a;
        let n = e1.cross(e2);
        let abs = n.abs();
        let k = if abs.x >= abs.y && abs.x >= abs.z {
            0
        } else if abs.y >= abs.z {
            1
        } else {
            2
        };
        let (ku, kv) = ((k + 1) % 3, (k + 2) % 3);
        let nk = n[k];
        // n_k is the 2×2 determinant of the projected edges [e1 e2].
        let det = e1[ku] * e2[kv] - e1[kv] * e2[ku];
        let degenerate = !(nk != 0.0 && det != 0.0 && n.is_finite() && a.is_finite());
        if degenerate {
            return Self {
                vertices: [a, b, c],
                projected: ProjectedTriangle::ZERO_AREA,
                n_scale: 0.0,
                test: TriangleTest::default(),
            };
        }
        Self {
            vertices: [a, b, c],
            projected: ProjectedTriangle {
                k: k as u32,
                n_u: n[ku] / nk,
                n_v: n[kv] / nk,
                n_d: n.dot(a) / nk,
                a_u: a[ku],
                a_v: a[kv],
                b_nu: e2[kv] / det,
                b_nv: -e2[ku] / det,
                c_nu: -e1[kv] / det,
                c_nv: e1[ku] / det,
            },
            n_scale: nk / n.length(),
            test: TriangleTest::default(),
        }
    }

    /// The same triangle under `test`.
    pub fn with_test(self, test: TriangleTest) -> Self {
        Self { test, ..self }
    }

    /// The test the kernels run.
    pub fn test(&self) -> TriangleTest {
        self.test
    }

    /// The constants the projected test reads.
    pub fn projected(&self) -> &ProjectedTriangle {
        &self.projected
    }

    /// What the watertight test reads: the vertices, or a triangle no ray
    /// hits if this one is degenerate (which both tests miss alike).
    pub fn watertight(&self) -> WatertightTriangle {
        if self.is_degenerate() {
            return WatertightTriangle::NEVER_HIT;
        }
        let [a, b, c] = self.vertices;
        WatertightTriangle::new(a, b, c)
    }

    /// Vertices `a, b, c`.
    pub fn vertices(&self) -> [Vec3; 3] {
        self.vertices
    }

    /// Bounding box of every point the kernels can hit; None for a degenerate
    /// triangle, which no ray can hit.
    ///
    /// The kernels accept hits up to `EDGE_EPSILON` (2⁻²⁰) outside the edges in
    /// barycentric units, which is that fraction of the edges' length in space:
    /// the corners of the accepted region lie within `3·EDGE_EPSILON` of the
    /// edge vectors from the vertices, so the vertices' box is grown by
    /// `4·EDGE_EPSILON` of its extent (the spare for rounding). Negligible on
    /// ordinary triangles; a needle 4·10¹⁸ long (a fuzzer's) is hit up to 10¹²
    /// beyond its end, where a BVH must not cull it.
    pub fn bounds(&self) -> Option<Aabb> {
        (!self.is_degenerate()).then(|| Self::bounds_of(self.vertices))
    }

    /// The box [`Triangle::bounds`] gives a triangle of `vertices` that is
    /// not degenerate: theirs, widened by the edge margin.
    pub fn bounds_of(vertices: [Vec3; 3]) -> Aabb {
        let tight = Aabb::from_points(vertices);
        let margin = 4.0 * EDGE_EPSILON * tight.extent();
        Aabb::new(tight.min - margin, tight.max + margin)
    }

    /// True for a zero-area triangle.
    pub fn is_degenerate(&self) -> bool {
        self.projected.k == DEGENERATE
    }

    /// Unit geometric normal `(b − a) × (c − a) / |…|` (zero for a degenerate triangle).
    pub fn normal(&self) -> Vec3 {
        if self.is_degenerate() {
            return Vec3::ZERO;
        }
        let p = &self.projected;
        let k = p.k as usize;
        let mut n = Vec3::ZERO;
        n[k] = 1.0;
        n[(k + 1) % 3] = p.n_u;
        n[(k + 2) % 3] = p.n_v;
        n.normalize() * self.n_scale.signum()
    }
}

impl Intersect for Triangle {
    #[inline(always)]
    fn intersect(&self, ray: &Ray, prim: u32, hit: &mut Hit) -> bool {
        match self.test {
            TriangleTest::Barycentric => self.projected.intersect(ray, prim, hit),
            TriangleTest::Watertight => self.watertight().intersect(ray, prim, hit),
        }
    }

    #[inline(always)]
    fn intersect_packet<F: SimdFloat>(&self, rays: &RayPacket<F>, prim: u32, hits: &mut HitPacket<F>) {
        match self.test {
            TriangleTest::Barycentric => self.projected.intersect_packet(rays, prim, hits),
            TriangleTest::Watertight => self.watertight().intersect_packet(rays, prim, hits),
        }
    }
}

impl Intersect for ProjectedTriangle {
    /// Scalar kernel.
    #[inline]
    fn intersect(&self, ray: &Ray, prim: u32, hit: &mut Hit) -> bool {
        let k = self.k as usize;
        if k == DEGENERATE as usize {
            return false;
        }
        // Index plain arrays with a table of the other two axes: indexing a
        // `Vec3` by a runtime axis compiles to a chain of branches.
        let [ku, kv] = OTHER_AXES[k];
        let (o, d) = (ray.origin.to_array(), ray.dir.to_array());
        let denom = d[k] + self.n_u * d[ku] + self.n_v * d[kv];
        if !usable_denominator(denom) {
            return false;
        }
        let t = (self.n_d - o[k] - self.n_u * o[ku] - self.n_v * o[kv]) / denom;
        if !hit.accepts(t, ray.t_min, prim) {
            return false;
        }
        let hu = o[ku] + t * d[ku] - self.a_u;
        let hv = o[kv] + t * d[kv] - self.a_v;
        let beta = hu * self.b_nu + hv * self.b_nv;
        let gamma = hu * self.c_nu + hv * self.c_nv;
        if !(beta >= -EDGE_EPSILON && gamma >= -EDGE_EPSILON && beta + gamma <= 1.0 + EDGE_EPSILON) {
            return false;
        }
        hit.record(t, prim, beta, gamma);
        true
    }

    /// Packet kernel: one triangle against every active lane.
    #[inline(always)]
    fn intersect_packet<F: SimdFloat>(&self, rays: &RayPacket<F>, prim: u32, hits: &mut HitPacket<F>) {
        intersect_packet_lane(self, 0, rays, prim, hits);
    }
}

/// A constant of the projected test, naming a field of [`ProjectedTriangle`];
/// its value is the constant's row in a [`ProjectedTriangles`] block.
#[derive(Clone, Copy)]
enum Constant {
    Nu,
    Nv,
    Nd,
    Au,
    Av,
    BNu,
    BNv,
    CNu,
    CNv,
}

impl Constant {
    /// Every constant, in row order.
    const ALL: [Constant; 9] = [
        Constant::Nu,
        Constant::Nv,
        Constant::Nd,
        Constant::Au,
        Constant::Av,
        Constant::BNu,
        Constant::BNv,
        Constant::CNu,
        Constant::CNv,
    ];
}

/// Where the packet kernel reads a triangle's constants: a
/// [`ProjectedTriangle`], or one lane of a [`ProjectedTriangles`] block, read
/// in place (copied out into a [`ProjectedTriangle`] first, the lanes went
/// through the stack with store-forwarding stalls, and packets slowed by a quarter).
trait TriangleConstants {
    /// Lane `i`'s dropped axis `k`.
    fn axis(&self, i: usize) -> u32;
    /// Lane `i`'s constant `c`.
    fn constant(&self, i: usize, c: Constant) -> f32;
}

impl TriangleConstants for ProjectedTriangle {
    #[inline(always)]
    fn axis(&self, _: usize) -> u32 {
        self.k
    }

    #[inline(always)]
    fn constant(&self, _: usize, c: Constant) -> f32 {
        match c {
            Constant::Nu => self.n_u,
            Constant::Nv => self.n_v,
            Constant::Nd => self.n_d,
            Constant::Au => self.a_u,
            Constant::Av => self.a_v,
            Constant::BNu => self.b_nu,
            Constant::BNv => self.b_nv,
            Constant::CNu => self.c_nu,
            Constant::CNv => self.c_nv,
        }
    }
}

/// The packet kernel: the triangle in lane `i` of `tri` against every active lane of `rays`.
#[inline(always)]
fn intersect_packet_lane<F: SimdFloat, T: TriangleConstants>(
    tri: &T,
    i: usize,
    rays: &RayPacket<F>,
    prim: u32,
    hits: &mut HitPacket<F>,
) {
    let k = tri.axis(i) as usize;
    if k == DEGENERATE as usize {
        return;
    }
    let c = |c: Constant| F::splat(tri.constant(i, c));
    let [ku, kv] = OTHER_AXES[k];
    let (o, d) = (&rays.origin, &rays.dir);
    let (n_u, n_v) = (c(Constant::Nu), c(Constant::Nv));
    let denom = d.axis(k) + n_u * d.axis(ku) + n_v * d.axis(kv);
    let t = (c(Constant::Nd) - o.axis(k) - n_u * o.axis(ku) - n_v * o.axis(kv)) / denom;
    let mut mask = hits.accepts(rays, t, prim) & usable_denominators(denom);
    if mask.none() {
        return;
    }
    let hu = o.axis(ku) + t * d.axis(ku) - c(Constant::Au);
    let hv = o.axis(kv) + t * d.axis(kv) - c(Constant::Av);
    let beta = hu * c(Constant::BNu) + hv * c(Constant::BNv);
    let gamma = hu * c(Constant::CNu) + hv * c(Constant::CNv);
    let low = F::splat(-EDGE_EPSILON);
    mask = mask & beta.ge(low) & gamma.ge(low) & (beta + gamma).le(F::splat(1.0 + EDGE_EPSILON));
    hits.record(mask, t, prim, beta, gamma);
}

/// Up to `F::LANES` triangles' projected-barycentric constants in
/// structure-of-arrays form, each lane with the primitive index its hit
/// reports, so one ray tests them all in one SIMD pass with no branch per
/// triangle (the layout of Embree's `Triangle4` leaves, Wald et al., "Embree: a
/// kernel framework for efficient CPU ray tracing", SIGGRAPH 2014). A BVH leaf
/// of triangles stores them this way. Each lane's dropped axis `k` rides in the
/// top two bits of its primitive index, so that with `f32x8` a block is 10 × 32
/// = 320 bytes, five cache lines (a row of its own for `k` made it six: a
/// sixth more memory for the rays to pull in at the bottom of a large tree).
/// With `f32x4`: 10 × 16 = 160 bytes, padded to 192 (three cache lines).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct ProjectedTriangles<F: SimdFloat> {
    /// The constants of [`ProjectedTriangle`] but `k`, one row per [`Constant`], lane by lane.
    constants: [F::Array; 9],
    /// Each lane's primitive index (the low [`BLOCK_ID_BITS`] bits) and
    /// dropped axis `k` (the two bits above; [`DEGENERATE`] for a degenerate
    /// or unused lane).
    tagged_ids: <F::U32 as SimdU32>::Array,
}

/// Bits of a [`ProjectedTriangles`] lane's primitive index: blocks hold
/// triangles whose input index is at most [`MAX_BLOCK_ID`].
const BLOCK_ID_BITS: u32 = 30;

/// The largest primitive index a [`ProjectedTriangles`] lane holds (2³⁰ − 1).
pub const MAX_BLOCK_ID: u32 = (1 << BLOCK_ID_BITS) - 1;

impl<F: SimdFloat> ProjectedTriangles<F> {
    block_lanes!();

    /// The row of constant `c`, in the lane type `N` of the block's width.
    #[inline(always)]
    fn row<N: SimdFloat<Array = F::Array>>(&self, c: Constant) -> N {
        N::from_array(self.constants[c as usize])
    }

    /// Lanes `0..tris.len()` hold `tris` (constants and primitive index), the rest nothing.
    ///
    /// # Panics
    /// If `tris` has more than `F::LANES` entries, or an index above [`MAX_BLOCK_ID`].
    pub fn new(tris: &[(ProjectedTriangle, u32)]) -> Self {
        let lanes = ShapeLanes::new::<F>(tris);
        let tag = |t: &ProjectedTriangle, id: u32| {
            assert!(
                id <= MAX_BLOCK_ID,
                "primitive index {id} does not fit a triangle block"
            );
            id | t.k << BLOCK_ID_BITS
        };
        Self {
            constants: Constant::ALL.map(|c| lanes.row::<F>(|t| t.constant(0, c), 0.0)),
            tagged_ids: lanes.ids::<F>(tag, DEGENERATE << BLOCK_ID_BITS),
        }
    }
}

impl<F: SimdFloat> BlockIntersect for ProjectedTriangles<F> {
    type Lanes = F;

    #[inline(always)]
    fn id(&self, i: usize) -> u32 {
        self.tagged_ids.as_ref()[i] & MAX_BLOCK_ID
    }

    /// One ray against every lane (the scalar kernel's arithmetic, lane by
    /// lane, so each lane's t, β, γ are bit for bit the scalar ones): records
    /// in `hit` what the scalar kernel run over the lanes in any order would,
    /// and returns true if any lane's hit was recorded.
    #[inline(always)]
    fn intersect_with<N: SimdFloat<Array = F::Array>>(&self, ray: &BlockRay, hit: &mut Hit) -> bool {
        let ray = ray.ray;
        // (No closures or array maps here: this is compiled into each
        // instruction set's entry point only if everything inlines.)
        let mut tagged_ids = <N::U32 as SimdU32>::Array::default();
        tagged_ids.as_mut().copy_from_slice(self.tagged_ids.as_ref());
        let tagged_ids = N::U32::from_array(tagged_ids);
        let (n_u, n_v, n_d): (N, N, N) = (
            self.row(Constant::Nu),
            self.row(Constant::Nv),
            self.row(Constant::Nd),
        );
        let (a_u, a_v): (N, N) = (self.row(Constant::Au), self.row(Constant::Av));
        let (b_nu, b_nv): (N, N) = (self.row(Constant::BNu), self.row(Constant::BNv));
        let (c_nu, c_nv): (N, N) = (self.row(Constant::CNu), self.row(Constant::CNv));
        // Each lane's ray components along its own axes k, ku, kv.
        // k = 0 and k ≤ 1, read off the tag bits by unsigned comparisons.
        let on_x = tagged_ids.lt(N::U32::splat(1 << BLOCK_ID_BITS));
        let on_y = tagged_ids.lt(N::U32::splat(2 << BLOCK_ID_BITS));
        let (o_k, o_ku, o_kv) = per_lane_axes(ray.origin, on_x, on_y);
        let (d_k, d_ku, d_kv) = per_lane_axes(ray.dir, on_x, on_y);
        let denom = d_k + n_u * d_ku + n_v * d_kv;
        let t = (n_d - o_k - n_u * o_ku - n_v * o_kv) / denom;
        let hu = o_ku + t * d_ku - a_u;
        let hv = o_kv + t * d_kv - a_v;
        let beta = hu * b_nu + hv * b_nv;
        let gamma = hu * c_nu + hv * c_nv;
        let low = N::splat(-EDGE_EPSILON);
        // Lanes hit within [t_min, hit.t]; the record's own rule (ties, t < ∞)
        // settles among them.
        let candidates = tagged_ids.lt(N::U32::splat(DEGENERATE << BLOCK_ID_BITS))
            & usable_denominators(denom)
            & t.ge(N::splat(ray.t_min))
            & t.le(N::splat(hit.t))
            & beta.ge(low)
            & gamma.ge(low)
            & (beta + gamma).le(N::splat(1.0 + EDGE_EPSILON));
        hit.record_nearest_lane(candidates.bitmask(), t, beta, gamma, |i| self.id(i), ray.t_min)
    }
}

impl<F: SimdFloat> TriangleConstants for ProjectedTriangles<F> {
    #[inline(always)]
    fn axis(&self, i: usize) -> u32 {
        self.tagged_ids.as_ref()[i] >> BLOCK_ID_BITS
    }

    #[inline(always)]
    fn constant(&self, i: usize, c: Constant) -> f32 {
        self.constants[c as usize].as_ref()[i]
    }
}

/// Per lane, the components of `v` along the lane's own axes k, ku, kv, where
/// `on_x` marks the lanes whose dropped axis k is x and `on_y`, read only in
/// the other lanes, those where it is y.
#[inline(always)]
fn per_lane_axes<N: SimdFloat>(v: Vec3, on_x: N, on_y: N) -> (N, N, N) {
    let (x, y, z) = (N::splat(v.x), N::splat(v.y), N::splat(v.z));
    (
        on_x.select(x, on_y.select(y, z)),
        on_x.select(y, on_y.select(z, x)),
        on_x.select(z, on_y.select(x, y)),
    )
}

/// The lecture's half-plane test, kept as the reference the projected test is
/// checked against: the plane hit `p`, then `⟨(p − a) × (b − a), n⟩ ≥ 0`,
/// `⟨(p − b) × (c − b), n⟩ ≥ 0`, `⟨(p − c) × (a − c), n⟩ ≥ 0` with
/// `n = (c − a) × (b − a)`. Returns the hit's t in `[t_min, t_max]`.
pub fn intersect_half_plane(a: Vec3, b: Vec3, c: Vec3, ray: &Ray) -> Option<f32> {
    let n = (c - a).cross(b - a);
    let denom = n.dot(ray.dir);
    if denom == 0.0 {
        return None;
    }
    let t = n.dot(a - ray.origin) / denom;
    if !(t >= ray.t_min && t <= ray.t_max && t.is_finite()) {
        return None;
    }
    let p = ray.at(t);
    let inside = (p - a).cross(b - a).dot(n) >= 0.0
        && (p - b).cross(c - b).dot(n) >= 0.0
        && (p - c).cross(a - c).dot(n) >= 0.0;
    inside.then_some(t)
}
