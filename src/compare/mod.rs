//! Comparing engines ray by ray: the rays ([`ray_sets`]), tracing them through
//! any [`Accel`](crate::accel::Accel) ([`batch`]), the CSV exchange format that
//! lets any other engine take part ([`csv`]), the agreement statistics of
//! two engines' hits, ray by ray classified ([`agreement`]), and the picture of
//! where they disagree ([`diff_image`]); the robustness oracle of rays with
//! known answers ([`robustness`], against the double-precision
//! [`reference_f64`]), its JSON result ([`robustness_result`]) and the picture
//! of where a mesh leaks ([`crack_image`]).

pub mod agreement;
pub mod batch;
pub mod crack_image;
pub mod csv;
pub mod diff_image;
pub mod ray_sets;
pub mod reference_f64;
pub mod robustness;
pub mod robustness_result;

pub use agreement::{
    Agreement, AgreementOptions, Disagreement, DisagreementKind, PrimitiveIds, RayClass, classify,
    classify_rays,
};
pub use batch::{Kernel, NearestHits, trace_rays};
pub use ray_sets::{CheckRays, primary_rays, primary_rays_in_blocks, random_rays};
