//! How each raypack primitive goes into Embree.
//!
//! | raypack | Embree |
//! | --- | --- |
//! | [`Triangle`](crate::geometry::Triangle) | triangle mesh (vertex order kept, so `u, v` mean the same) |
//! | [`Polygon`](crate::geometry::Polygon), simple | the triangles raypack tests: its watertight pieces (the default), or under the crossing test the polygon ear-clipped with its vertices projected onto its plane (fixed by its first three vertices, as that kernel's is) |
//! | [`Polygon`](crate::geometry::Polygon), self-crossing | user geometry: ear clipping would cover another region than the even-odd rule |
//! | [`Sphere`](crate::geometry::Sphere) | `SPHERE_POINT` |
//! | inside-only sphere (NFF negative radius) | user geometry: Embree's spheres are visible from outside |
//! | [`Transformed`](crate::geometry::Transformed) | an instance of a one-object scene (nested transforms are multiplied out) |
//! | planes, transformed planes, any shape Embree has no type for (cones) | user geometry calling raypack's own scalar kernel |
//! | degenerate triangle, zero-area polygon | nothing: no ray can hit them |
//!
//! Several Embree primitives may stand for one raypack primitive (a polygon's
//! triangles); each keeps the index of the primitive it came from, so hits are
//! reported in raypack's numbering (file order).

use glam::{Mat4, Vec3};

use crate::geometry::Primitive;

/// A shape Embree has a native type for.
#[derive(Clone, Debug, PartialEq)]
pub enum NativeShape {
    /// Triangles (one for a triangle, several for a polygon).
    Triangles(Vec<[Vec3; 3]>),
    /// A sphere: centre and radius.
    Sphere(Vec3, f32),
}

/// Where a primitive goes.
#[derive(Clone, Debug, PartialEq)]
pub enum Placement {
    /// Into the top-level scene as native geometry.
    Native(NativeShape),
    /// Into a scene of its own, instanced with the object-to-world matrix.
    Instance(Mat4, NativeShape),
    /// Into the user geometry, traced by raypack's kernel.
    User,
    /// Nowhere: it cannot be hit.
    Empty,
}

/// What [`place`] decided for a whole scene, by count.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct TranslationStats {
    /// Embree triangles (from triangles and polygons, instanced or not).
    pub triangles: usize,
    /// Embree spheres.
    pub spheres: usize,
    /// Instances (one per transformed primitive with a native shape).
    pub instances: usize,
    /// Primitives traced as user geometry by raypack's kernels.
    pub user: usize,
    /// Polygons that were ear-clipped.
    pub polygons_triangulated: usize,
    /// Primitives left out because no ray can hit them.
    pub empty: usize,
}

impl TranslationStats {
    /// Count one placement.
    pub fn add(&mut self, prim: &Primitive, placement: &Placement) {
        let shape = match placement {
            Placement::Native(shape) => shape,
            Placement::Instance(_, shape) => {
                self.instances += 1;
                shape
            }
            Placement::User => {
                self.user += 1;
                return;
            }
            Placement::Empty => {
                self.empty += 1;
                return;
            }
        };
        match shape {
            NativeShape::Triangles(t) => self.triangles += t.len(),
            NativeShape::Sphere(..) => self.spheres += 1,
        }
        let mut inner = prim;
        while let Primitive::Transformed(t) = inner {
            inner = t.object();
        }
        if matches!(inner, Primitive::Polygon(_)) {
            self.polygons_triangulated += 1;
        }
    }
}

/// A primitive without its transforms.
enum Local {
    Native(NativeShape),
    User,
    Empty,
}

/// The native shape of an untransformed primitive, if Embree has one.
fn local(prim: &Primitive) -> Local {
    match prim {
        // Embree's sphere shows its front face; only raypack's kernel takes the far root.
        Primitive::Sphere(s) if s.inside_only => Local::User,
        Primitive::Sphere(s) => Local::Native(NativeShape::Sphere(s.center, s.radius)),
        Primitive::Triangle(t) if t.is_degenerate() => Local::Empty,
        Primitive::Triangle(t) => Local::Native(NativeShape::Triangles(vec![t.vertices()])),
        // The triangles raypack tests: its watertight pieces, or for the
        // crossing test the polygon cut on its plane; either way both engines
        // hit the same surface.
        Primitive::Polygon(p) => {
            let triangles = match p.watertight_pieces() {
                Some(pieces) => Ok(pieces.to_vec()),
                None => p.triangles(),
            };
            match triangles {
                Ok(tris) if tris.is_empty() => Local::Empty,
                Ok(tris) => Local::Native(NativeShape::Triangles(tris)),
                Err(_) => Local::User,
            }
        }
        // Planes, and shapes Embree has no type for (cones, …).
        _ => Local::User,
    }
}

/// Where `prim` goes in Embree.
pub fn place(prim: &Primitive) -> Placement {
    let Primitive::Transformed(t) = prim else {
        return match local(prim) {
            Local::Native(shape) => Placement::Native(shape),
            Local::User => Placement::User,
            Local::Empty => Placement::Empty,
        };
    };
    // Multiply nested transforms out: M₁·(M₂·object).
    let mut m = t.matrix();
    let mut object = t.object();
    while let Primitive::Transformed(inner) = object {
        m *= inner.matrix();
        object = inner.object();
    }
    match local(object) {
        Local::Native(shape) => Placement::Instance(m, shape),
        // The whole transformed primitive goes to raypack's kernel, in world space.
        Local::User => Placement::User,
        Local::Empty => Placement::Empty,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Plane, Polygon, Sphere, Transformed, Triangle, TriangleTest};
    use glam::Quat;

    #[test]
    fn every_kind_goes_where_the_table_says() {
        let tri = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y);
        assert_eq!(
            place(&Primitive::Triangle(tri)),
            Placement::Native(NativeShape::Triangles(vec![[Vec3::ZERO, Vec3::X, Vec3::Y]]))
        );
        let flat = Triangle::new(Vec3::ZERO, Vec3::X, 2.0 * Vec3::X);
        assert_eq!(place(&Primitive::Triangle(flat)), Placement::Empty);
        let sphere = Primitive::Sphere(Sphere::new(Vec3::ONE, 2.0));
        assert_eq!(
            place(&sphere),
            Placement::Native(NativeShape::Sphere(Vec3::ONE, 2.0))
        );
        let dome = Primitive::Sphere(Sphere::inside_only(Vec3::ONE, 2.0));
        assert_eq!(place(&dome), Placement::User);
        let plane = Primitive::Plane(Plane::implicit(0.0, 1.0, 0.0, 1.0).unwrap());
        assert_eq!(place(&plane), Placement::User);
        let bowtie = Polygon::new(&[Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0), Vec3::X, Vec3::Y]).unwrap();
        assert_eq!(place(&Primitive::Polygon(bowtie)), Placement::User);
        let square = Polygon::new(&[Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y]).unwrap();
        match place(&Primitive::Polygon(square)) {
            Placement::Native(NativeShape::Triangles(t)) => assert_eq!(t.len(), 2),
            other => panic!("{other:?}"),
        }
        let transformed_plane = Primitive::Transformed(Box::new(
            Transformed::new(plane, Mat4::from_translation(Vec3::X)).unwrap(),
        ));
        assert_eq!(place(&transformed_plane), Placement::User);
    }

    #[test]
    fn nested_transforms_are_multiplied_out() {
        let (a, b) = (
            Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0)),
            Mat4::from_scale_rotation_translation(
                Vec3::new(2.0, 1.0, 0.5),
                Quat::from_rotation_y(0.3),
                Vec3::Z,
            ),
        );
        let sphere = Primitive::Sphere(Sphere::new(Vec3::ZERO, 1.0));
        let inner = Primitive::Transformed(Box::new(Transformed::new(sphere, b).unwrap()));
        let outer = Primitive::Transformed(Box::new(Transformed::new(inner, a).unwrap()));
        match place(&outer) {
            Placement::Instance(m, NativeShape::Sphere(c, r)) => {
                assert!(m.abs_diff_eq(a * b, 1e-6));
                assert_eq!((c, r), (Vec3::ZERO, 1.0));
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn polygon_triangles_are_the_surface_raypack_tests() {
        // The fourth vertex is a little off the plane of the first three.
        let mut p = Polygon::new(&[
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(1.0, 1.0, 0.01),
            Vec3::new(0.0, 1.0, -0.02),
        ])
        .unwrap();
        let triangles = |p: &Polygon| match place(&Primitive::Polygon(p.clone())) {
            Placement::Native(NativeShape::Triangles(tris)) => tris,
            other => panic!("a simple polygon is triangulated: {other:?}"),
        };
        // The watertight pieces, as they are.
        assert_eq!(triangles(&p), p.watertight_pieces().unwrap());
        // For the crossing test, which hits the plane: on the plane.
        p.set_test(TriangleTest::Barycentric);
        for v in triangles(&p).iter().flatten() {
            assert!((p.normal().dot(*v) - p.plane_offset()).abs() < 1e-6);
        }
        let mut stats = TranslationStats::default();
        stats.add(&Primitive::Polygon(p.clone()), &place(&Primitive::Polygon(p)));
        assert_eq!((stats.triangles, stats.polygons_triangulated), (2, 1));
    }
}
