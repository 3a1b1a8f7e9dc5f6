//! What the integration test crates share, one module per concern. Each test
//! crate compiles its own copy and uses only some of it.
#![allow(dead_code)]

pub mod bvh;
pub mod cli;
pub mod kernel;
pub mod render;
pub mod scratch;
