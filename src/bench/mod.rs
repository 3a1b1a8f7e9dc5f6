//! Measurement code shared by the `raypack bench` command and the criterion benches.

pub mod kernels;
pub mod rays;
pub mod scene;
pub mod traversal;
