//! Embree 4 side by side with raypack (the `embree` feature).
//!
//! [`EmbreeScene`] puts a scene's primitives into Embree ([`translate`] says
//! how) and answers raypack's [`Accel`](crate::accel::Accel) queries with
//! `rtcIntersect1/4/8/16` and `rtcOccluded1/4/8/16`, so the same code can trace
//! through raypack or Embree: `raypack check` compares the two hit by hit, and
//! `benches/embree.rs` compares their throughput.
//!
//! - [`device`]: the device, its configuration string ([`DEFAULT_CONFIG`]:
//!   AVX2 kernels, one build thread) and its error log;
//! - [`denormals`]: FTZ/DAZ, which Embree wants set on every tracing thread;
//! - [`ray_hit`]: ray-hit records padded for the hit layout of Embree ≥ 4.3
//!   (the crate's bindings are generated from the 4.2 headers);
//! - `layout_probe`: which of those layouts the loaded library writes
//!   ([`Device::writes_inst_prim_id`]);
//! - [`translate`] and [`user_geometry`]: raypack primitives as Embree geometry;
//! - `raw_scene`: an owned `RTCScene` and the geometries attached to it;
//! - [`scene`] holds [`EmbreeScene`], raypack's primitives built into one;
//! - `trace`: [`EmbreeScene`]'s answers to the [`Accel`](crate::accel::Accel)
//!   queries (single rays, 4/8/16-wide packets, the coherent flag).
//!
//! The library is found at build time by `build.rs`, after
//! `scripts/install-embree.sh` has installed it.

#[cfg(not(target_arch = "x86_64"))]
compile_error!("the `embree` feature supports x86_64 only (FTZ/DAZ are set through MXCSR)");

pub mod denormals;
pub mod device;
mod layout_probe;
mod raw_scene;
pub mod ray_hit;
pub mod scene;
mod trace;
pub mod translate;
pub mod user_geometry;

pub use denormals::flush_denormals;
pub use device::{DEFAULT_CONFIG, Device};
pub use scene::EmbreeScene;

/// What went wrong on the Embree side.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EmbreeError {
    /// `rtcNewDevice` refused the configuration (or the CPU).
    #[error("cannot create an Embree device with config \"{config}\": {message}")]
    Device {
        /// The configuration string.
        config: String,
        /// Embree's error.
        message: String,
    },
    /// An Embree call reported an error.
    #[error("Embree failed while {step}: {message}")]
    Api {
        /// What raypack was doing.
        step: &'static str,
        /// Embree's messages.
        message: String,
    },
    /// The loaded library writes hit records in a layout raypack does not know.
    #[error("unsupported Embree hit-record layout: {0}")]
    Layout(String),
}
