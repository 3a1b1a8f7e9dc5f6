//! Acceleration structures, one test crate: the BVH against the lecture's
//! brute-force loop on random, degenerate and hostile scenes, and the
//! traversal statistics.

#[path = "../support/mod.rs"]
mod support;

mod agrees_with_brute_force;
mod brute_force;
mod degenerate;
mod hostile_values;
mod instances;
mod isa;
mod stats;
