//! Scenes built in code for the render tests and benches (the file loaders are
//! written elsewhere): every primitive kind, reflective and transmitting
//! materials, several lights, and a camera.

use glam::{Mat4, Quat, Vec3};
use raypack::geometry::{Plane, Polygon, Primitive, Sphere, Transformed, Triangle};
use raypack::rng::Rng;
use raypack::scene::{CameraSpec, Light, Material, Scene};

/// A material.
pub fn material(color: Vec3, kd: f32, ks: f32, shine: f32, t: f32, ior: f32) -> Material {
    Material {
        color,
        kd,
        ks,
        shine,
        transmittance: t,
        ior,
    }
}

/// An empty scene with these materials.
pub fn with_materials(materials: Vec<Material>) -> Scene {
    Scene {
        materials,
        ..Scene::default()
    }
}

/// A camera looking from `eye` at `center`, square image of `size` pixels, 45°.
pub fn camera(eye: Vec3, center: Vec3, size: u32) -> CameraSpec {
    CameraSpec {
        eye,
        center,
        up: Vec3::Y,
        fovx: 45.0,
        fovy: 45.0,
        width: size,
        height: size,
    }
}

/// `n` random spheres of random materials (diffuse, mirror, glass) in a box
/// above a floor plane, with a few triangles (one smooth-shaded), a concave
/// polygon, a transformed ellipsoid, two lights, and a camera: every primitive
/// kind and every secondary ray kind.
pub fn mixed_scene(n: usize, seed: u64) -> Scene {
    let mut rng = Rng::new(seed);
    let mut scene = Scene {
        background: Vec3::new(0.1, 0.15, 0.3),
        source: format!("mixed-{n}-{seed}"),
        ..Scene::default()
    };
    scene.materials = vec![
        material(Vec3::new(0.8, 0.8, 0.7), 0.9, 0.0, 0.0, 0.0, 1.0),
        material(Vec3::new(0.9, 0.3, 0.2), 0.7, 0.3, 20.0, 0.0, 1.0),
        material(Vec3::new(0.9, 0.9, 1.0), 0.1, 0.2, 60.0, 0.8, 1.5),
        material(Vec3::new(0.2, 0.6, 0.9), 0.5, 0.5, 40.0, 0.0, 1.0),
    ];
    scene.lights = vec![
        Light {
            position: Vec3::new(6.0, 9.0, 7.0),
            color: Vec3::ONE,
        },
        Light {
            position: Vec3::new(-8.0, 5.0, 2.0),
            color: Vec3::new(0.8, 0.8, 1.0),
        },
    ];
    scene.push(
        Primitive::Plane(Plane::implicit(0.0, 1.0, 0.0, 1.0).expect("floor")),
        3,
    );
    for _ in 0..n {
        let c = rng.point_in(Vec3::new(-4.0, -0.5, -4.0), Vec3::new(4.0, 3.0, 2.0));
        let r = rng.range(0.15, 0.6);
        let m = rng.below(3);
        scene.push(Primitive::Sphere(Sphere::new(c, r)), m);
    }
    let tri = Triangle::new(
        Vec3::new(-3.0, -1.0, -5.0),
        Vec3::new(3.0, -1.0, -5.0),
        Vec3::new(0.0, 3.5, -5.5),
    );
    let t = scene.push(Primitive::Triangle(tri), 1);
    scene.vertex_normals.insert(
        t,
        [
            Vec3::new(-0.3, 0.0, 1.0).normalize(),
            Vec3::new(0.3, 0.0, 1.0).normalize(),
            Vec3::new(0.0, 0.4, 1.0).normalize(),
        ],
    );
    scene.push(
        Primitive::Triangle(Triangle::new(
            Vec3::new(2.0, -1.0, 1.0),
            Vec3::new(4.0, 0.5, 0.0),
            Vec3::new(3.0, 2.0, 1.5),
        )),
        2,
    );
    let star: Vec<Vec3> = (0..10)
        .map(|i| {
            let r = if i % 2 == 0 { 1.2 } else { 0.5 };
            let a = i as f32 * std::f32::consts::TAU / 10.0;
            Vec3::new(-3.0 + r * a.cos(), 1.5 + r * a.sin(), 1.0)
        })
        .collect();
    scene.push(Primitive::Polygon(Polygon::new(&star).expect("star")), 0);
    let ellipsoid = Mat4::from_scale_rotation_translation(
        Vec3::new(0.9, 0.4, 0.5),
        Quat::from_rotation_z(0.6),
        Vec3::new(0.5, 0.0, 1.5),
    );
    scene.push(
        Primitive::Transformed(Box::new(
            Transformed::new(Primitive::Sphere(Sphere::new(Vec3::ZERO, 1.0)), ellipsoid).expect("invertible"),
        )),
        2,
    );
    scene.camera = Some(camera(Vec3::new(0.0, 2.0, 10.0), Vec3::new(0.0, 0.5, 0.0), 64));
    scene
}

/// `n` random diffuse spheres in a cube, camera outside looking in: the
/// sphere-heavy scene of the benchmarks.
pub fn sphere_cloud(n: usize, seed: u64, size: u32) -> Scene {
    let mut rng = Rng::new(seed);
    let mut scene = Scene {
        source: format!("spheres-{n}"),
        ..Scene::default()
    };
    scene.materials = vec![Material::default()];
    scene.lights = vec![Light {
        position: Vec3::new(5.0, 8.0, 10.0),
        color: Vec3::ONE,
    }];
    for _ in 0..n {
        let c = rng.point_in(Vec3::splat(-3.0), Vec3::splat(3.0));
        scene.push(Primitive::Sphere(Sphere::new(c, rng.range(0.1, 0.5))), 0);
    }
    scene.camera = Some(camera(Vec3::new(0.0, 0.0, 12.0), Vec3::ZERO, size));
    scene
}
