//! raypack: a CPU ray-tracing engine built to be measured.
//!
//! Rays travel in 8-wide structure-of-arrays packets ([`packet::RayPacket8`])
//! through SIMD kernels, and every packet kernel has a scalar twin in the same
//! file that it is tested against lane by lane. The mathematics follows the
//! lecture in `docs/lecture.md`: the camera ([`camera`]), planes,
//! triangles, polygons, spheres and transformed objects ([`geometry`]).

// Every public item says what it is (docs are part of the API).
#![warn(missing_docs)]

pub mod accel;
pub mod atomic_file;
pub mod bench;
pub mod bounds;
pub mod camera;
pub mod cli;
pub mod compare;
#[cfg(feature = "embree")]
pub mod embree;
pub mod embree_settings;
pub mod engines;
pub mod environment;
pub mod geometry;
pub mod huge_pages;
pub mod packet;
pub mod picture;
pub mod plural;
pub mod ray;
pub mod render;
pub mod report;
pub mod rng;
pub mod scene;
pub mod simd;
pub mod statistics;
