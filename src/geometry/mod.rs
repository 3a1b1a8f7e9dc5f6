//! The primitives of the lecture, each with a scalar and a packet kernel side by
//! side in its own file, and [`Primitive`], the enum that dispatches to them.
//!
//! Every kernel has the same contract: it finds the nearest hit of the ray with
//! the shape in `[t_min, hit.t]` and records it (t, primitive index, u, v) only
//! if [`Hit::accepts`] it; a miss leaves the record untouched. Packet kernels do
//! the same on every active lane and must agree with the scalar kernel lane by lane.

pub mod cone;
pub mod ear_clip;
pub mod plane;
pub mod polygon;
pub mod sphere;
pub mod transformed;
pub mod triangle;
pub mod triangle_watertight;

use glam::Vec3;

pub use cone::Cone;
pub use plane::Plane;
pub use polygon::Polygon;
pub use sphere::Sphere;
pub use transformed::Transformed;
pub use triangle::{Triangle, TriangleTest};
pub use triangle_watertight::ShearedRay;

use crate::bounds::Aabb;
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, Ray};
use crate::simd::{SimdFloat, SimdU32};

/// Why a primitive cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GeometryError {
    /// A NaN or infinite coordinate.
    #[error("non-finite coordinate")]
    NotFinite,
    /// A plane normal (or `i × j`) of zero length.
    #[error("plane normal is zero (spanning vectors are parallel)")]
    DegeneratePlane,
    /// A polygon with fewer than three vertices.
    #[error("polygon needs at least 3 vertices, got {0}")]
    TooFewVertices(usize),
    /// A polygon whose first three vertices (which fix its normal) are collinear.
    #[error("the first three polygon vertices are collinear")]
    CollinearVertices,
    /// A transform whose bottom row is not `0 0 0 1`.
    #[error("transform is not affine (bottom row must be 0 0 0 1)")]
    NotAffine,
    /// A transform that cannot be inverted.
    #[error("transform is singular")]
    SingularTransform,
    /// A negative radius where only radii ≥ 0 make sense.
    #[error("radius {0} is negative")]
    NegativeRadius(f32),
    /// A cone whose base and apex centres coincide, or whose radii are both 0.
    #[error("cone is degenerate (base and apex centres coincide, or both radii are 0)")]
    DegenerateCone,
}

/// A shape's intersection kernels, scalar and packet, with one contract: find
/// the nearest hit in `[t_min, hit.t]` and record it only where
/// [`Hit::accepts`] allows; a miss leaves the record untouched.
pub trait Intersect {
    /// Scalar kernel: returns whether the record was updated.
    fn intersect(&self, ray: &Ray, prim: u32, hit: &mut Hit) -> bool;

    /// Packet kernel: the scalar kernel on every active lane.
    fn intersect_packet<F: SimdFloat>(&self, rays: &RayPacket<F>, prim: u32, hits: &mut HitPacket<F>);
}

/// True when a plane-hit denominator `⟨n, v⟩` is neither zero (the ray is
/// parallel to the plane) nor infinite nor NaN (an infinite direction would
/// otherwise give `t = 0`).
#[inline(always)]
pub fn usable_denominator(denom: f32) -> bool {
    denom != 0.0 && denom.abs() < f32::INFINITY
}

/// Lane mask of [`usable_denominator`].
#[inline(always)]
pub fn usable_denominators<F: SimdFloat>(denom: F) -> F {
    denom.ne(F::splat(0.0)) & denom.abs().lt(F::splat(f32::INFINITY))
}

/// A ray as the block kernels take it: the ray, and what a kernel derives
/// from the ray alone, made once per ray rather than at every block it meets
/// (the watertight test's shear frame: three divisions and the choice of
/// axes). 72 bytes.
#[derive(Clone, Copy, Debug)]
pub struct BlockRay<'a> {
    /// The ray.
    pub ray: &'a Ray,
    /// Its shear frame, for [`triangle_watertight`].
    pub sheared: ShearedRay,
}

impl<'a> BlockRay<'a> {
    /// `ray`, prepared for the block kernels.
    #[inline(always)]
    pub fn new(ray: &'a Ray) -> Self {
        Self {
            ray,
            sheared: ShearedRay::new(ray),
        }
    }
}

/// How a query holds its ray for the leaves' block kernels: prepared when
/// the walk starts ([`BlockRay`]) or at its first leaf ([`LazyBlockRay`]).
pub trait LeafRay<'a>: Sized {
    /// `ray`, held for the leaves.
    fn hold(ray: &'a Ray) -> Self;

    /// The ray.
    fn ray(&self) -> &'a Ray;

    /// The prepared ray.
    fn get(&mut self) -> &BlockRay<'a>;
}

/// Prepared at once: for walks sure to reach a leaf (a packet's lane handed
/// to a single-ray walk deep in the tree), where checking for the frame at
/// every leaf would be work for nothing.
impl<'a> LeafRay<'a> for BlockRay<'a> {
    #[inline(always)]
    fn hold(ray: &'a Ray) -> Self {
        BlockRay::new(ray)
    }

    #[inline(always)]
    fn ray(&self) -> &'a Ray {
        self.ray
    }

    #[inline(always)]
    fn get(&mut self) -> &BlockRay<'a> {
        self
    }
}

/// A [`BlockRay`] made when a walk reaches its first leaf rather than when
/// it starts: a walk that reaches none (a ray missing the root's box, or
/// passing through an instance's box between its mesh's leaves) never makes
/// the shear frame. 80 bytes.
#[derive(Clone, Copy, Debug)]
pub struct LazyBlockRay<'a> {
    /// The ray.
    ray: &'a Ray,
    /// The prepared ray, once a leaf needed it.
    block: Option<BlockRay<'a>>,
}

impl<'a> LeafRay<'a> for LazyBlockRay<'a> {
    /// `ray`, not prepared yet.
    #[inline(always)]
    fn hold(ray: &'a Ray) -> Self {
        Self { ray, block: None }
    }

    #[inline(always)]
    fn ray(&self) -> &'a Ray {
        self.ray
    }

    /// The prepared ray, made at the first call.
    #[inline(always)]
    fn get(&mut self) -> &BlockRay<'a> {
        let ray = self.ray;
        self.block.get_or_insert_with(|| BlockRay::new(ray))
    }
}

/// Block kernels: one ray against up to `F::LANES` shapes held in
/// structure-of-arrays lanes ([`triangle::ProjectedTriangles`],
/// [`sphere::Spheres`], what BVH leaves store), in one SIMD pass with no branch
/// per shape and each lane bit for bit the scalar kernel; the packet kernels
/// read single lanes in place.
pub trait BlockIntersect {
    /// The lane type the block stores its rows as.
    type Lanes: SimdFloat;

    /// One ray against every lane, computed with the vectors of `N` (any
    /// instruction set's type of the block's width): records in `hit` what the
    /// scalar kernel run over the lanes in any order would; true if any lane's
    /// hit was recorded.
    fn intersect_with<N: SimdFloat<Array = <Self::Lanes as SimdFloat>::Array>>(
        &self,
        ray: &BlockRay,
        hit: &mut Hit,
    ) -> bool;

    /// [`intersect_with`](Self::intersect_with) the storage's own lane type.
    #[inline(always)]
    fn intersect(&self, ray: &Ray, hit: &mut Hit) -> bool {
        self.intersect_with::<Self::Lanes>(&BlockRay::new(ray), hit)
    }

    /// Primitive index of lane `i`'s shape.
    fn id(&self, i: usize) -> u32;
}

/// The packet kernel of one lane of a block, which every block spells alike:
/// the shape module's own `intersect_packet_lane` reading the lane in place
/// and recording its primitive index. Invoked inside each block's inherent
/// `impl` (an unused lane is never hit).
macro_rules! block_lanes {
    () => {
        /// The packet kernel of lane `i`'s shape, recording its primitive index.
        #[inline(always)]
        pub fn intersect_packet<G: SimdFloat>(&self, i: usize, rays: &RayPacket<G>, hits: &mut HitPacket<G>) {
            intersect_packet_lane(self, i, rays, self.id(i), hits);
        }
    };
}
pub(crate) use block_lanes;

/// Shapes with their primitive indices, spread over the lanes of a block
/// kernel's rows (`ProjectedTriangles`, `Spheres`): lane `i` holds shape `i`.
struct ShapeLanes<'a, T>(&'a [(T, u32)]);

impl<'a, T> ShapeLanes<'a, T> {
    /// The lanes of `shapes` at width `F`.
    ///
    /// # Panics
    /// If there are more shapes than lanes.
    fn new<F: SimdFloat>(shapes: &'a [(T, u32)]) -> Self {
        assert!(
            shapes.len() <= F::LANES,
            "{} shapes for {} lanes",
            shapes.len(),
            F::LANES
        );
        Self(shapes)
    }

    /// The row of `field`, with `unused` in the lanes past the shapes.
    fn row<F: SimdFloat>(&self, field: impl Fn(&T) -> f32, unused: f32) -> F::Array {
        let mut row = F::Array::default();
        row.as_mut().fill(unused);
        for (lane, (shape, _)) in row.as_mut().iter_mut().zip(self.0) {
            *lane = field(shape);
        }
        row
    }

    /// The row of `field` of each shape and its primitive index, with
    /// `unused` in the lanes past the shapes.
    fn ids<F: SimdFloat>(&self, field: impl Fn(&T, u32) -> u32, unused: u32) -> <F::U32 as SimdU32>::Array {
        let mut ids = <F::U32 as SimdU32>::Array::default();
        ids.as_mut().fill(unused);
        for (lane, (shape, id)) in ids.as_mut().iter_mut().zip(self.0) {
            *lane = field(shape, *id);
        }
        ids
    }
}

/// The kind of a primitive, for statistics and reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum PrimitiveKind {
    /// [`Sphere`].
    Sphere,
    /// [`Plane`].
    Plane,
    /// [`Triangle`].
    Triangle,
    /// [`Polygon`].
    Polygon,
    /// [`Cone`].
    Cone,
    /// [`Transformed`].
    Transformed,
}

/// Any primitive of the engine.
#[derive(Clone, Debug, PartialEq)]
pub enum Primitive {
    /// A sphere.
    Sphere(Sphere),
    /// An infinite plane (kept out of acceleration structures).
    Plane(Plane),
    /// A triangle.
    Triangle(Triangle),
    /// A planar polygon.
    Polygon(Polygon),
    /// A cone or cylinder without end caps.
    Cone(Cone),
    /// A primitive under an affine transform.
    Transformed(Box<Transformed>),
}

/// Run `$body` with `$p` bound to the shape inside any variant.
macro_rules! dispatch {
    ($self:expr, $p:ident => $body:expr) => {
        match $self {
            Primitive::Sphere($p) => $body,
            Primitive::Plane($p) => $body,
            Primitive::Triangle($p) => $body,
            Primitive::Polygon($p) => $body,
            Primitive::Cone($p) => $body,
            Primitive::Transformed($p) => $body,
        }
    };
}

impl Primitive {
    /// The polygon with `vertices` in order, refused as [`Polygon::new`]
    /// refuses it; one of three vertices is the [`Triangle`] it is. The
    /// triangle's kernels are the faster (in a BVH leaf, a block of 8 in one
    /// pass, where a polygon is one scalar call) and the watertight one closes
    /// the edges that triangles share, where the crossing test's rounding can
    /// let a ray through. (SPD `tetra` and `mount` are made of `p 3`.)
    pub fn polygon(vertices: &[Vec3]) -> Result<Primitive, GeometryError> {
        Polygon::normal_of(vertices)?;
        Ok(match *vertices {
            [a, b, c] => Primitive::Triangle(Triangle::new(a, b, c)),
            _ => Primitive::Polygon(Polygon::new(vertices)?),
        })
    }

    /// The kind of this primitive.
    pub fn kind(&self) -> PrimitiveKind {
        match self {
            Primitive::Sphere(_) => PrimitiveKind::Sphere,
            Primitive::Plane(_) => PrimitiveKind::Plane,
            Primitive::Triangle(_) => PrimitiveKind::Triangle,
            Primitive::Polygon(_) => PrimitiveKind::Polygon,
            Primitive::Cone(_) => PrimitiveKind::Cone,
            Primitive::Transformed(_) => PrimitiveKind::Transformed,
        }
    }

    /// Bounding box; None for unbounded primitives (planes) and for shapes that
    /// can never be hit (degenerate triangles).
    pub fn bounds(&self) -> Option<Aabb> {
        match self {
            Primitive::Sphere(s) => Some(s.bounds()),
            Primitive::Plane(_) => None,
            Primitive::Triangle(t) => t.bounds(),
            Primitive::Polygon(p) => Some(p.bounds()),
            Primitive::Cone(c) => Some(c.bounds()),
            Primitive::Transformed(t) => t.bounds(),
        }
    }

    /// Put every triangle and polygon in this primitive (a transformed one
    /// included) under `test`.
    pub fn set_triangle_test(&mut self, test: TriangleTest) {
        match self {
            Primitive::Triangle(t) => *t = t.with_test(test),
            Primitive::Polygon(p) => p.set_test(test),
            Primitive::Transformed(t) => t.set_triangle_test(test),
            _ => {}
        }
    }

    /// Unit geometric normal at the recorded hit of `ray`.
    pub fn geometric_normal(&self, ray: &Ray, hit: &Hit) -> Vec3 {
        match self {
            Primitive::Sphere(s) => s.normal_at(ray.at(hit.t)),
            Primitive::Plane(p) => p.normal(),
            Primitive::Triangle(t) => t.normal(),
            Primitive::Polygon(p) => p.normal(),
            Primitive::Cone(c) => c.normal_at(ray.at(hit.t)),
            Primitive::Transformed(t) => t.geometric_normal(ray, hit),
        }
    }
}

impl Intersect for Primitive {
    #[inline]
    fn intersect(&self, ray: &Ray, prim: u32, hit: &mut Hit) -> bool {
        dispatch!(self, p => p.intersect(ray, prim, hit))
    }

    /// Packet kernel.
    #[inline(always)]
    fn intersect_packet<F: SimdFloat>(&self, rays: &RayPacket<F>, prim: u32, hits: &mut HitPacket<F>) {
        match self {
            Primitive::Transformed(t) => t.intersect_packet(rays, prim, hits),
            _ => self.intersect_packet_object(rays, prim, hits),
        }
    }
}

impl Primitive {
    /// The packet kernel of a transformed primitive's object. All of it is
    /// inlined (so it runs with the caller's instruction set, see
    /// `accel::bvh::dispatch`) except a transform of a transform, whose
    /// recursion goes through one call that is not.
    #[inline(always)]
    pub(crate) fn intersect_packet_object<F: SimdFloat>(
        &self,
        rays: &RayPacket<F>,
        prim: u32,
        hits: &mut HitPacket<F>,
    ) {
        match self {
            Primitive::Sphere(p) => p.intersect_packet(rays, prim, hits),
            Primitive::Plane(p) => p.intersect_packet(rays, prim, hits),
            Primitive::Triangle(p) => p.intersect_packet(rays, prim, hits),
            Primitive::Polygon(p) => p.intersect_packet(rays, prim, hits),
            Primitive::Cone(p) => p.intersect_packet(rays, prim, hits),
            Primitive::Transformed(t) => nested_transform_packet(t, rays, prim, hits),
        }
    }
}

/// The packet kernel of a transform nested in another: the one call of the
/// packet kernels that is not inlined, which ends their recursion.
#[inline(never)]
fn nested_transform_packet<F: SimdFloat>(
    t: &Transformed,
    rays: &RayPacket<F>,
    prim: u32,
    hits: &mut HitPacket<F>,
) {
    t.intersect_packet(rays, prim, hits);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The frame is made at the first `get`, once, and is the one
    /// [`BlockRay::new`] makes.
    #[test]
    fn a_lazy_block_ray_makes_the_block_rays_frame_once() {
        let ray = Ray::new(
            Vec3::new(0.5, -2.0, 1.0),
            Vec3::new(0.3, 0.9, -0.2).normalize(),
            0.0,
            9.0,
        );
        let mut lazy = LazyBlockRay::hold(&ray);
        assert!(lazy.block.is_none(), "made before a leaf asked");
        let first = format!("{:?}", lazy.get().sheared);
        assert_eq!(first, format!("{:?}", BlockRay::new(&ray).sheared));
        let made = lazy.block.map(|b| b.ray as *const Ray);
        assert_eq!(format!("{:?}", lazy.get().sheared), first);
        assert_eq!(made, Some(&ray as *const Ray), "made for another ray");
        assert!(std::ptr::eq(lazy.ray(), &ray));
    }
}
