//! The standard ray kinds' any-hit answers are right: on the shadow and
//! ambient-occlusion rays of a generated mesh and of SPD scenes, raypack's
//! `occluded` (single and packet) is true exactly when its nearest hit lies
//! within the ray's `[t_min, t_max]`; and with the `embree` feature, raypack
//! and Embree agree on hit/miss for at least 99.9% of the rays of every kind.

use std::path::Path;

use raypack::accel::{Accel, Bvh};
use raypack::bench::rays::{KindRays, RayKind};
use raypack::bench::traversal::{TraversalSetup, scene_bounds};
use raypack::scene::generate::random::framing_camera;
use raypack::simd::SimdFloat;

/// The rays of every kind over a few scenes, on a small image.
fn setups() -> Vec<TraversalSetup> {
    let mut setups = vec![TraversalSetup::generated("mesh", 20_000, (96, 64), 4096, &RayKind::ALL).unwrap()];
    for file in ["scenes/spd_balls_small.nff", "scenes/spd_tetra_small.nff"] {
        let scene = raypack::scene::load(Path::new(file)).unwrap();
        let camera = match scene.camera {
            Some(spec) => spec.camera_at(96, 64).unwrap(),
            None => framing_camera(scene_bounds(&scene), 96, 64),
        };
        let light = scene.lights.first().map(|l| l.position);
        setups.push(TraversalSetup::new(
            file,
            scene,
            &camera,
            light,
            4096,
            &RayKind::ALL,
        ));
    }
    setups
}

/// Per ray of `set`: hit (nearest) or occluded (any hit), single rays.
fn single_answers(accel: &impl Accel, set: &KindRays) -> Vec<bool> {
    set.rays
        .iter()
        .map(|r| match set.kind {
            RayKind::Shadow | RayKind::Ao => accel.occluded(r),
            _ => accel.intersect(r).is_hit(),
        })
        .collect()
}

#[test]
fn any_hit_is_a_nearest_hit_within_the_ray() {
    for setup in setups() {
        let bvh = Bvh::new(&setup.scene.primitives);
        for kind in [RayKind::Shadow, RayKind::Ao] {
            let set = setup.rays_of(kind).unwrap();
            let occluded = single_answers(&bvh, set);
            let nearest: Vec<bool> = set.rays.iter().map(|r| bvh.intersect(r).is_hit()).collect();
            assert_eq!(occluded, nearest, "{} {kind:?}", setup.name);
            let packets: Vec<bool> = set
                .packets
                .iter()
                .flat_map(|p| {
                    let mask = bvh.occluded_packet(p).bitmask();
                    (0..8)
                        .filter(|&i| p.is_active(i))
                        .map(move |i| mask & (1 << i) != 0)
                })
                .collect();
            assert_eq!(packets, occluded, "{} {kind:?} packets", setup.name);
            // Neither all nor none: the rays test something.
            let hits = occluded.iter().filter(|&&h| h).count();
            assert!(
                hits > 0 && hits < occluded.len(),
                "{} {kind:?}: {hits}",
                setup.name
            );
        }
    }
}

#[cfg(feature = "embree")]
#[test]
fn raypack_and_embree_agree_on_hit_or_miss_of_every_kind() {
    use std::sync::Arc;

    use raypack::embree::{Device, EmbreeScene};

    let device = Arc::new(Device::with_default_config().expect("Embree device"));
    for setup in setups() {
        let bvh = Bvh::new(&setup.scene.primitives);
        let embree = EmbreeScene::new(device.clone(), &setup.scene.primitives).unwrap();
        for set in &setup.kinds {
            let ours = single_answers(&bvh, set);
            let theirs = single_answers(&embree, set);
            let same = ours.iter().zip(&theirs).filter(|(a, b)| a == b).count();
            let agreement = same as f64 / ours.len() as f64;
            assert!(
                agreement >= 0.999,
                "{} {:?}: {same} of {} agree",
                setup.name,
                set.kind,
                ours.len()
            );
        }
    }
}
