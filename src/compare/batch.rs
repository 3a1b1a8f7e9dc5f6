//! Tracing a batch of rays through any [`Accel`], scalar or in 8-wide packets,
//! on rayon's threads.

use rayon::prelude::*;

use crate::accel::Accel;
use crate::engines::WithAccel;
use crate::packet::RayPacket;
use crate::ray::{Hit, Ray};
use crate::simd::SimdFloat;

/// Rays handed to one rayon task: enough to amortise scheduling. Every chunk
/// is a task of its own (`with_max_len(1)`), as the renderer's tiles and the
/// benchmarks' are: left to rayon's adaptive split, a few hundred chunks went
/// in about four runs on two threads, and the thread done first waited for
/// the other's last run.
const CHUNK: usize = 256;

/// How rays go through the accel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Kernel {
    /// One ray at a time (`Accel::intersect`).
    Scalar,
    /// Eight consecutive rays per packet (`Accel::intersect_packet`).
    Packet8,
    /// Sixteen consecutive rays per packet.
    Packet16,
}

impl Kernel {
    /// Rays traced together: 1 for single rays, else the packet width.
    pub fn lanes(self) -> usize {
        match self {
            Kernel::Scalar => 1,
            Kernel::Packet8 => 8,
            Kernel::Packet16 => 16,
        }
    }

    /// The name on the command line and in results.
    pub fn name(self) -> &'static str {
        match self {
            Kernel::Scalar => "scalar",
            Kernel::Packet8 => "packet8",
            Kernel::Packet16 => "packet16",
        }
    }
}

/// [`trace_rays`] as a job for any engine of the registry ([`Built::visit`](crate::engines::Built::visit)).
pub struct NearestHits<'r> {
    /// The rays.
    pub rays: &'r [Ray],
    /// How they go through the engine.
    pub kernel: Kernel,
}

impl WithAccel<'_> for NearestHits<'_> {
    type Output = Vec<Hit>;

    fn run<A: Accel>(self, accel: &A) -> Vec<Hit> {
        trace_rays(accel, self.rays, self.kernel)
    }
}

/// The nearest hit of every ray, in order.
pub fn trace_rays<A: Accel>(accel: &A, rays: &[Ray], kernel: Kernel) -> Vec<Hit> {
    let mut hits: Vec<Hit> = rays.iter().map(Hit::none).collect();
    hits.par_chunks_mut(CHUNK)
        .zip(rays.par_chunks(CHUNK))
        .with_max_len(1)
        .for_each(|(hits, rays)| match kernel {
            Kernel::Scalar => {
                for (hit, ray) in hits.iter_mut().zip(rays) {
                    *hit = accel.intersect(ray);
                }
            }
            Kernel::Packet8 => trace_packets::<_, wide::f32x8>(accel, rays, hits),
            Kernel::Packet16 => trace_packets::<_, wide::f32x16>(accel, rays, hits),
        });
    hits
}

/// `rays` in packets of `F::LANES` consecutive rays (the last one partial).
fn trace_packets<A: Accel, F: SimdFloat>(accel: &A, rays: &[Ray], hits: &mut [Hit]) {
    for (hits, rays) in hits.chunks_mut(F::LANES).zip(rays.chunks(F::LANES)) {
        let packet = accel.intersect_packet(&RayPacket::<F>::from_rays(rays));
        for (i, hit) in hits.iter_mut().enumerate() {
            *hit = packet.hit(i);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::BruteForce;
    use crate::compare::random_rays;
    use crate::geometry::{Primitive, Sphere};
    use glam::Vec3;

    #[test]
    fn scalar_and_packet_batches_give_each_ray_its_own_hit() {
        let prims: Vec<Primitive> = (0..5)
            .map(|i| Primitive::Sphere(Sphere::new(Vec3::new(i as f32, 0.0, 0.0), 0.4)))
            .collect();
        let accel = BruteForce::new(&prims);
        // 1003 rays: the last packet is partial.
        let rays = random_rays(
            crate::bounds::Aabb::new(Vec3::splat(-1.0), Vec3::new(5.0, 1.0, 1.0)),
            1003,
            9,
        );
        let scalar = trace_rays(&accel, &rays, Kernel::Scalar);
        assert_eq!(scalar.len(), rays.len());
        for kernel in [Kernel::Packet8, Kernel::Packet16] {
            let packet = trace_rays(&accel, &rays, kernel);
            for (i, ray) in rays.iter().enumerate() {
                assert_eq!(scalar[i], accel.intersect(ray));
                assert_eq!(
                    (packet[i].t, packet[i].prim),
                    (scalar[i].t, scalar[i].prim),
                    "{kernel:?} ray {i}"
                );
            }
        }
        assert!(scalar.iter().any(Hit::is_hit) && scalar.iter().any(|h| !h.is_hit()));
    }
}
