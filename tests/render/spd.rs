//! `stats --spd`: the SPD's counting procedure gives identical counts with the
//! scalar and the packet kernels, and hand-derived counts on simple scenes.

use crate::support;
use crate::support::render::{camera, material};
use glam::Vec3;
use raypack::accel::BruteForce;
use raypack::geometry::{Plane, Primitive};
use raypack::render::spd::{SPD_SIZE, spd_counts};
use raypack::render::{KernelKind, RayCounts};
use raypack::scene::{Light, Scene};

fn counts(scene: &Scene, kernel: KernelKind, threads: usize) -> RayCounts {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    spd_counts(scene, &BruteForce::new(&scene.primitives), kernel, &pool).unwrap()
}

const EYE_RAYS: u64 = (SPD_SIZE as u64 + 1) * (SPD_SIZE as u64 + 1);

#[test]
fn spd_counts_are_identical_for_scalar_and_packet_kernels() {
    for seed in [2, 8] {
        let scene = support::render::mixed_scene(12, seed);
        let scalar = counts(&scene, KernelKind::Scalar, 2);
        let packet = counts(&scene, KernelKind::Packet8, 2);
        assert_eq!(scalar, packet, "seed {seed}");
        assert_eq!(scalar.eye_rays, EYE_RAYS);
        // The scene exercises every counter.
        assert!(scalar.eye_hits > 0 && scalar.eye_hits < EYE_RAYS);
        assert!(scalar.reflect_rays > 0 && scalar.refract_rays > 0);
        assert!(scalar.shadow_blocked > 0 && scalar.shadow_blocked < scalar.shadow_rays);
        // And the counts do not depend on the thread count.
        assert_eq!(counts(&scene, KernelKind::Packet8, 1), packet);
    }
}

#[test]
fn spd_counts_of_a_mirror_corridor_follow_from_the_rules() {
    // Two facing mirrors, a light between them, the camera looking down the
    // corridor: all 513² eye rays hit; each hit spawns a reflection while the
    // depth (eye = 1) is below 5, so 4 per eye ray; each of the 5 hits per eye
    // ray sees the light in front of its mirror: 5 unblocked shadow rays.
    let mut scene = support::render::with_materials(vec![material(Vec3::ONE, 0.5, 0.5, 10.0, 0.0, 1.0)]);
    scene.push(
        Primitive::Plane(Plane::point_normal(-Vec3::Z, Vec3::Z).unwrap()),
        0,
    );
    scene.push(
        Primitive::Plane(Plane::point_normal(Vec3::Z, -Vec3::Z).unwrap()),
        0,
    );
    scene.lights = vec![Light {
        position: Vec3::new(0.0, 0.0, 0.3),
        color: Vec3::ONE,
    }];
    scene.camera = Some(camera(Vec3::new(0.0, 0.0, 0.5), Vec3::new(0.0, 0.0, -1.0), 64));
    let expected = RayCounts {
        eye_rays: EYE_RAYS,
        eye_hits: EYE_RAYS,
        reflect_rays: 4 * EYE_RAYS,
        refract_rays: 0,
        total_internal_reflections: 0,
        shadow_rays: 5 * EYE_RAYS,
        shadow_blocked: 0,
    };
    assert_eq!(counts(&scene, KernelKind::Scalar, 2), expected);
    assert_eq!(counts(&scene, KernelKind::Packet8, 2), expected);
}

#[test]
fn spd_eye_rays_go_through_pixel_corners() {
    // A half-space floor filling exactly the lower half of the view: with
    // corner rays the middle row (j = 256) looks exactly at the horizon
    // direction of the camera axis and the rows below it hit.
    let mut scene = support::render::with_materials(vec![material(Vec3::ONE, 1.0, 0.0, 0.0, 0.0, 1.0)]);
    scene.push(
        Primitive::Plane(Plane::point_normal(Vec3::new(0.0, -1.0, 0.0), Vec3::Y).unwrap()),
        0,
    );
    scene.camera = Some(camera(Vec3::ZERO, -Vec3::Z, 8));
    let c = counts(&scene, KernelKind::Packet8, 2);
    // Rows j = 257..=512 point below the horizon and hit; row 256 is parallel
    // to the floor and misses; rows above miss.
    assert_eq!(c.eye_hits, 256 * 513);
    assert_eq!(c.eye_rays, EYE_RAYS);
}
