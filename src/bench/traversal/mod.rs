//! Traversal throughput: Mrays/s of single-ray, 8- and 16-ray packet traversal
//! of the BVH on the standard ray kinds ([`RayKind`](crate::bench::rays::RayKind):
//! primary, shadow, ambient occlusion, diffuse and random rays), build times
//! and the tree's SAH cost; shared by `raypack bench traversal` and the
//! criterion bench `benches/traversal.rs`.
//! With the `embree` feature, Embree's BVH is timed on the same rays alongside
//! (`rtcIntersect1`/`rtcOccluded1`, `rtcIntersect8`/`rtcOccluded8` and
//! `rtcIntersect16`/`rtcOccluded16`; its build gets the same thread count as
//! raypack's).
//!
//! Rays are made before timing ([`RaySource`](crate::bench::rays::RaySource)),
//! so only traversal is measured.
//! Threads take whole tiles of 256 rays (rayon). Thread counts, scenes,
//! engines, kinds and variants are interleaved round by round, backwards in
//! odd rounds, and every round is kept, so a drift of a shared machine's speed
//! hits every scene alike and nothing is always measured first: each figure is a
//! median with its interval, and the ratios (packets over single rays, one
//! scene's time per ray over the first's, raypack over Embree) are taken
//! round by round ([`Summary::paired_ratio`](crate::statistics::Summary::paired_ratio)).

mod engines;
mod instructions;
mod measure;
mod measured;
mod rows;
mod setup;
mod trace;

pub use engines::{Builder, EngineVariant, engine_variants};
pub use instructions::{count_instructions, instructions_per_ray};
pub use measure::{builds_how, measure};
pub use rows::{BestVsEmbree, KindRow, TraversalRow};
pub use setup::{TraversalSetup, scene_bounds};
pub use trace::{PATHS, TILE_RAYS, path_name, trace_batch, trace_packets, trace_path, trace_single};
