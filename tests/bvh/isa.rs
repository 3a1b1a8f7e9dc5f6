//! Every instruction set answers every BVH query as the portable level does,
//! bit for bit (#18): the same hits (t, primitive, u, v), the same occlusion,
//! for single rays and 4-, 8- and 16-wide packets, on triangle meshes, sphere
//! clouds and scenes of every shape, with random, primary and hostile rays
//! (NaN and infinite components, zero directions). Levels this CPU cannot run
//! are skipped, and the test says which.

use glam::Vec3;
use raypack::accel::{Accel, Bvh};
use raypack::geometry::Primitive;
use raypack::packet::RayPacket;
use raypack::ray::Ray;
use raypack::scene::generate::random;
use raypack::simd::{Isa, SimdFloat, SimdU32};
use wide::{f32x4, f32x8, f32x16};

use crate::support::bvh::{key, primary_packets, random_rays, scene_bounds};

/// Everything a level answers for `rays`: per ray its single-ray hit and
/// occlusion, then per packet width the packets' hits and occlusion masks.
fn answers(bvh: &Bvh, rays: &[Ray]) -> Vec<(u32, u32, u32, u32)> {
    let mut out = Vec::new();
    for ray in rays {
        out.push(key(&bvh.intersect(ray)));
        out.push((u32::from(bvh.occluded(ray)), 0, 0, 0));
    }
    packet_answers::<f32x4>(bvh, rays, &mut out);
    packet_answers::<f32x8>(bvh, rays, &mut out);
    packet_answers::<f32x16>(bvh, rays, &mut out);
    out
}

fn packet_answers<F: SimdFloat>(bvh: &Bvh, rays: &[Ray], out: &mut Vec<(u32, u32, u32, u32)>) {
    for (i, chunk) in rays.chunks(F::LANES).enumerate() {
        // Some lanes off, as the renderer's masks leave them.
        let mask = if i % 3 == 0 {
            0b1011_0110_1101_1011
        } else {
            u32::MAX
        };
        let packet = RayPacket::<F>::from_rays_masked(chunk, mask);
        let hits = bvh.intersect_packet(&packet);
        let (t, prim, u, v) = (
            hits.t.to_array(),
            hits.prim.to_array(),
            hits.u.to_array(),
            hits.v.to_array(),
        );
        for lane in 0..F::LANES {
            out.push((
                t.as_ref()[lane].to_bits(),
                prim.as_ref()[lane],
                u.as_ref()[lane].to_bits(),
                v.as_ref()[lane].to_bits(),
            ));
        }
        out.push((bvh.occluded_packet(&packet).bitmask(), 1, 0, 0));
    }
}

/// Rays with NaN and infinite components, zero and axis-parallel directions.
fn hostile_rays(bounds: raypack::bounds::Aabb) -> Vec<Ray> {
    let c = bounds.center();
    let specials = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 0.0, -0.0, 1e-40, 1e30];
    let mut rays = Vec::new();
    for (i, &s) in specials.iter().enumerate() {
        for axis in 0..3 {
            let mut origin = c - 3.0 * bounds.extent();
            origin[axis] = s;
            rays.push(Ray::unbounded(origin, (c - origin).normalize_or(Vec3::X)));
            let mut dir = Vec3::new(0.3, -0.5, 0.8);
            dir[axis] = s;
            rays.push(Ray::new(
                c,
                dir,
                0.0,
                if i % 2 == 0 { f32::INFINITY } else { s.abs() },
            ));
            rays.push(Ray::unbounded(bounds.min, Vec3::AXES[axis]));
        }
    }
    rays
}

fn check(name: &str, prims: &[Primitive]) {
    let mut bvh = Bvh::new(prims);
    let bounds = scene_bounds(prims);
    let mut rays = random_rays(bounds, 20_000, 3);
    rays.extend(
        primary_packets(bounds, 96, 96)
            .into_iter()
            .flat_map(|(rays, _)| rays),
    );
    rays.extend(hostile_rays(bounds));
    bvh.set_isa(Isa::Portable).unwrap();
    let expected = answers(&bvh, &rays);
    let hits = rays.iter().filter(|r| bvh.intersect(r).is_hit()).count();
    assert!(
        hits > rays.len() / 10,
        "{name}: {hits} hits of {} rays: too few for the test to prove much",
        rays.len()
    );
    for isa in Isa::available() {
        bvh.set_isa(isa).unwrap();
        let got = answers(&bvh, &rays);
        let first = expected.iter().zip(&got).position(|(e, g)| e != g);
        assert_eq!(
            first, None,
            "{name}: {isa} differs from portable at answer {first:?}"
        );
    }
}

#[test]
fn every_instruction_set_answers_as_the_portable_one() {
    let skipped: Vec<&str> = Isa::ALL
        .iter()
        .filter(|i| !i.is_available())
        .map(|i| i.name())
        .collect();
    eprintln!(
        "instruction sets checked: {:?}; skipped (this CPU lacks them): {skipped:?}",
        Isa::available().iter().map(|i| i.name()).collect::<Vec<_>>()
    );
    check("mesh", &random::bumpy_sphere(20_000, 4));
    check("spheres", &random::random_spheres(2000, 5));
    check("mixed", &random::random_mixed(1500, 9));
}

#[test]
fn a_level_the_cpu_lacks_is_refused() {
    let mut bvh = Bvh::new(&random::random_spheres(10, 1));
    for isa in Isa::ALL {
        assert_eq!(bvh.set_isa(isa).is_ok(), isa.is_available(), "{isa}");
    }
    assert_eq!("avx2".parse::<Isa>(), Ok(Isa::Avx2));
    assert_eq!("auto".parse::<Isa>(), Ok(Isa::best()));
    assert!("avx9".parse::<Isa>().is_err());
}
