//! The intersection kernels, one test crate: every packet kernel and block
//! kernel against its scalar twin lane by lane on random rays, and hand-made
//! edge cases.

#[path = "../support/mod.rs"]
mod support;

mod agreement;
mod cone;
mod edge_cases;
mod sphere_block;
mod sphere_inside_only;
mod triangle_block;
