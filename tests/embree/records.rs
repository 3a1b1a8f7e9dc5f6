//! The traps of calling Embree 4.4 through `embree4-sys` 0.0.12 (whose bindings
//! come from the Embree 4.2 headers), each shown to be real and shown handled.

use std::mem::{align_of, offset_of, size_of};
use std::sync::Arc;

use embree4_sys as sys;
use glam::Vec3;
use raypack::accel::Accel;
use raypack::embree::denormals::denormals_flushed;
use raypack::embree::ray_hit::{
    INVALID_ID, RayHit1, RayHit4, RayHit8, RayHit16, RayHitPacket, intersect_arguments,
};
use raypack::embree::{Device, EmbreeScene};
use raypack::geometry::{Primitive, Triangle};
use raypack::packet::RayPacket8;
use raypack::ray::{NO_HIT, Ray};

fn device() -> Arc<Device> {
    Arc::new(Device::with_default_config().expect("Embree device"))
}

/// One big triangle in the plane z = 0 and rays towards it from z = 1.
fn triangle_scene(device: &Arc<Device>) -> EmbreeScene {
    let tri = Triangle::new(
        Vec3::new(-100.0, -100.0, 0.0),
        Vec3::new(100.0, -100.0, 0.0),
        Vec3::new(0.0, 100.0, 0.0),
    );
    EmbreeScene::new(device.clone(), &[Primitive::Triangle(tri)]).expect("scene")
}

fn down(x: f32) -> Ray {
    Ray::unbounded(Vec3::new(x, 0.0, 1.0), Vec3::NEG_Z)
}

#[test]
fn padded_records_extend_the_4_2_layout_by_inst_prim_id() {
    // The 4.2 layout the bindings describe.
    assert_eq!(size_of::<sys::RTCRayHit>(), 80);
    assert_eq!(size_of::<sys::RTCRayHit8>(), 640);
    // Embree 4.4's: instPrimID right after, and the size rounded to the alignment.
    assert_eq!((size_of::<RayHit1>(), align_of::<RayHit1>()), (96, 16));
    assert_eq!(offset_of!(RayHit1, inst_prim_id), 80);
    for (inner, pad, valid, size, align, n) in [
        (
            size_of::<sys::RTCRayHit4>(),
            offset_of!(RayHit4, inst_prim_id),
            offset_of!(RayHit4, valid),
            size_of::<RayHit4>(),
            align_of::<RayHit4>(),
            4,
        ),
        (
            size_of::<sys::RTCRayHit8>(),
            offset_of!(RayHit8, inst_prim_id),
            offset_of!(RayHit8, valid),
            size_of::<RayHit8>(),
            align_of::<RayHit8>(),
            8,
        ),
        (
            size_of::<sys::RTCRayHit16>(),
            offset_of!(RayHit16, inst_prim_id),
            offset_of!(RayHit16, valid),
            size_of::<RayHit16>(),
            align_of::<RayHit16>(),
            16,
        ),
    ] {
        assert_eq!(pad, inner, "instPrimID follows the {n}-lane record");
        assert_eq!(valid, inner + 4 * n, "the valid mask follows instPrimID");
        assert_eq!(align, 4 * n, "rtcIntersect{n} alignment");
        assert_eq!(valid % align, 0, "the valid mask is aligned too");
        assert_eq!(size, inner + 8 * n);
    }
}

#[test]
fn embree_4_4_writes_inst_prim_id_past_the_4_2_record() {
    let device = device();
    assert!(device.version() >= 40000, "{}", device.version_string());
    assert_eq!(device.writes_inst_prim_id().unwrap(), device.version() >= 40300);
    let scene = triangle_scene(&device);

    /// The 4.2 record with the 4 bytes that follow it on the stack.
    #[repr(C)]
    struct Unpadded {
        record: sys::RTCRayHit,
        next: u32,
    }
    let record = RayHit1::new(&down(0.0));
    let mut unpadded = Unpadded {
        record: record.inner,
        next: 0xABCD_EF01,
    };
    let mut args = intersect_arguments();
    // SAFETY: deliberately unpadded; `next` is ours to be overwritten.
    unsafe { sys::rtcIntersect1(scene.raw_scene(), &mut unpadded.record, &mut args) };
    assert_eq!(unpadded.record.hit.geomID, 0);
    if device.writes_inst_prim_id().unwrap() {
        assert_eq!(
            unpadded.next, INVALID_ID,
            "Embree ≥ 4.3 overwrote the word after RTCRayHit"
        );
    } else {
        assert_eq!(unpadded.next, 0xABCD_EF01);
    }

    // The packet record: the 32 bytes after RTCRayHit8 are written on hit lanes,
    // and the valid mask after them is left alone.
    let rays: Vec<Ray> = (0..8).map(|i| down(i as f32)).collect();
    let packet = RayPacket8::from_rays_masked(&rays, 0b0101_1011);
    let mut record = RayHit8::new(&packet);
    record.inst_prim_id = [0x1234_5678; 8];
    let valid_before = record.valid;
    // SAFETY: a committed scene.
    unsafe { record.intersect(scene.raw_scene(), &mut intersect_arguments()) };
    assert_eq!(record.valid, valid_before);
    for lane in 0..8 {
        let active = 0b0101_1011 >> lane & 1 == 1;
        assert_eq!(record.geom_id()[lane] == 0, active, "lane {lane}");
        let expected = if active && device.writes_inst_prim_id().unwrap() {
            INVALID_ID
        } else {
            0x1234_5678
        };
        assert_eq!(record.inst_prim_id[lane], expected, "lane {lane}");
    }
}

#[test]
fn rays_need_an_all_ones_mask() {
    let device = device();
    let scene = triangle_scene(&device);
    let trace = |mask: u32| {
        let mut record = RayHit1::new(&down(0.0));
        record.inner.ray.mask = mask;
        // SAFETY: a committed scene and a padded record.
        unsafe { sys::rtcIntersect1(scene.raw_scene(), &mut record.inner, &mut intersect_arguments()) };
        record.inner.hit.geomID
    };
    // This build has ray masks on: a zero mask skips every geometry.
    assert_eq!(trace(0), INVALID_ID);
    assert_eq!(trace(u32::MAX), 0);
    // A miss leaves geomID at RTC_INVALID_GEOMETRY_ID, which is how misses are told.
    let mut miss = RayHit1::new(&Ray::unbounded(Vec3::new(0.0, 0.0, 1.0), Vec3::Z));
    // SAFETY: as above.
    unsafe { sys::rtcIntersect1(scene.raw_scene(), &mut miss.inner, &mut intersect_arguments()) };
    assert_eq!(
        (miss.inner.hit.geomID, miss.inner.ray.tfar),
        (INVALID_ID, f32::INFINITY)
    );
}

#[test]
fn inactive_lanes_are_neither_traced_nor_changed() {
    let device = device();
    let scene = triangle_scene(&device);
    let rays: Vec<Ray> = (0..8)
        .map(|i| Ray::new(Vec3::new(i as f32, 0.0, 1.0), Vec3::NEG_Z, 0.0, 50.0 + i as f32))
        .collect();
    for mask in [0u32, 0b1, 0b1000_0000, 0b0110_1001, 0xFF] {
        let packet = RayPacket8::from_rays_masked(&rays, mask);
        let hits = scene.intersect_packet(&packet);
        let occluded = scene.occluded_packet(&packet);
        for (lane, ray) in rays.iter().enumerate() {
            let hit = hits.hit(lane);
            if mask >> lane & 1 == 1 {
                assert_eq!((hit.prim, hit.t), (0, 1.0), "lane {lane} of {mask:#b}");
            } else {
                assert_eq!((hit.prim, hit.t), (NO_HIT, ray.t_max), "lane {lane} of {mask:#b}");
            }
        }
        assert_eq!(wide::f32x8::to_bitmask(occluded), mask);
    }
}

#[test]
fn queries_set_ftz_and_daz_on_the_calling_thread() {
    // Threads inherit the mode from the thread that spawns them: build the scene
    // (which flushes) on a helper thread, keeping this one clean.
    let scene = std::thread::scope(|s| s.spawn(|| triangle_scene(&device())).join().unwrap());
    assert!(!denormals_flushed());
    std::thread::scope(|s| {
        s.spawn(|| {
            assert!(!denormals_flushed());
            assert_eq!(scene.intersect(&down(0.0)).prim, 0);
            assert!(denormals_flushed());
        });
    });
}

#[test]
fn a_device_reports_its_config_and_version() {
    let device = Device::new("threads=1,isa=avx2").unwrap();
    assert_eq!(device.config(), "threads=1,isa=avx2");
    assert!(device.version_string().starts_with("4."));
    assert!(matches!(
        Device::new("isa=avx2\0"),
        Err(raypack::embree::EmbreeError::Device { .. })
    ));
}
