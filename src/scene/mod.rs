//! Scenes: primitives in file order, their materials, lights and camera, and the
//! loaders that read them (one file per format under `scene/`).
//!
//! Readers: [`nff`] (the SPD's Neutral File Format) and [`native`] (TOML, for
//! what NFF cannot say); [`load`] picks one by file extension.
//!
//! One primitive numbering serves every format: a primitive's index is its
//! position in file order (NFF: each `s`/`p`/`pp`/`c` entity; OBJ/PLY: each
//! face), so hit records can be compared ray by ray with any other engine.

mod error;
pub mod generate;
pub mod gltf;
pub mod gltf_writer;
mod input;
pub mod instance;
pub mod loader;
mod mesh;
mod model;
pub mod native;
pub mod nff;
pub mod obj;
pub mod ply;

pub use error::{SceneError, geometry_message};
pub use instance::{Instance, InstanceError, InstancingSummary, Mesh};
pub use loader::{load, parse};
pub use model::{CameraSpec, DEFAULT_VIEW, Light, Located, Material, Scene};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::{Accel, BruteForce};
    use crate::geometry::{Primitive, Sphere};
    use glam::Vec3;

    /// A model far smaller than the unit distance to the image plane (the
    /// dragon is 0.27 units across) is in front of that plane and fills the
    /// default camera's view.
    #[test]
    fn default_camera_sees_models_of_any_size() {
        for radius in [0.05f32, 1.0, 300.0] {
            let mut scene = Scene {
                materials: vec![Material::default()],
                ..Scene::default()
            };
            scene.push(
                Primitive::Sphere(Sphere::new(Vec3::new(2.0, 0.5, -1.0), radius)),
                0,
            );
            let camera = scene.default_camera().camera_at(33, 33).unwrap();
            let brute = BruteForce::new(&scene.primitives);
            let hits = (0..33 * 33)
                .filter(|k| brute.intersect(&camera.pixel_ray(k % 33, k / 33)).is_hit())
                .count();
            // The view fits the box's bounding sphere, √3 times the sphere's
            // radius: the sphere covers about π/4 · (1/√3)² ≈ 26% of the image.
            assert!(hits > 33 * 33 / 5, "radius {radius}: {hits} hits");
            assert!(brute.intersect(&camera.pixel_ray(16, 16)).is_hit());
        }
    }
}
