//! Measurement code shared by the `raypack bench` command and the criterion
//! benches, and what their results are made of: figures with their intervals,
//! changes against a baseline, and the timing test hook.

pub mod change;
pub mod figure;
pub mod kernels;
pub mod rays;
pub mod scene;
pub mod slowdown;
pub mod traversal;
