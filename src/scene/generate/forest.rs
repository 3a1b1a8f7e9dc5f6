//! An instanced scene: a forest of `n` trees and rocks on a ground of two
//! triangles, every tree one of two meshes placed by a rotation about the
//! vertical, a scale and a translation. Memory grows with the instance count
//! and the meshes (about 20,000 triangles each), not with the instanced
//! triangles: `gen:forest:50000` holds about 10⁹.

use std::f32::consts::TAU;

use glam::{Mat4, Quat, Vec3};

use crate::geometry::{Primitive, Triangle};
use crate::rng::Rng;
use crate::scene::generate::lots::{Lots, diffuse};
use crate::scene::generate::random::bumpy_sphere;
use crate::scene::instance::placed_primitive;
use crate::scene::{CameraSpec, Light, Mesh, Scene};

/// Triangles of a tree's canopy (a sphere).
const CANOPY_TRIANGLES: usize = 20_000;

/// Sides of a trunk (a prism of triangles).
const TRUNK_SIDES: usize = 12;

/// Triangles of a rock (a squashed sphere).
const ROCK_TRIANGLES: usize = 4_000;

/// Most instances `raypack gen forest` makes: with every one a tree (some
/// 20,000 triangles) the ids stay within 32 bits.
pub const MAX_INSTANCES: u32 = 200_000;

/// Distance between neighbouring trees.
const SPACING: f32 = 4.0;

/// The forest of `n` instances (about one in eight a rock), from `seed`, seen
/// from above one corner.
pub fn forest(n: usize, seed: u64) -> Scene {
    let mut rng = Rng::new(seed);
    let mut scene = Scene {
        source: format!("generated:forest:{n}:{seed}"),
        background: Vec3::new(0.55, 0.7, 0.9),
        materials: vec![
            diffuse(Vec3::new(0.45, 0.4, 0.3)),
            diffuse(Vec3::new(0.2, 0.55, 0.2)),
            diffuse(Vec3::new(0.4, 0.28, 0.15)),
            diffuse(Vec3::new(0.55, 0.55, 0.55)),
        ],
        ..Scene::default()
    };
    let lots = Lots::new(n, SPACING);
    let extent = lots.extent;
    lots.push_ground(&mut scene, 0);
    let tree = scene.add_mesh(tree_mesh());
    let rock = scene.add_mesh(mesh("rock", sphere(0.8, Vec3::ZERO, ROCK_TRIANGLES, seed), 3));
    for k in 0..n {
        let jitter = Vec3::new(rng.range(-1.0, 1.0), 0.0, rng.range(-1.0, 1.0));
        let at = lots.centre(k) + jitter;
        let turn = Quat::from_rotation_y(rng.range(0.0, TAU));
        let size = rng.range(0.7, 1.3);
        let (mesh, scale) = if rng.below(8) == 0 {
            (rock, Vec3::new(size, 0.5 * size, size))
        } else {
            (tree, Vec3::splat(size))
        };
        scene
            .place(mesh, Mat4::from_scale_rotation_translation(scale, turn, at))
            .expect("a forest's transforms are invertible, its ids few");
    }
    scene.lights.push(Light {
        position: Vec3::new(-0.5 * extent, 3.0 * extent.max(20.0), -0.3 * extent),
        color: Vec3::ONE,
    });
    let center = Vec3::new(0.5 * extent, 0.0, 0.5 * extent);
    scene.camera = Some(CameraSpec {
        eye: center + Vec3::new(-0.6 * extent - 10.0, 0.35 * extent + 8.0, -0.6 * extent - 10.0),
        center,
        up: Vec3::Y,
        fovx: 50.0,
        fovy: 50.0,
        width: 512,
        height: 512,
    });
    scene
}

/// A bumpy sphere of about `n` triangles, of `radius` around `center`.
fn sphere(radius: f32, center: Vec3, n: usize, seed: u64) -> Vec<Primitive> {
    let m = Mat4::from_scale_rotation_translation(Vec3::splat(radius), Quat::IDENTITY, center);
    bumpy_sphere(n, seed)
        .iter()
        .map(|p| placed_primitive(p, m).expect("a scale and a translation"))
        .collect()
}

/// A mesh of `prims`, all of material `material`.
fn mesh(name: &str, prims: Vec<Primitive>, material: u32) -> Mesh {
    Mesh {
        name: name.into(),
        material_of: vec![material; prims.len()],
        primitives: prims,
        ..Mesh::default()
    }
}

/// A tree: a trunk (prism, material 2) under a canopy (sphere, material 1), 3.5 units tall.
fn tree_mesh() -> Mesh {
    let canopy = sphere(1.2, Vec3::new(0.0, 2.5, 0.0), CANOPY_TRIANGLES, 2);
    let mut tree = mesh("tree", canopy, 1);
    let at = |k: usize, y: f32| {
        let a = TAU * k as f32 / TRUNK_SIDES as f32;
        Vec3::new(0.2 * a.cos(), y, 0.2 * a.sin())
    };
    for k in 0..TRUNK_SIDES {
        let (a, b, c, d) = (at(k, 0.0), at(k + 1, 0.0), at(k, 1.5), at(k + 1, 1.5));
        for t in [Triangle::new(a, b, c), Triangle::new(b, d, c)] {
            tree.primitives.push(Primitive::Triangle(t));
            tree.material_of.push(2);
        }
    }
    tree
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_forest_holds_its_meshes_once() {
        let f = forest(100, 1);
        assert_eq!(f.primitives.len(), 2, "the ground");
        let summary = f.instancing_summary().unwrap();
        assert_eq!((summary.instances, summary.meshes), (100, 2));
        let meshes = (CANOPY_TRIANGLES + ROCK_TRIANGLES) as u64;
        assert!(summary.unique_primitives < meshes * 11 / 10, "{summary:?}");
        assert!(
            summary.instanced_primitives > 70 * CANOPY_TRIANGLES as u64,
            "{summary:?}"
        );
        assert!(f.camera.unwrap().camera().is_ok());
        assert_eq!(forest(100, 1).id_count(), f.id_count(), "seeded");
    }
}
