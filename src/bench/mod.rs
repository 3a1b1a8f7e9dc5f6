//! Measurement code shared by the `raypack bench` command and the criterion
//! benches, and the results they produce: figures with their intervals, the
//! JSON result, and baselines to compare runs against.

pub mod baseline;
pub mod callgrind;
pub mod change;
pub mod figure;
pub mod kernels;
pub mod matrix;
pub mod pinned_pool;
pub mod rays;
pub mod result;
pub mod scene;
pub mod timing_hooks;
pub mod traversal;
