//! What the shaders need to know about a hit: the point, the normals turned to
//! face the incoming ray, the side that was hit, and the material.

use glam::Vec3;

use crate::ray::{Hit, Ray};
use crate::scene::{Material, Scene};

/// The surface at a ray's nearest hit. 40 bytes.
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
    /// The geometric normal comes from [`Scene::normals_at`] (the
    /// primitive's, through its instance's transform if it has one) and is flipped to face the ray, so back faces shade like front faces
    /// (NFF's one-sided surfaces are not culled, and transmitting ones need both
    /// sides). A smooth-shading normal `(1−u−v)·n0 + u·n1 + v·n2` is flipped to the
    /// same side as the facing geometric normal, so interpolation never turns a
    /// visible surface away from the viewer.
    #[inline]
    pub fn at(scene: &'a Scene, ray: &Ray, hit: &Hit) -> Self {
        let prim = hit.prim;
        let (ng, vertex_normals) = scene.normals_at(ray, hit);
        let front = ng.dot(ray.dir) < 0.0;
        let facing = if front { ng } else { -ng };
        let normal = match vertex_normals {
            Some([n0, n1, n2]) => {
                let n = ((1.0 - hit.u - hit.v) * n0 + hit.u * n1 + hit.v * n2).normalize_or_zero();
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Intersect, Primitive, Triangle};

    /// A triangle in z = 0 with normal +z, material 0.
    fn scene() -> Scene {
        let mut s = Scene {
            materials: vec![Material::default()],
            ..Scene::default()
        };
        let t = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y);
        s.push(Primitive::Triangle(t), 0);
        s
    }

    fn hit(scene: &Scene, ray: &Ray) -> Hit {
        let mut h = Hit::none(ray);
        assert!(scene.primitives[0].intersect(ray, 0, &mut h));
        h
    }

    #[test]
    fn normals_face_the_ray_and_front_tells_the_side() {
        let s = scene();
        let from_front = Ray::unbounded(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z);
        let f = Surface::at(&s, &from_front, &hit(&s, &from_front));
        assert!(f.front);
        assert_eq!(f.normal, Vec3::Z);
        assert!((f.point - Vec3::new(0.2, 0.2, 0.0)).length() < 1e-6);
        let from_back = Ray::unbounded(Vec3::new(0.2, 0.2, -1.0), Vec3::Z);
        let b = Surface::at(&s, &from_back, &hit(&s, &from_back));
        assert!(!b.front);
        assert_eq!(b.normal, -Vec3::Z);
    }

    #[test]
    fn vertex_normals_are_interpolated_and_turned_to_the_visible_side() {
        let mut s = scene();
        let n0 = Vec3::new(-1.0, 0.0, 1.0).normalize();
        let n1 = Vec3::new(1.0, 0.0, 1.0).normalize();
        s.vertex_normals.insert(0, [n0, n1, Vec3::Z]);
        // At (u, v) = (0.5, 0): halfway between n0 and n1, i.e. +z.
        let ray = Ray::unbounded(Vec3::new(0.5, 0.0, 1.0), -Vec3::Z);
        let h = hit(&s, &ray);
        assert!((h.u - 0.5).abs() < 1e-6 && h.v.abs() < 1e-6);
        assert!((Surface::at(&s, &ray, &h).normal - Vec3::Z).length() < 1e-6);
        // Near vertex b the normal leans towards n1.
        let ray = Ray::unbounded(Vec3::new(0.9, 0.05, 1.0), -Vec3::Z);
        let n = Surface::at(&s, &ray, &hit(&s, &ray)).normal;
        assert!(n.x > 0.5 && (n.length() - 1.0).abs() < 1e-6, "{n}");
        // Seen from behind, the interpolated normal is turned to the viewer too.
        let ray = Ray::unbounded(Vec3::new(0.9, 0.05, -1.0), Vec3::Z);
        let back = Surface::at(&s, &ray, &hit(&s, &ray)).normal;
        assert!((back + n).length() < 1e-6, "{back} {n}");
    }
}
