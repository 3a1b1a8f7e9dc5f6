//! What a BVH leaf stores per primitive: the kernel's data inline for the
//! shapes scenes are made of in bulk (triangles, spheres), a reference to a
//! full [`Primitive`] for the rest, and the input index hits report.
//!
//! A [`Primitive`] is 88 bytes (the largest variant, a triangle with its
//! vertices); a leaf of three triangles stored that way spans five cache lines.
//! The triangle kernels read only the 40-byte [`ProjectedTriangle`], so a
//! [`LeafPrim`] is 48 bytes and the same leaf fits in three lines: the memory a
//! ray pulls in at the bottom of a large tree, where nearly every leaf is a
//! cache miss, roughly halves (the precomputed triangle records of Embree's
//! `Triangle4` leaves, Wald et al. 2014, serve the same purpose).

use crate::geometry::triangle::ProjectedTriangle;
use crate::geometry::{Intersect, Primitive, Sphere};
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, Ray};
use crate::simd::SimdFloat;

/// A leaf's primitive. 48 bytes.
#[derive(Clone, Debug, PartialEq)]
pub struct LeafPrim {
    /// The shape's kernel data.
    shape: LeafShape,
    /// Index in the input slice, reported by hits.
    id: u32,
}

/// A leaf primitive's kernel data. 44 bytes.
#[derive(Clone, Debug, PartialEq)]
enum LeafShape {
    /// A triangle's projected-barycentric constants.
    Triangle(ProjectedTriangle),
    /// A sphere.
    Sphere(Sphere),
    /// Any other shape: its index in the BVH's list of other primitives.
    Other(u32),
}

impl LeafPrim {
    /// The leaf record of `prim`, input index `id`; shapes kept whole are
    /// appended to `others`.
    pub fn new(prim: &Primitive, id: u32, others: &mut Vec<Primitive>) -> Self {
        let shape = match prim {
            Primitive::Triangle(t) => LeafShape::Triangle(*t.projected()),
            Primitive::Sphere(s) => LeafShape::Sphere(*s),
            other => {
                others.push(other.clone());
                LeafShape::Other(others.len() as u32 - 1)
            }
        };
        Self { shape, id }
    }

    /// Index in the input slice.
    pub fn id(&self) -> u32 {
        self.id
    }

    /// The scalar kernel of the shape (`others` is the BVH's list of other primitives).
    #[inline(always)]
    pub fn intersect(&self, others: &[Primitive], ray: &Ray, hit: &mut Hit) -> bool {
        match &self.shape {
            LeafShape::Triangle(t) => t.intersect(ray, self.id, hit),
            LeafShape::Sphere(s) => s.intersect(ray, self.id, hit),
            LeafShape::Other(i) => others[*i as usize].intersect(ray, self.id, hit),
        }
    }

    /// The packet kernel of the shape.
    #[inline(always)]
    pub fn intersect_packet<F: SimdFloat>(
        &self,
        others: &[Primitive],
        rays: &RayPacket<F>,
        hits: &mut HitPacket<F>,
    ) {
        match &self.shape {
            LeafShape::Triangle(t) => t.intersect_packet(rays, self.id, hits),
            LeafShape::Sphere(s) => s.intersect_packet(rays, self.id, hits),
            LeafShape::Other(i) => others[*i as usize].intersect_packet(rays, self.id, hits),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    use crate::geometry::{Cone, Triangle};

    #[test]
    fn record_is_48_bytes() {
        assert_eq!(size_of::<LeafPrim>(), 48);
    }

    #[test]
    fn each_shape_reports_what_the_primitive_reports() {
        let prims = [
            Primitive::Triangle(Triangle::new(
                Vec3::new(-1.0, -1.0, 0.0),
                Vec3::new(1.0, -1.0, 0.0),
                Vec3::Y,
            )),
            Primitive::Sphere(Sphere::new(Vec3::new(0.0, 0.0, 2.0), 0.5)),
            Primitive::Cone(
                Cone::new(Vec3::new(0.0, -1.0, 4.0), 1.0, Vec3::new(0.0, 1.0, 4.0), 0.5).unwrap(),
            ),
        ];
        let mut others = Vec::new();
        let leaves: Vec<LeafPrim> = prims
            .iter()
            .enumerate()
            .map(|(i, p)| LeafPrim::new(p, 10 + i as u32, &mut others))
            .collect();
        assert_eq!(others.len(), 1);
        for (i, (p, leaf)) in prims.iter().zip(&leaves).enumerate() {
            assert_eq!(leaf.id(), 10 + i as u32);
            let ray = Ray::unbounded(Vec3::new(0.1, 0.2, -5.0), Vec3::Z);
            let (mut want, mut got) = (Hit::none(&ray), Hit::none(&ray));
            assert_eq!(
                leaf.intersect(&others, &ray, &mut got),
                p.intersect(&ray, leaf.id(), &mut want)
            );
            assert_eq!(got, want);
            assert!(got.is_hit(), "shape {i}");
            let rays = RayPacket::<wide::f32x8>::from_rays(&[ray; 8]);
            let (mut want, mut got) = (HitPacket::none(&rays), HitPacket::none(&rays));
            leaf.intersect_packet(&others, &rays, &mut got);
            p.intersect_packet(&rays, leaf.id(), &mut want);
            assert_eq!(got.hit(3), want.hit(3));
        }
    }
}
