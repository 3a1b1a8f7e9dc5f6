//! Indexed meshes (OBJ, PLY) into scene primitives, one primitive per face in
//! file order, so a hit's primitive index is the face's position in the file.
//!
//! A face of three corners becomes a [`Triangle`], a larger one a [`Polygon`].
//! The polygon kernel takes its plane from the first three corners (the NFF
//! rule); when those happen to be collinear the corner list is rotated to start
//! at a corner that turns the way the whole face does (its Newell normal, M. E.
//! Newell, via Sutherland, Sproull & Schumacker, "A Characterization of Ten
//! Hidden-Surface Algorithms", 1974), which leaves the polygon itself unchanged.
//! A face of zero area is kept as a degenerate triangle: no ray can hit it either
//! way, and the numbering of every later face stays intact.

use std::path::Path;

use glam::Vec3;

use crate::geometry::{Polygon, Primitive, Triangle};
use crate::scene::model::{Material, Scene};

/// Collects the faces of one mesh into a [`Scene`] with one default material.
#[derive(Debug)]
pub struct MeshBuilder {
    scene: Scene,
    /// Scratch space for rotated polygon corners.
    rotated: Vec<Vec3>,
}

impl MeshBuilder {
    /// An empty mesh read from `path`, with room for `faces` faces.
    pub fn new(path: &Path, faces: usize) -> Self {
        let mut scene = Scene {
            materials: vec![Material::default()],
            source: path.display().to_string(),
            ..Scene::default()
        };
        scene.primitives.reserve(faces);
        scene.material_of.reserve(faces);
        Self {
            scene,
            rotated: Vec::new(),
        }
    }

    /// Append a face (at least three finite corners) and, for a triangle, its
    /// per-corner shading normals. Returns the face's primitive index.
    pub fn push_face(&mut self, corners: &[Vec3], normals: Option<[Vec3; 3]>) -> u32 {
        debug_assert!(
            corners.len() >= 3,
            "faces are checked for 3+ corners by the readers"
        );
        let prim = match corners {
            &[a, b, c] => Primitive::Triangle(Triangle::new(a, b, c)),
            _ => self.polygon(corners),
        };
        let is_triangle = matches!(prim, Primitive::Triangle(_));
        let index = self.scene.push(prim, 0);
        if let (Some(n), true, 3) = (normals, is_triangle, corners.len()) {
            self.scene.vertex_normals.insert(index, n);
        }
        index
    }

    /// Number of faces so far.
    pub fn face_count(&self) -> usize {
        self.scene.primitives.len()
    }

    /// The finished scene.
    pub fn finish(self) -> Scene {
        self.scene
    }

    /// A polygon face, its corners rotated if the first three are collinear.
    fn polygon(&mut self, corners: &[Vec3]) -> Primitive {
        if let Ok(p) = Polygon::new(corners) {
            return Primitive::Polygon(p);
        }
        let normal = newell_normal(corners);
        let n = corners.len();
        for start in 1..n {
            let (a, b, c) = (corners[start], corners[(start + 1) % n], corners[(start + 2) % n]);
            if (b - a).cross(c - a).dot(normal) > 0.0 {
                self.rotated.clear();
                self.rotated.extend_from_slice(&corners[start..]);
                self.rotated.extend_from_slice(&corners[..start]);
                if let Ok(p) = Polygon::new(&self.rotated) {
                    return Primitive::Polygon(p);
                }
            }
        }
        // Zero area: nothing can hit it; keep its place in the numbering.
        Primitive::Triangle(Triangle::new(corners[0], corners[1], corners[2]))
    }
}

/// Newell's normal of a polygon: twice its vector area, robust for non-planar
/// and concave corner lists; zero for a face of zero area.
fn newell_normal(corners: &[Vec3]) -> Vec3 {
    let n = corners.len();
    (0..n).fold(Vec3::ZERO, |acc, i| acc + corners[i].cross(corners[(i + 1) % n]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::PrimitiveKind;

    #[test]
    fn triangles_and_polygons_keep_file_order_and_normals() {
        let mut mesh = MeshBuilder::new(Path::new("m"), 2);
        let quad = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        assert_eq!(mesh.push_face(&quad, None), 0);
        assert_eq!(mesh.push_face(&tri, Some([Vec3::Z; 3])), 1);
        let scene = mesh.finish();
        let kinds: Vec<_> = scene.primitives.iter().map(Primitive::kind).collect();
        assert_eq!(kinds, [PrimitiveKind::Polygon, PrimitiveKind::Triangle]);
        assert_eq!(scene.vertex_normals.get(&1), Some(&[Vec3::Z; 3]));
        assert_eq!(scene.material_of, [0, 0]);
        assert_eq!(scene.source, "m");
    }

    #[test]
    fn collinear_first_corners_are_rotated_not_rejected() {
        // A square with an extra corner in the middle of its first edge.
        let face = [
            Vec3::ZERO,
            Vec3::new(0.5, 0.0, 0.0),
            Vec3::X,
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::Y,
        ];
        let mut mesh = MeshBuilder::new(Path::new("m"), 1);
        mesh.push_face(&face, None);
        let scene = mesh.finish();
        let Primitive::Polygon(p) = &scene.primitives[0] else {
            panic!("expected a polygon, got {:?}", scene.primitives[0]);
        };
        assert_eq!(p.normal(), Vec3::Z, "orientation follows the corner order");
        assert_eq!(p.bounds().max, Vec3::new(1.0, 1.0, 0.0));
    }

    #[test]
    fn zero_area_faces_keep_their_index_but_cannot_be_hit() {
        let line = [
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(3.0, 0.0, 0.0),
        ];
        let mut mesh = MeshBuilder::new(Path::new("m"), 2);
        mesh.push_face(&line, None);
        mesh.push_face(&[Vec3::ZERO, Vec3::X, Vec3::Y], None);
        let scene = mesh.finish();
        assert_eq!(scene.primitives.len(), 2);
        assert_eq!(
            scene.primitives[0].bounds(),
            None,
            "degenerate faces have no bounds"
        );
        assert!(scene.primitives[1].bounds().is_some());
    }
}
