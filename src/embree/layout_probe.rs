//! Which hit-record layout the loaded library writes, probed with one ray:
//! whether Embree ≥ 4.3 writes `instPrimID` after `instID` (see
//! [`ray_hit`](crate::embree::ray_hit)). The probe traces a scene, so it lives
//! here, above [`RawScene`], rather than in `device.rs`, below scenes.

use glam::Vec3;

use embree4_sys as sys;

use crate::embree::EmbreeError;
use crate::embree::device::Device;
use crate::embree::raw_scene::RawScene;
use crate::embree::ray_hit::{INVALID_ID, RayHit1, intersect_arguments};
use crate::ray::Ray;

impl Device {
    /// Whether the library writes `instPrimID` after `instID` in every hit
    /// record (Embree ≥ 4.3 built with instance arrays), probed once per device with one ray at a one-triangle
    /// scene; fails if it writes past the padded record (a layout raypack does
    /// not know). Every [`EmbreeScene`](crate::embree::EmbreeScene) asks before
    /// it is traced.
    pub fn writes_inst_prim_id(&self) -> Result<bool, EmbreeError> {
        if let Some(&known) = self.inst_prim_id.get() {
            return Ok(known);
        }
        let probed = probe_inst_prim_id(self)?;
        Ok(*self.inst_prim_id.get_or_init(|| probed))
    }
}

/// A value Embree never writes, to see which words it does write.
const SENTINEL: u32 = 0x5EED_F00D;

/// A [`RayHit1`] followed by guard words that Embree must leave alone.
#[repr(C)]
struct Guarded {
    record: RayHit1,
    guard: [u32; 8],
}

/// Trace one ray at a one-triangle scene and report whether the library writes
/// `instPrimID` into the padding, failing if it writes past the padded record
/// (a layout this module does not know, e.g. more than one instance level).
fn probe_inst_prim_id(device: &Device) -> Result<bool, EmbreeError> {
    let vertices = [
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ];
    let scene = RawScene::new(device)?;
    scene.attach_triangles(device, &[vertices], 0)?;
    scene.commit(device, "committing the layout probe scene")?;
    let ray = Ray::unbounded(Vec3::new(0.0, 0.0, 1.0), Vec3::NEG_Z);
    let mut probe = Guarded {
        record: RayHit1::new(&ray),
        guard: [SENTINEL; 8],
    };
    probe.record.inst_prim_id = SENTINEL;
    let mut args = intersect_arguments();
    // SAFETY: a committed scene and a padded, aligned record with guard words after it.
    unsafe { sys::rtcIntersect1(scene.raw(), &mut probe.record.inner, &mut args) };
    device.check("tracing the layout probe ray")?;
    if probe.guard != [SENTINEL; 8] {
        return Err(EmbreeError::Layout(
            "Embree wrote past the padded RTCRayHit (more than one instance level?)".into(),
        ));
    }
    if probe.record.inner.hit.geomID != 0 || (probe.record.inner.ray.tfar - 1.0).abs() > 1e-5 {
        return Err(EmbreeError::Layout(format!(
            "the probe ray should hit geometry 0 at t = 1, got geometry {} at t = {}",
            probe.record.inner.hit.geomID, probe.record.inner.ray.tfar
        )));
    }
    match probe.record.inst_prim_id {
        SENTINEL => Ok(false),
        INVALID_ID => Ok(true),
        other => Err(EmbreeError::Layout(format!(
            "unexpected value {other:#x} after instID in the hit record"
        ))),
    }
}
