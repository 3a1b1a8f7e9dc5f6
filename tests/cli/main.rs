//! The command line, one test crate: `render`, `stats`, `info`, `env`, `trace`,
//! `robustness`, `report` and the `bench` subcommands (with their baselines;
//! `bench matrix` with Embree),
//! run as a user runs them (the built binary), bad input included.

#[path = "../support/mod.rs"]
mod support;

mod bench_baseline;
mod bench_matrix;
mod bench_scene;
mod bench_traversal;
mod closed_stdout;
mod engines;
mod info;
mod inlining;
mod instances;
mod render;
mod report;
mod robustness;
mod trace;
