//! The choice of acceleration structure (`--accel none|bvh`) and a value holding
//! either, so commands build whichever the user asked for and trace through one type.

use std::fmt;

use crate::accel::stats::Counter;
use crate::accel::{Accel, BruteForce, Bvh};
use crate::geometry::Primitive;
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, Ray};
use crate::simd::SimdFloat;

/// Which acceleration structure to trace with.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum AccelKind {
    /// No acceleration: every ray against every primitive (the reference).
    None,
    /// The SAH bounding volume hierarchy.
    #[default]
    Bvh,
}

impl AccelKind {
    /// The name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            AccelKind::None => "none",
            AccelKind::Bvh => "bvh",
        }
    }

    /// Build this structure over `prims` (a hit's index is the position in `prims`).
    pub fn build(self, prims: &[Primitive]) -> AnyAccel<'_> {
        match self {
            AccelKind::None => AnyAccel::None(BruteForce::new(prims)),
            AccelKind::Bvh => AnyAccel::Bvh(Box::new(Bvh::new(prims))),
        }
    }
}

impl fmt::Display for AccelKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Either acceleration structure, built by [`AccelKind::build`].
#[derive(Clone, Debug)]
pub enum AnyAccel<'a> {
    /// Brute force over the scene's primitives.
    None(BruteForce<'a>),
    /// A BVH (boxed: its buffer headers take 232 bytes, brute force's slice 16).
    Bvh(Box<Bvh>),
}

impl AnyAccel<'_> {
    /// Which kind this is.
    pub fn kind(&self) -> AccelKind {
        match self {
            AnyAccel::None(_) => AccelKind::None,
            AnyAccel::Bvh(_) => AccelKind::Bvh,
        }
    }
}

/// Forward a query to whichever structure is inside.
macro_rules! forward {
    ($self:expr, $a:ident => $body:expr) => {
        match $self {
            AnyAccel::None($a) => $body,
            AnyAccel::Bvh($a) => $body,
        }
    };
}

impl Accel for AnyAccel<'_> {
    fn intersect_counted<S: Counter>(&self, ray: &Ray, stats: &mut S) -> Hit {
        forward!(self, a => a.intersect_counted(ray, stats))
    }

    fn intersect_packet_counted<F: SimdFloat, S: Counter>(
        &self,
        rays: &RayPacket<F>,
        stats: &mut S,
    ) -> HitPacket<F> {
        forward!(self, a => a.intersect_packet_counted(rays, stats))
    }

    fn occluded_counted<S: Counter>(&self, ray: &Ray, stats: &mut S) -> bool {
        forward!(self, a => a.occluded_counted(ray, stats))
    }

    fn occluded_packet_counted<F: SimdFloat, S: Counter>(&self, rays: &RayPacket<F>, stats: &mut S) -> F {
        forward!(self, a => a.occluded_packet_counted(rays, stats))
    }

    fn intersect_rays_counted<F: SimdFloat, S: Counter>(
        &self,
        rays: &[Ray],
        mask: u32,
        stats: &mut S,
    ) -> HitPacket<F> {
        forward!(self, a => a.intersect_rays_counted(rays, mask, stats))
    }

    fn occluded_rays_counted<F: SimdFloat, S: Counter>(&self, rays: &[Ray], mask: u32, stats: &mut S) -> F {
        forward!(self, a => a.occluded_rays_counted(rays, mask, stats))
    }

    fn intersect_each_counted<S: Counter>(&self, rays: &[Ray], active: u32, hits: &mut [Hit], stats: &mut S) {
        forward!(self, a => a.intersect_each_counted(rays, active, hits, stats))
    }

    fn occluded_each_counted<S: Counter>(&self, rays: &[Ray], active: u32, stats: &mut S) -> u32 {
        forward!(self, a => a.occluded_each_counted(rays, active, stats))
    }
}
