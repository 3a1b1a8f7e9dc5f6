//! Ray statistics the way the Standard Procedural Databases count them
//! (E. Haines, IEEE CG&A 7(11), 1987; the rules in `docs/nff.md`):
//! a 512×512 image with eye rays through the pixel *corners* (513×513 rays),
//! Whitted tracing to depth 5 (the eye ray is depth 1), a reflection ray at
//! every hit on Ks > 0 or T > 0, a refraction ray at every hit on T > 0 (only
//! the reflection on total internal reflection, which the published table still
//! counts as a refraction ray: [`RayCounts::spd_refract_rays`]), no shadow ray where the normal
//! faces away from the light, no adaptive depth cut-off. The published counts
//! and the comparison with them are in [`crate::render::spd_published`].
//!
//! The counts are the engine's external correctness oracle: for SPD-generated
//! files they should lie within 10% of the published figures, and they are the
//! same for the scalar and the packet kernels.

use crate::accel::{Accel, TraversalStats};
use crate::camera::{Camera, CameraError};
use crate::render::counting::Counting;
use crate::render::{Block, KernelKind, Mode, RayCounts, RenderSettings, Sampling, render, render_counted};
use crate::scene::Scene;

/// Image edge of the SPD's test procedure.
pub const SPD_SIZE: u32 = 512;
/// Maximum tree depth of the SPD's test procedure.
pub const SPD_DEPTH: u32 = 5;

/// The render settings of the SPD's test procedure with the given kernel.
pub fn spd_settings(kernel: KernelKind) -> RenderSettings {
    RenderSettings {
        mode: Mode::Whitted,
        kernel,
        block: Block::B4x4,
        tile_size: 16,
        max_depth: SPD_DEPTH,
        sampling: Sampling::PixelCorners,
    }
}

/// Trace `scene` the SPD way and count its rays. The scene's own camera is
/// used (its view, not its resolution); a scene without one gets
/// [`Scene::default_camera`].
pub fn spd_counts<A: Accel>(
    scene: &Scene,
    accel: &A,
    kernel: KernelKind,
    pool: &rayon::ThreadPool,
) -> Result<RayCounts, CameraError> {
    let camera = spd_camera(scene)?;
    Ok(render(scene, accel, &camera, &spd_settings(kernel), pool, &|| {}).counts)
}

/// [`spd_counts`], and the traversal work of all those rays where the
/// structure reports it ([`Accel::COUNTS_WORK`]).
///
/// [`Accel::COUNTS_WORK`]: crate::accel::Accel::COUNTS_WORK
pub fn spd_counts_with_traversal<A: Accel>(
    scene: &Scene,
    accel: &A,
    kernel: KernelKind,
    pool: &rayon::ThreadPool,
) -> Result<(RayCounts, Option<TraversalStats>), CameraError> {
    let camera = spd_camera(scene)?;
    let settings = spd_settings(kernel);
    let r = render_counted(scene, accel, &camera, &settings, Counting::Totals, pool, &|| {});
    Ok((r.counts, r.traversal.map(|t| t.total)))
}

/// The scene's camera (or the default one) at the SPD's resolution.
fn spd_camera(scene: &Scene) -> Result<Camera, CameraError> {
    let spec = scene.camera.unwrap_or_else(|| scene.default_camera());
    spec.camera_at(SPD_SIZE, SPD_SIZE)
}
