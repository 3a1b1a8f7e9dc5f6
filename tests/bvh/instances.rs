//! The two-level structure over instances against brute force over the same
//! scene flattened: the same primitive ids, t within rounding, the same
//! blocked rays; single rays and packets alike.

use glam::{Mat4, Quat, Vec3};
use raypack::accel::{Accel, BruteForce, Bvh, TwoLevel};
use raypack::geometry::{Plane, Primitive};
use raypack::packet::RayPacket;
use raypack::ray::{Hit, Ray};
use raypack::rng::Rng;
use raypack::scene::generate::random::{random_mixed, random_triangles};
use raypack::scene::{Mesh, Scene};
use raypack::simd::SimdFloat;
use wide::{f32x8, f32x16};

use crate::support::bvh::{key, random_rays};

/// A mesh of `prims`, every primitive material 0.
fn mesh(name: &str, prims: Vec<Primitive>) -> Mesh {
    Mesh {
        name: name.into(),
        material_of: vec![0; prims.len()],
        primitives: prims,
        ..Mesh::default()
    }
}

/// A random rotation, non-uniform scale and translation within `[-spread, spread]³`.
fn random_placement(rng: &mut Rng, spread: f32) -> Mat4 {
    let axis = rng.unit_vector();
    let scale = Vec3::new(rng.range(0.3, 1.5), rng.range(0.3, 1.5), rng.range(0.3, 1.5));
    let at = rng.point_in(Vec3::splat(-spread), Vec3::splat(spread));
    Mat4::from_scale_rotation_translation(scale, Quat::from_axis_angle(axis, rng.range(0.0, 6.3)), at)
}

/// Own primitives (triangles), a triangle mesh and a mixed mesh (spheres,
/// cones, polygons, transformed shapes: unit directions needed) placed
/// 24 times each, and one instance of a mesh holding a plane.
fn instanced_scene(seed: u64) -> Scene {
    let mut rng = Rng::new(seed);
    let mut scene = Scene::default();
    for p in random_triangles(50, seed) {
        scene.push(p, 0);
    }
    let triangles = scene.add_mesh(mesh("triangles", random_triangles(300, seed + 1)));
    let bounded = random_mixed(120, seed + 2)
        .into_iter()
        .filter(|p| p.bounds().is_some());
    let mixed = scene.add_mesh(mesh("mixed", bounded.collect()));
    let floor = vec![Primitive::Plane(Plane::implicit(0.0, 1.0, 0.0, 4.0).unwrap())];
    let floor = scene.add_mesh(mesh("floor", floor));
    for k in 0..48 {
        let m = random_placement(&mut rng, 3.0);
        scene
            .place(if k % 2 == 0 { triangles } else { mixed }, m)
            .unwrap();
    }
    scene.place(floor, random_placement(&mut rng, 0.5)).unwrap();
    scene
}

/// How two answers compare: the same primitive with t within a relative
/// 10⁻⁴ (the ray moved into the mesh's space against the mesh moved into
/// the world's), or not.
fn same(a: &Hit, b: &Hit) -> bool {
    a.prim == b.prim && (!a.is_hit() || (a.t - b.t).abs() <= 1e-4 * a.t.abs().max(1.0))
}

/// The packet answers of width `F` equal the single-ray answers bit for bit.
fn check_packets<F: SimdFloat, A: Accel>(accel: &A, rays: &[Ray], singles: &[Hit], blocked: &[bool]) {
    for (rs, (hs, bs)) in rays
        .chunks(F::LANES)
        .zip(singles.chunks(F::LANES).zip(blocked.chunks(F::LANES)))
    {
        let packet = RayPacket::<F>::from_rays(rs);
        let hits = accel.intersect_packet(&packet);
        let occluded = accel.occluded_packet(&packet).bitmask();
        for (lane, (h, b)) in hs.iter().zip(bs).enumerate() {
            assert_eq!(
                key(&hits.hit(lane)),
                key(h),
                "packet{} lane {lane} {:?}",
                F::LANES,
                rs[lane]
            );
            assert_eq!(
                occluded >> lane & 1 == 1,
                *b,
                "occluded packet{} lane {lane}",
                F::LANES
            );
        }
    }
}

#[test]
fn instances_answer_as_the_flattened_scene_does() {
    let scene = instanced_scene(11);
    let flat = scene.flattened().unwrap();
    assert_eq!(flat.primitives.len() as u64, scene.id_count());
    let sizes: Vec<u64> = scene
        .instances
        .meshes()
        .iter()
        .map(|m| m.primitives.len() as u64)
        .collect();
    assert_eq!(scene.id_count(), 50 + 24 * sizes[0] + 24 * sizes[1] + 1);
    let reference = BruteForce::new(&flat.primitives);
    let two_level = TwoLevel::new(&scene, Bvh::new);
    let brute_two_level = TwoLevel::new(&scene, BruteForce::new);
    assert_eq!(two_level.instance_counts(), (48, 1));

    let rays = random_rays(scene.bounds(), 20_000, 12);
    let (mut differ, mut hits) = (0, 0);
    let mut singles = Vec::new();
    let mut blocked = Vec::new();
    for ray in &rays {
        let expect = reference.intersect(ray);
        let got = two_level.intersect(ray);
        // The two-level walk finds what brute force over the same instances finds.
        assert_eq!(key(&got), key(&brute_two_level.intersect(ray)), "{ray:?}");
        differ += usize::from(!same(&got, &expect));
        hits += usize::from(expect.is_hit());
        let b = two_level.occluded(ray);
        assert_eq!(
            b,
            got.is_hit(),
            "occluded iff hit (unbounded rays included) {ray:?}"
        );
        assert_eq!(b, brute_two_level.occluded(ray));
        singles.push(got);
        blocked.push(b);
    }
    assert!(
        hits > rays.len() / 4 && hits < rays.len() * 19 / 20,
        "{hits} hits"
    );
    // Only rays through a shared edge or a tangent point may go either way.
    assert!(
        differ <= rays.len() / 2000,
        "{differ} of {} rays differ from the flattened scene",
        rays.len()
    );
    check_packets::<f32x8, _>(&two_level, &rays, &singles, &blocked);
    check_packets::<f32x16, _>(&two_level, &rays, &singles, &blocked);
}

#[test]
fn an_id_names_its_instance_and_mesh_primitive() {
    let scene = instanced_scene(3);
    let own = scene.primitives.len() as u32;
    assert_eq!(scene.locate(own - 1).instance.map(|(i, _)| i), None);
    let first = scene.locate(own);
    assert_eq!((first.instance.map(|(i, _)| i), first.index), (Some(0), 0));
    // Instance 0 places the 300 triangles, instance 1 the mixed primitives.
    let second = scene.locate(own + 300 + 5);
    assert_eq!((second.instance.map(|(i, _)| i), second.index), (Some(1), 5));
    let last = scene.locate(scene.id_count() as u32 - 1);
    assert_eq!((last.instance.map(|(i, _)| i), last.index), (Some(48), 0));
}

#[test]
fn a_scene_past_32_bit_ids_is_refused() {
    let mut scene = Scene::default();
    let big = scene.add_mesh(mesh("big", random_triangles(1 << 20, 1)));
    for _ in 0..4095 {
        scene.place(big, Mat4::IDENTITY).unwrap();
    }
    let e = scene.place(big, Mat4::IDENTITY).unwrap_err();
    assert!(e.to_string().contains("32-bit ids"), "{e}");
    let singular = scene.add_mesh(mesh("one", random_triangles(1, 2)));
    let e = scene
        .place(singular, Mat4::from_scale(Vec3::new(1.0, 0.0, 1.0)))
        .unwrap_err();
    assert!(e.to_string().contains("singular"), "{e}");
}

#[test]
fn a_ray_through_many_instances_counts_once() {
    use raypack::accel::TraversalCounter;
    let scene = instanced_scene(5);
    let two_level = TwoLevel::new(&scene, Bvh::new);
    let rays = random_rays(scene.bounds(), 64, 6);
    let mut single = TraversalCounter::totals();
    for ray in &rays {
        two_level.intersect_counted(ray, &mut single);
        two_level.occluded_counted(ray, &mut single);
    }
    assert_eq!(single.total().rays, 128);
    assert!(single.total().nodes_visited > 128, "the walks' nodes still count");
    let mut packets = TraversalCounter::totals();
    for chunk in rays.chunks(8) {
        two_level.intersect_packet_counted(&RayPacket::<f32x8>::from_rays(chunk), &mut packets);
    }
    assert_eq!((packets.total().rays, packets.total().packets), (64, 8));
}
