//! A scene with instances renders as the same scene flattened (every
//! instanced primitive a copy under the same id): the same primitive in
//! every pixel but where rounding decides an edge, the same colours within
//! rounding.

use glam::{Mat4, Quat, Vec3};
use raypack::accel::{Bvh, TwoLevel};
use raypack::render::{Block, KernelKind, Mode, Render, RenderSettings, Sampling, render};
use raypack::scene::Scene;
use raypack::scene::generate::city::city;
use raypack::scene::generate::forest::forest;
use raypack::scene::generate::test_scenes::from_spec;

fn pool() -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap()
}

fn settings(mode: Mode, kernel: KernelKind) -> RenderSettings {
    RenderSettings {
        mode,
        kernel,
        block: Block::B4x4,
        tile_size: 16,
        max_depth: 5,
        sampling: Sampling::PixelCentres,
    }
}

/// The render of `scene` through its instances, and of it flattened.
fn both(scene: &Scene, settings: &RenderSettings) -> (Render, Render) {
    let camera = scene.camera.unwrap().camera_at(160, 160).unwrap();
    let flat = scene.flattened().unwrap();
    let instanced = render(
        scene,
        &TwoLevel::new(scene, Bvh::new),
        &camera,
        settings,
        &pool(),
        &|| {},
    );
    let copies = render(
        &flat,
        &Bvh::new(&flat.primitives),
        &camera,
        settings,
        &pool(),
        &|| {},
    );
    (instanced, copies)
}

/// Pixels whose primitive differs, and 8-bit channels that differ by more than one level.
fn differences(a: &Render, b: &Render) -> (usize, usize) {
    let prims = a
        .frame
        .prim
        .iter()
        .zip(&b.frame.prim)
        .filter(|(x, y)| x != y)
        .count();
    let (ra, rb) = (a.frame.to_rgb8(), b.frame.to_rgb8());
    let colours = ra
        .iter()
        .zip(rb.iter())
        .filter(|(x, y)| x.abs_diff(**y) > 1)
        .count();
    (prims, colours)
}

/// A forest (triangle meshes: rays keep their length in mesh space), a city
/// (quarter turns and stretched heights; its windows reflect), and the
/// mixed test scene's primitives as one mesh placed four times (spheres,
/// cones, polygons, transformed shapes: unit directions in mesh space).
fn scenes() -> Vec<Scene> {
    let mut mixed = from_spec("gen:mixed:400:3").unwrap().unwrap();
    let mesh = raypack::scene::Mesh {
        name: "mixed".into(),
        primitives: std::mem::take(&mut mixed.primitives),
        material_of: std::mem::take(&mut mixed.material_of),
        vertex_normals: std::mem::take(&mut mixed.vertex_normals),
    };
    let m = mixed.add_mesh(mesh);
    for k in 0..4 {
        let turn = Quat::from_rotation_y(0.4 * k as f32);
        let at = Vec3::new(2.5 * (k % 2) as f32, 0.0, -2.5 * (k / 2) as f32);
        let scale = Vec3::new(1.0, 0.8 + 0.1 * k as f32, 1.0);
        mixed
            .place(m, Mat4::from_scale_rotation_translation(scale, turn, at))
            .unwrap();
    }
    mixed.camera = Some(raypack::scene::CameraSpec {
        width: 160,
        height: 160,
        ..mixed.default_camera()
    });
    vec![forest(60, 2), city(36, 4), mixed]
}

#[test]
fn instanced_and_flattened_scenes_render_alike() {
    for scene in scenes() {
        for (mode, kernel) in [
            (Mode::Id, KernelKind::Packet8),
            (Mode::Whitted, KernelKind::Packet8),
            (Mode::Whitted, KernelKind::Scalar),
        ] {
            let (instanced, flat) = both(&scene, &settings(mode, kernel));
            let (prims, colours) = differences(&instanced, &flat);
            let pixels = instanced.frame.prim.len();
            eprintln!(
                "{} {mode:?} {kernel:?}: {prims} primitives, {colours} channels differ of {pixels}",
                scene.source
            );
            assert!(instanced.frame.prim.iter().filter(|&&p| p != u32::MAX).count() > pixels / 4);
            assert!(
                prims <= pixels / 5000,
                "{}: {prims} pixels see another primitive",
                scene.source
            );
            assert!(
                colours <= pixels / 2000,
                "{}: {colours} channels differ",
                scene.source
            );
            assert_eq!(instanced.counts.eye_rays, flat.counts.eye_rays);
        }
    }
}

/// A forest written as glTF (`raypack gen forest -o forest.glb`) and read
/// back renders as the forest made in memory, pixel for pixel: the same
/// meshes, instance matrices and materials, the ground an identity instance.
/// (glTF has no background colour; the file's camera looks the same way.)
#[test]
fn a_forest_written_as_gltf_renders_as_itself() {
    use raypack::scene::gltf_writer::{Container, write_gltf};
    let scene = forest(60, 2);
    let bytes = write_gltf(&scene, Container::Glb, Vec::new()).unwrap();
    let mut read = raypack::scene::gltf::parse(std::path::Path::new("forest.glb"), &bytes).unwrap();
    read.background = scene.background;
    let (spec, back) = (scene.camera.unwrap(), read.camera.unwrap());
    let view = |s: &raypack::scene::CameraSpec| (s.center - s.eye).normalize();
    assert!(back.eye.distance(spec.eye) < 1e-3 * spec.eye.length());
    assert!(view(&back).dot(view(&spec)) > 1.0 - 1e-6);
    assert!((back.fovx - spec.fovx).abs() < 1e-3 && (back.fovy - spec.fovy).abs() < 1e-3);
    let camera = spec.camera_at(160, 160).unwrap();
    let settings = settings(Mode::Whitted, KernelKind::Packet8);
    let [original, written] = [&scene, &read].map(|s| {
        render(
            s,
            &TwoLevel::new(s, Bvh::new),
            &camera,
            &settings,
            &pool(),
            &|| {},
        )
    });
    let pixels = original.frame.prim.len();
    assert!(original.frame.prim.iter().filter(|&&p| p != u32::MAX).count() > pixels / 4);
    assert_eq!(differences(&original, &written), (0, 0));
    assert_eq!(original.frame.to_rgb8(), written.frame.to_rgb8());
}
