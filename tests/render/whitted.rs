//! Whitted ray tracing end to end on scenes small enough to work out by hand:
//! direct light, shadows, mirrors, glass, and the depth limit.

use crate::support;
use crate::support::render::{camera, material};
use glam::Vec3;
use raypack::accel::BruteForce;
use raypack::geometry::{Plane, Primitive, Sphere};
use raypack::render::{Block, KernelKind, Mode, Render, RenderSettings, Sampling, render};
use raypack::scene::{CameraSpec, Light, Scene};

fn trace(scene: &Scene, kernel: KernelKind, max_depth: u32) -> Render {
    let camera = scene.camera.unwrap().camera().unwrap();
    let settings = RenderSettings {
        mode: Mode::Whitted,
        kernel,
        block: Block::B4x4,
        tile_size: 4,
        max_depth,
        sampling: Sampling::PixelCentres,
    };
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    render(
        scene,
        &BruteForce::new(&scene.primitives),
        &camera,
        &settings,
        &pool,
        &|| {},
    )
}

/// Both kernels, checked to agree, then the render.
fn trace_both(scene: &Scene, max_depth: u32) -> Render {
    let a = trace(scene, KernelKind::Scalar, max_depth);
    let b = trace(scene, KernelKind::Packet8, max_depth);
    assert_eq!(a.frame, b.frame);
    assert_eq!(a.counts, b.counts);
    b
}

/// A floor `y = 0` seen straight down from (0, 5, 0) in a 3×3 image (the
/// centre pixel's ray is exactly −y), lit from (0, 10, 0).
fn floor_scene(floor: raypack::scene::Material) -> Scene {
    let mut scene = support::render::with_materials(vec![floor]);
    scene.push(Primitive::Plane(Plane::implicit(0.0, 1.0, 0.0, 0.0).unwrap()), 0);
    scene.lights = vec![Light {
        position: Vec3::new(0.0, 10.0, 0.0),
        color: Vec3::ONE,
    }];
    scene.camera = Some(CameraSpec {
        up: Vec3::Z,
        ..camera(Vec3::new(0.0, 5.0, 0.0), Vec3::ZERO, 3)
    });
    scene
}

fn centre(r: &Render) -> Vec3 {
    r.frame.color[r.frame.index(1, 1)]
}

#[test]
fn a_lit_diffuse_floor_gets_ambient_plus_lambert() {
    let c = Vec3::new(0.5, 0.4, 0.2);
    let scene = floor_scene(material(c, 0.8, 0.0, 0.0, 0.0, 1.0));
    let r = trace_both(&scene, 5);
    // ⟨n, l⟩ = 1 at the centre: 0.1·Kd·C + Kd·1·C = 1.1 · 0.8 · C.
    assert!((centre(&r) - 0.88 * c).length() < 1e-6, "{}", centre(&r));
    // Every pixel sees the floor and sends one unblocked shadow ray.
    assert_eq!(r.counts.eye_hits, 9);
    assert_eq!(r.counts.shadow_rays, 9);
    assert_eq!(r.counts.shadow_blocked, 0);
    assert_eq!(r.counts.reflect_rays + r.counts.refract_rays, 0);
}

#[test]
fn a_sphere_between_floor_and_light_casts_a_shadow() {
    let c = Vec3::new(0.5, 0.4, 0.2);
    let mut scene = floor_scene(material(c, 1.0, 0.0, 0.0, 0.0, 1.0));
    scene.materials.push(material(Vec3::ONE, 1.0, 0.0, 0.0, 0.0, 1.0));
    // Above the camera: invisible to it, but on the way from the floor to the light.
    scene.push(Primitive::Sphere(Sphere::new(Vec3::new(0.0, 7.0, 0.0), 1.0)), 1);
    let r = trace_both(&scene, 5);
    assert!((centre(&r) - 0.1 * c).length() < 1e-6, "{}", centre(&r));
    assert_eq!(r.counts.shadow_rays, 9);
    assert!(r.counts.shadow_blocked >= 1);
}

#[test]
fn a_light_behind_the_surface_sends_no_shadow_ray() {
    let c = Vec3::new(0.5, 0.4, 0.2);
    let mut scene = floor_scene(material(c, 1.0, 0.0, 0.0, 0.0, 1.0));
    scene.lights[0].position = Vec3::new(0.0, -10.0, 0.0);
    let r = trace_both(&scene, 5);
    assert_eq!(r.counts.shadow_rays, 0);
    assert!((centre(&r) - 0.1 * c).length() < 1e-6);
}

#[test]
fn a_mirror_floor_shows_what_is_above_it() {
    // Pure mirror floor (Kd = 0, Ks = 1, no highlight); above it a diffuse
    // sphere whose underside faces away from the light: the centre pixel is the
    // sphere's ambient colour, seen in the mirror.
    let s = Vec3::new(0.2, 0.9, 0.3);
    let mut scene = floor_scene(material(Vec3::ONE, 0.0, 1.0, 0.0, 0.0, 1.0));
    scene.materials.push(material(s, 1.0, 0.0, 0.0, 0.0, 1.0));
    scene.push(Primitive::Sphere(Sphere::new(Vec3::new(0.0, 7.0, 0.0), 1.0)), 1);
    let r = trace_both(&scene, 5);
    assert!((centre(&r) - 0.1 * s).length() < 1e-6, "{}", centre(&r));
    assert_eq!(r.counts.reflect_rays, 9);
    // Depth 1 is ray casting with shadows: no reflection, the mirror stays black.
    let r1 = trace_both(&scene, 1);
    assert_eq!(r1.counts.reflect_rays, 0);
    assert_eq!(centre(&r1), Vec3::ZERO);
}

/// Two facing mirrors `z = −1` and `z = 1` with the camera between them: every
/// ray bounces until the depth limit.
fn mirror_pair(light: bool) -> Scene {
    let mut scene = support::render::with_materials(vec![material(Vec3::ONE, 0.5, 0.5, 10.0, 0.0, 1.0)]);
    scene.push(
        Primitive::Plane(Plane::point_normal(-Vec3::Z, Vec3::Z).unwrap()),
        0,
    );
    scene.push(
        Primitive::Plane(Plane::point_normal(Vec3::Z, -Vec3::Z).unwrap()),
        0,
    );
    if light {
        scene.lights = vec![Light {
            position: Vec3::new(0.0, 0.0, 0.3),
            color: Vec3::ONE,
        }];
    }
    scene.camera = Some(camera(Vec3::new(0.0, 0.0, 0.5), Vec3::new(0.0, 0.0, -1.0), 16));
    scene
}

#[test]
fn the_depth_limit_bounds_the_ray_tree_with_the_eye_ray_at_depth_one() {
    let scene = mirror_pair(false);
    for depth in 1..=6 {
        let r = trace_both(&scene, depth);
        assert_eq!(r.counts.eye_hits, 256);
        assert_eq!(r.counts.reflect_rays, 256 * u64::from(depth - 1), "depth {depth}");
    }
    // Default depth 5 with a light between the mirrors: a shadow ray at every
    // hit (the light is in front of both mirrors), none blocked.
    let r = trace_both(&mirror_pair(true), 5);
    assert_eq!(r.counts.shadow_rays, 5 * 256);
    assert_eq!(r.counts.shadow_blocked, 0);
}

#[test]
fn glass_spheres_refract_in_and_out() {
    // A glass sphere (T > 0, Ks = 0) in front of an empty background, no lights.
    // Every hit on a transmitter spawns a reflection ray (the SPD's rule, even at
    // Ks = 0) and a refraction ray: the eye hit reflects into the void and
    // refracts in; each inside hit at depths 2, 3 and 4 refracts out into the
    // void and reflects on inside, to the next inside hit. So 4 reflection and 4
    // refraction rays per eye hit. A sphere never reflects totally on the way
    // out (the exit angle equals the entry's refraction angle), but rounding
    // may tip a handful of grazing exits into total internal reflection, which
    // spawns the reflection alone.
    let mut scene = support::render::with_materials(vec![material(Vec3::ONE, 0.0, 0.0, 0.0, 1.0, 1.5)]);
    scene.push(Primitive::Sphere(Sphere::new(Vec3::ZERO, 1.0)), 0);
    scene.camera = Some(camera(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, 40));
    scene.background = Vec3::new(0.0, 0.0, 1.0);
    let r = trace_both(&scene, 5);
    let hits = r.counts.eye_hits;
    assert!(hits > 200, "{hits}");
    let (reflect, refract) = (r.counts.reflect_rays, r.counts.refract_rays);
    assert!(refract <= 4 * hits && reflect >= 4 * hits, "{:?}", r.counts);
    assert!((8 * hits - (reflect + refract)) * 100 <= hits, "{:?}", r.counts);
    // Weights T = 1 all the way: the sphere shows the background colour.
    let c = r.frame.color[r.frame.index(20, 20)];
    assert!((c - scene.background).length() < 1e-6, "{c}");
}

/// Glass (T = 1, ior 1.5, Ks = 0) filling the half-space below `y = 0`, seen
/// from inside it at `eye` looking at `center`, 3×3 pixels, no lights.
fn glass_below(eye: Vec3, center: Vec3) -> Scene {
    let mut scene = support::render::with_materials(vec![material(Vec3::ONE, 0.0, 0.0, 0.0, 1.0, 1.5)]);
    scene.push(Primitive::Plane(Plane::implicit(0.0, 1.0, 0.0, 0.0).unwrap()), 0);
    scene.camera = Some(CameraSpec {
        up: Vec3::Z,
        ..camera(eye, center, 3)
    });
    scene
}

#[test]
fn total_internal_reflections_count_as_refraction_rays_in_the_spd_tally() {
    // From (0, −1, 0) towards (2, 0, 0) every eye ray meets the surface from inside at 48°–78°
    // from the normal, beyond the critical angle asin(1/1.5) = 41.8°: total
    // internal reflection, so one reflection ray each (down into the void) and
    // no refraction ray, but the SPD's table counts one there (rule 9 as
    // Haines tallies it; see RayCounts::spd_refract_rays).
    let r = trace_both(&glass_below(-Vec3::Y, Vec3::new(2.0, 0.0, 0.0)), 5);
    assert_eq!(r.counts.eye_hits, 9);
    assert_eq!(r.counts.reflect_rays, 9);
    assert_eq!(r.counts.refract_rays, 0);
    assert_eq!(r.counts.total_internal_reflections, 9);
    assert_eq!(r.counts.spd_refract_rays(), 9);
    assert_eq!(r.counts.total(), 9 + 9);
    // Nearly along the normal (11° ± 16°) every ray gets out: no TIR.
    let r = trace_both(&glass_below(-3.0 * Vec3::Y, Vec3::new(0.6, 0.0, 0.0)), 5);
    assert_eq!(
        (r.counts.reflect_rays, r.counts.refract_rays),
        (9, 9),
        "{:?}",
        r.counts
    );
    assert_eq!(r.counts.total_internal_reflections, 0);
    assert_eq!(r.counts.spd_refract_rays(), 9);
    // At the depth limit nothing is spawned, so nothing is counted.
    let r = trace_both(&glass_below(-Vec3::Y, Vec3::new(2.0, 0.0, 0.0)), 1);
    assert_eq!(r.counts.reflect_rays + r.counts.spd_refract_rays(), 0);
}
