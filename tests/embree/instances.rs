//! Embree's instances (`RTC_GEOMETRY_TYPE_INSTANCE`, one Embree scene per
//! mesh) against raypack's two-level structure on the same instanced scene:
//! the same primitive ids on random rays, and the same blocked rays.

use std::sync::Arc;

use glam::{Mat4, Quat, Vec3};
use raypack::accel::{Accel, Bvh, TwoLevel};
use raypack::embree::{Device, EmbreeScene};
use raypack::geometry::{Primitive, Sphere};
use raypack::rng::Rng;
use raypack::scene::generate::city::city;
use raypack::scene::generate::forest::forest;
use raypack::scene::generate::random::random_triangles;
use raypack::scene::{Mesh, Scene};

use crate::support::bvh::random_rays;

/// A forest, a city, and a scene of a triangle mesh and a sphere cloud placed under
/// rotations and non-uniform scales (Embree's spheres are native shapes).
fn scenes() -> Vec<Scene> {
    let mut rng = Rng::new(5);
    let mut mixed = Scene::default();
    mixed.push(
        Primitive::Sphere(Sphere::new(Vec3::new(0.0, -30.0, 0.0), 28.0)),
        0,
    );
    let spheres: Vec<Primitive> = (0..200)
        .map(|_| Primitive::Sphere(Sphere::new(rng.point_in(Vec3::splat(-1.0), Vec3::ONE), 0.05)))
        .collect();
    for (name, prims) in [("triangles", random_triangles(400, 6)), ("spheres", spheres)] {
        let mesh = mixed.add_mesh(Mesh {
            name: name.into(),
            material_of: vec![0; prims.len()],
            primitives: prims,
            ..Mesh::default()
        });
        for _ in 0..12 {
            let at = rng.point_in(Vec3::splat(-4.0), Vec3::splat(4.0));
            let turn = Quat::from_axis_angle(rng.unit_vector(), rng.range(0.0, 6.0));
            let scale = Vec3::new(rng.range(0.5, 1.5), rng.range(0.5, 1.5), rng.range(0.5, 1.5));
            mixed
                .place(mesh, Mat4::from_scale_rotation_translation(scale, turn, at))
                .unwrap();
        }
    }
    vec![forest(40, 3), city(36, 4), mixed]
}

#[test]
fn embree_instances_agree_with_raypack_instances() {
    let device = Arc::new(Device::with_default_config().expect("Embree device"));
    for scene in scenes() {
        assert!(scene.instances.meshes().iter().all(EmbreeScene::instances_mesh));
        let embree = EmbreeScene::with_instances(device.clone(), &scene, true).unwrap();
        assert_eq!(embree.instanced_meshes(), scene.instances.meshes().len());
        let raypack = TwoLevel::new(&scene, Bvh::new);
        let rays = random_rays(scene.bounds(), 50_000, 9);
        let (mut differ, mut hits) = (0, 0);
        for ray in &rays {
            let (a, b) = (raypack.intersect(ray), embree.intersect(ray));
            hits += usize::from(a.is_hit());
            differ += usize::from(a.prim != b.prim);
            assert_eq!(embree.occluded(ray), b.is_hit(), "{ray:?}");
        }
        assert!(hits > rays.len() / 10, "{}: {hits} hits", scene.source);
        // Rays through a shared edge may go either way: at most 1 in 10⁴.
        assert!(
            differ <= rays.len() / 10_000,
            "{}: {differ} of {} differ",
            scene.source,
            rays.len()
        );
        eprintln!(
            "{}: {differ} of {} rays differ, {hits} hits",
            scene.source,
            rays.len()
        );
    }
}
