//! raypack against Embree 4 (the `embree` feature), one test crate: hit
//! agreement on every scene, the edge cases behind the disagreements it
//! allows, the hit-record layouts, and the command line's `--engine embree`.
#![cfg(feature = "embree")]

#[path = "../support/mod.rs"]
mod support;

mod agreement;
mod cli;
mod edge_cases;
mod instances;
mod records;
