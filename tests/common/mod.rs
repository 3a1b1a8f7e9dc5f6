//! Helpers shared by the scene loader tests.

use glam::Vec3;
use raypack::geometry::Primitive;
use raypack::scene::Scene;

/// Assert two scenes hold the same primitives, in the same order, with the
/// same materials.
#[track_caller]
pub fn assert_same_geometry(a: &Scene, b: &Scene) {
    assert_eq!(a.primitives.len(), b.primitives.len(), "primitive counts differ");
    for (i, (p, q)) in a.primitives.iter().zip(&b.primitives).enumerate() {
        assert_eq!(p, q, "primitive {i} differs");
    }
    assert_eq!(a.material_of, b.material_of);
    assert_eq!(a.materials, b.materials);
}

/// The vertices of a triangle primitive.
#[track_caller]
pub fn triangle_vertices(p: &Primitive) -> [Vec3; 3] {
    match p {
        Primitive::Triangle(t) => t.vertices(),
        other => panic!("expected a triangle, got {other:?}"),
    }
}
