//! The intersection kernels, one test crate: every packet kernel and block
//! kernel against its scalar twin lane by lane on random rays, and hand-made
//! edge cases.

#[path = "../support/mod.rs"]
mod support;

mod agreement;
mod cone;
mod edge_cases;
mod isa;
mod sphere_block;
mod sphere_inside_only;
mod triangle_block;
mod triangle_watertight;

/// A concave L in its plane's (x, y): the 2×2 square with the upper-right
/// quarter cut out, counter-clockwise.
pub const L_SHAPE: [(f32, f32); 6] = [
    (0.0, 0.0),
    (2.0, 0.0),
    (2.0, 1.0),
    (1.0, 1.0),
    (1.0, 2.0),
    (0.0, 2.0),
];
