//! The whole path on any NFF text: parse, build the BVH, trace a few rays
//! (camera rays, and rays aimed at the first primitives) with both the
//! single-ray and the 8-wide packet traversal, which must agree lane by lane.
#![no_main]

use libfuzzer_sys::fuzz_target;
use raypack::accel::{Accel, Bvh};
use raypack::packet::RayPacket8;
use raypack::ray::Ray;
use raypack::scene::Scene;
use std::path::Path;

/// Image size of the camera rays: 4×4 pixels, two packets.
const PIXELS: u32 = 4;

fn rays(scene: &Scene) -> Vec<Ray> {
    let mut rays = Vec::new();
    let spec = scene.camera.unwrap_or_else(|| scene.default_camera());
    if let Ok(camera) = spec.camera_at(PIXELS, PIXELS) {
        for k in 0..PIXELS * PIXELS {
            rays.push(camera.pixel_ray(k % PIXELS, k / PIXELS));
        }
    }
    // From a corner of the scene's box (or the origin) at the centres of the
    // first primitives' boxes: rays that hit something.
    let bounds = scene.bounds();
    let from = if bounds.is_empty() || !bounds.min.is_finite() {
        glam::Vec3::new(0.3, 0.7, 11.0)
    } else {
        bounds.min - glam::Vec3::ONE
    };
    for b in scene.primitives.iter().filter_map(|p| p.bounds()).take(16) {
        if let Some(dir) = (b.center() - from).try_normalize() {
            rays.push(Ray::unbounded(from, dir));
        }
    }
    rays
}

fuzz_target!(|data: &[u8]| {
    let Ok(scene) = raypack::scene::nff::parse(Path::new("fuzz.nff"), data) else {
        return;
    };
    let bvh = Bvh::new(&scene.primitives);
    let rays = rays(&scene);
    for chunk in rays.chunks(8) {
        let packet = RayPacket8::from_rays(chunk);
        let hits = bvh.intersect_packet(&packet);
        for (i, ray) in chunk.iter().enumerate() {
            let scalar = bvh.intersect(ray);
            let lane = hits.hit(i);
            assert_eq!(lane.prim, scalar.prim, "lane {i} of {ray:?}: {lane:?} vs scalar {scalar:?}");
            assert!(
                lane.t == scalar.t || (lane.t - scalar.t).abs() <= 1e-5 * scalar.t.abs(),
                "lane {i} of {ray:?}: t {} vs scalar {}",
                lane.t,
                scalar.t
            );
        }
    }
});
