//! Rendering, one test crate: scalar and packet renders agree, the optics and
//! Whitted's rules, the SPD ray counts, the report around a render and the
//! traversal statistics it counts.

#[path = "../support/mod.rs"]
mod support;

mod identity;
mod instances;
mod optics;
mod report;
mod spd;
mod spd_files;
mod traversal;
mod whitted;
