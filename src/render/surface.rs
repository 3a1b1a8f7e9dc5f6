//! What the shaders need to know about a hit: the point, the normals turned to
//! face the incoming ray, the side that was hit, and the material.

use glam::Vec3;

use crate::ray::{Hit, Ray};
use crate::scene::{Material, Scene};

/// The surface at a ray's nearest hit. 48 bytes.
#[derive(Clone, Copy, Debug)]
pub struct Surface<'a> {
    /// Hit point `origin + t·dir`.
    pub point: Vec3,
    /// Shading normal (interpolated vertex normal where the scene has one, else
    /// the geometric normal), unit length, on the side the ray came from.
    pub normal: Vec3,
    /// True when the ray hit the front side (against the geometric normal):
    /// it enters a transmitting object rather than leaving it.
    pub front: bool,
    /// The primitive's material.
    pub material: &'a Material,
}

impl<'a> Surface<'a> {
    /// The surface at `hit` (which must be a hit) of `ray` in `scene`.
    ///
    /// The geometric normal comes from [`Primitive::geometric_normal`](crate::geometry::Primitive::geometric_normal)
    /// and is flipped to face the ray, so back faces shade like front faces
    /// (NFF's one-sided surfaces are not culled, and transmitting ones need both
    /// sides). A smooth-shading normal `(1−u−v)·n0 + u·n1 + v·n2` is flipped to the
    /// same side as the facing geometric normal, so interpolation never turns a
    /// visible surface away from the viewer.
    #[inline]
    pub fn at(scene: &'a Scene, ray: &Ray, hit: &Hit) -> Self {
        let prim = hit.prim;
        let ng = scene.primitives[prim as usize].geometric_normal(ray, hit);
        let front = ng.dot(ray.dir) < 0.0;
        let facing = if front { ng } else { -ng };
        let normal = match scene.vertex_normals.get(&prim) {
            Some([n0, n1, n2]) => {
                let n = ((1.0 - hit.u - hit.v) * *n0 + hit.u * *n1 + hit.v * *n2).normalize_or_zero();
                if n == Vec3::ZERO {
                    facing
                } else if n.dot(facing) < 0.0 {
                    -n
                } else {
                    n
                }
            }
            None => facing,
        };
        Self {
            point: ray.at(hit.t),
            normal,
            front,
            material: scene.material(prim),
        }
    }
}
