//! The unit of work of a trace kernel: a batch of rays (one pixel block, one
//! 16-wide packet or two 8-wide ones) with a lane mask. Counting and kernels both speak of batch
//! lanes, so the batch is defined below both.

use crate::ray::{Hit, Ray};

/// Rays per batch: one 4×4 or 8×2 pixel block, the widest packet.
pub const BATCH: usize = 16;

/// A batch of rays; lane `i` takes part where bit `i` of the mask is set.
pub type Rays = [Ray; BATCH];

/// A batch's hit records, lane by lane.
pub type Hits = [Hit; BATCH];

/// The lane mask with every lane of a batch set.
pub const ALL_LANES: u32 = (1 << BATCH) - 1;
