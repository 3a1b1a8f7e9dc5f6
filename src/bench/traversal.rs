//! Traversal throughput: Mrays/s of single-ray and 8-ray packet traversal of the
//! BVH on primary (coherent) and random (incoherent) rays, and build times;
//! shared by `raypack bench traversal` and the criterion bench `benches/traversal.rs`.
//! With the `embree` feature, Embree's BVH is timed on the same rays alongside
//! (`rtcIntersect1` and `rtcIntersect8`; its build gets the same thread count
//! as raypack's).
//!
//! Rays are made before timing, so only traversal is measured: primary rays
//! through pixel centres in 16×16 tiles of 4×2-pixel packets (the same rays for
//! both variants), random rays from points of the scene's box in uniform
//! directions, packed 8 at a time. Threads take whole tiles (rayon). Scenes and
//! variants are interleaved round by round and the best round is kept, so a
//! drift of a shared machine's speed hits every scene alike and the growth of
//! time per ray from the first scene to the others is read off one run.

use std::hint::black_box;
use std::time::{Duration, Instant};

use rayon::prelude::*;
use wide::f32x8;

use crate::accel::{Accel, AccelWithStats, Bvh, TraversalStats};
use crate::bounds::Aabb;
use crate::camera::Camera;
use crate::engine::Engine;
use crate::geometry::Primitive;
use crate::packet::RayPacket8;
use crate::ray::Ray;
use crate::scene::generate::random::{bumpy_sphere, framing_camera, random_rays, random_spheres};
use crate::simd::SimdFloat;

/// Rays per tile: 16×16 pixels, 32 packets of 4×2.
pub const TILE_RAYS: usize = 256;

/// A scene and the rays it is measured on.
pub struct TraversalSetup {
    /// Name in reports (`mesh-1000`, `dragon`…).
    pub name: String,
    /// The primitives.
    pub prims: Vec<Primitive>,
    /// Primary rays, tile by tile, packet by packet (lane order), pixel centres.
    pub primary: Vec<Ray>,
    /// The same rays in 4×2-pixel packets.
    pub primary_packets: Vec<RayPacket8>,
    /// Random rays.
    pub random: Vec<Ray>,
    /// The same rays, 8 to a packet.
    pub random_packets: Vec<RayPacket8>,
    /// Image size of the primary rays.
    pub resolution: (u32, u32),
}

impl TraversalSetup {
    /// Rays for `prims` seen by `camera` (`width`, `height` multiples of 16 are
    /// best: partial tiles get inactive lanes), plus `random` random rays.
    pub fn new(
        name: impl Into<String>,
        prims: Vec<Primitive>,
        camera: &Camera,
        random: usize,
        seed: u64,
    ) -> Self {
        let (w, h) = (camera.width, camera.height);
        let mut primary = Vec::with_capacity((w * h) as usize);
        let mut primary_packets = Vec::with_capacity((w * h) as usize / 8);
        for ty in (0..h).step_by(16) {
            for tx in (0..w).step_by(16) {
                for py in (ty..(ty + 16).min(h)).step_by(2) {
                    for px in (tx..(tx + 16).min(w)).step_by(4) {
                        let pixels: Vec<(u32, u32)> = (0..8)
                            .map(|k| (px + k % 4, py + k / 4))
                            .filter(|&(i, j)| i < w && j < h)
                            .collect();
                        primary.extend(pixels.iter().map(|&(i, j)| camera.pixel_ray(i, j)));
                        primary_packets.push(camera.pixel_packet::<f32x8>(&pixels));
                    }
                }
            }
        }
        let bounds = scene_bounds(&prims);
        let random = random_rays(bounds, random, seed);
        let random_packets = random.chunks(8).map(RayPacket8::from_rays).collect();
        Self {
            name: name.into(),
            prims,
            primary,
            primary_packets,
            random,
            random_packets,
            resolution: (w, h),
        }
    }

    /// A generated scene of about `n` primitives: `kind` is `mesh` (bumpy-sphere
    /// triangles) or `spheres`; seen by [`framing_camera`].
    pub fn generated(kind: &str, n: usize, width: u32, height: u32, random: usize) -> Option<Self> {
        let prims = match kind {
            "mesh" => bumpy_sphere(n, 1),
            "spheres" => random_spheres(n, 1),
            _ => return None,
        };
        let camera = framing_camera(scene_bounds(&prims), width, height);
        Some(Self::new(format!("{kind}-{n}"), prims, &camera, random, 2))
    }
}

/// The box of the bounded primitives (the unit cube when there are none).
pub fn scene_bounds(prims: &[Primitive]) -> Aabb {
    let b = prims
        .iter()
        .filter_map(Primitive::bounds)
        .fold(Aabb::EMPTY, Aabb::union);
    if b.is_empty() {
        Aabb::new(-glam::Vec3::ONE, glam::Vec3::ONE)
    } else {
        b
    }
}

/// Trace `rays` one by one, tiles spread over the current rayon pool; returns a checksum.
pub fn trace_single(accel: &impl Accel, rays: &[Ray]) -> u64 {
    rays.par_chunks(TILE_RAYS)
        .map(|tile| {
            tile.iter()
                .map(|r| u64::from(accel.intersect(r).prim))
                .sum::<u64>()
        })
        .sum()
}

/// Trace `packets`, tiles spread over the current rayon pool; returns a checksum.
pub fn trace_packets(accel: &impl Accel, packets: &[RayPacket8]) -> u64 {
    packets
        .par_chunks(TILE_RAYS / 8)
        .map(|tile| {
            tile.iter()
                .map(|p| u64::from(accel.intersect_packet(p).hit_mask().bitmask()))
                .sum::<u64>()
        })
        .sum()
}

/// A structure built over a scene whose traversal is timed.
pub enum Structure {
    /// raypack's SAH BVH.
    Raypack(Bvh),
    /// Embree's BVH, default (fast) scene flags.
    #[cfg(feature = "embree")]
    Embree(crate::embree::EmbreeScene),
}

impl Structure {
    /// Trace `rays` one by one ([`trace_single`]).
    fn trace_single(&self, rays: &[Ray]) -> u64 {
        match self {
            Self::Raypack(bvh) => trace_single(bvh, rays),
            #[cfg(feature = "embree")]
            Self::Embree(scene) => trace_single(scene, rays),
        }
    }

    /// Trace `packets` ([`trace_packets`]).
    fn trace_packets(&self, packets: &[RayPacket8]) -> u64 {
        match self {
            Self::Raypack(bvh) => trace_packets(bvh, packets),
            #[cfg(feature = "embree")]
            Self::Embree(scene) => trace_packets(scene, packets),
        }
    }
}

/// Builds each engine's structure with `threads` threads; holds Embree's
/// device when Embree is measured.
pub struct Builder {
    engines: Vec<Engine>,
    threads: usize,
    #[cfg(feature = "embree")]
    device: Option<std::sync::Arc<crate::embree::Device>>,
}

impl Builder {
    /// A builder for `engines` on `threads` threads: Embree's device (on
    /// [`embree_config`](crate::engine::embree_config)`(threads)`, so its
    /// build gets as many threads as raypack's) is made here, so a missing
    /// feature or a failing device is reported before any scene is generated.
    ///
    /// Embree's thread limit is the task scheduler's, shared by every device
    /// of the process: drop one builder before making the next.
    pub fn new(engines: &[Engine], threads: usize) -> anyhow::Result<Self> {
        anyhow::ensure!(!engines.is_empty(), "no engine to measure");
        let mut distinct = Vec::new();
        for &engine in engines {
            if !distinct.contains(&engine) {
                distinct.push(engine);
            }
        }
        let engines = distinct;
        let threads = threads.max(1);
        let embree = engines.contains(&Engine::Embree);
        #[cfg(feature = "embree")]
        {
            let device = if embree {
                let device = crate::embree::Device::new(&crate::engine::embree_config(threads))?;
                Some(std::sync::Arc::new(device))
            } else {
                None
            };
            Ok(Self {
                engines,
                threads,
                device,
            })
        }
        #[cfg(not(feature = "embree"))]
        {
            anyhow::ensure!(!embree, crate::engine::EMBREE_MISSING);
            Ok(Self { engines, threads })
        }
    }

    /// The engines measured, in the order given.
    pub fn engines(&self) -> &[Engine] {
        &self.engines
    }

    /// Threads of the builds, and of the pool that [`measure`] traces on.
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// Build `engine`'s structure over `prims`.
    pub fn build(&self, engine: Engine, prims: &[Primitive]) -> anyhow::Result<Structure> {
        match engine {
            Engine::Raypack => Ok(Structure::Raypack(Bvh::new(prims))),
            #[cfg(feature = "embree")]
            Engine::Embree => {
                let device = self
                    .device
                    .clone()
                    .ok_or_else(|| anyhow::anyhow!("Embree was not among the builder's engines"))?;
                Ok(Structure::Embree(crate::embree::EmbreeScene::new(device, prims)?))
            }
            #[cfg(not(feature = "embree"))]
            Engine::Embree => anyhow::bail!(crate::engine::EMBREE_MISSING),
        }
    }
}

/// One row of the traversal table.
#[derive(Clone, Debug, serde::Serialize)]
pub struct TraversalRow {
    /// Scene name.
    pub scene: String,
    /// Primitives in the scene.
    pub primitives: usize,
    /// Engine whose structure was traversed.
    pub engine: Engine,
    /// Threads of the rayon pool.
    pub threads: usize,
    /// Best build time, seconds.
    pub build_s: f64,
    /// Primary rays: image size.
    pub resolution: (u32, u32),
    /// Primary rays, single-ray traversal, Mrays/s.
    pub primary_single_mrays: f64,
    /// Primary rays, 8-ray packets (4×2 pixels), Mrays/s.
    pub primary_packet_mrays: f64,
    /// Random rays, single-ray traversal, Mrays/s.
    pub random_single_mrays: f64,
    /// Random rays, 8-ray packets, Mrays/s.
    pub random_packet_mrays: f64,
    /// Counts of the primary packet pass (raypack only: Embree does not report them).
    pub primary_packet_stats: Option<TraversalStats>,
    /// Counts of the primary single-ray pass (raypack only).
    pub primary_single_stats: Option<TraversalStats>,
    /// Counts of the random packet pass (raypack only).
    pub random_packet_stats: Option<TraversalStats>,
    /// Time per ray against the same engine on the first scene measured
    /// alongside (1 for itself).
    pub growth_vs_first: Growth,
    /// Timed rounds per variant (best kept).
    pub rounds: usize,
}

/// Per traversal variant, a scene's time per ray divided by the first scene's.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Growth {
    /// Primary rays, single-ray traversal.
    pub primary_single: f64,
    /// Primary rays, 8-ray packets.
    pub primary_packet: f64,
    /// Random rays, single-ray traversal.
    pub random_single: f64,
    /// Random rays, 8-ray packets.
    pub random_packet: f64,
}

/// Best (shortest) wall time of `f` over `rounds` calls.
fn best_time<T>(rounds: usize, mut f: impl FnMut() -> T) -> Duration {
    (0..rounds.max(1))
        .map(|_| {
            let start = Instant::now();
            black_box(f());
            start.elapsed()
        })
        .min()
        .unwrap_or_default()
}

/// A scene and an engine measured on it.
struct Case<'a> {
    setup: &'a TraversalSetup,
    engine: Engine,
    structure: Structure,
    /// Best build time.
    build: Duration,
    /// Best times of primary single, primary packet, random single, random packet.
    best: [Duration; 4],
}

impl Case<'_> {
    /// Seconds per ray of each variant.
    fn per_ray(&self) -> [f64; 4] {
        let (primary, random) = (self.setup.primary.len(), self.setup.random.len());
        let rays = [primary, primary, random, random];
        std::array::from_fn(|k| self.best[k].as_secs_f64() / rays[k].max(1) as f64)
    }
}

/// Measure every engine of `builder` on `setups` on a rayon pool of the
/// builder's threads:
/// each build time (best of 3), then the four traversal variants of every
/// scene and engine, interleaved scene by scene, engine by engine and variant
/// by variant, best of `rounds` after a warm-up round. With Embree among the
/// engines every pool thread sets FTZ/DAZ, so both engines run in that mode.
pub fn measure(
    setups: &[TraversalSetup],
    builder: &Builder,
    rounds: usize,
) -> anyhow::Result<Vec<TraversalRow>> {
    let (engines, threads) = (builder.engines(), builder.threads());
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads);
    #[cfg(feature = "embree")]
    let pool = if engines.contains(&Engine::Embree) {
        pool.start_handler(|_| crate::embree::flush_denormals())
    } else {
        pool
    };
    let pool = pool.build()?;
    pool.install(|| {
        // Build each structure three times, keeping the best time and the last structure.
        let mut cases = Vec::with_capacity(setups.len() * engines.len());
        for setup in setups {
            for &engine in engines {
                let mut build = Duration::MAX;
                let mut structure = None;
                for _ in 0..3 {
                    let start = Instant::now();
                    let built = builder.build(engine, &setup.prims)?;
                    build = build.min(start.elapsed());
                    structure = Some(built);
                }
                let structure = structure.expect("three builds");
                let best = [Duration::MAX; 4];
                cases.push(Case {
                    setup,
                    engine,
                    structure,
                    build,
                    best,
                });
            }
        }
        // Round 0 warms every variant up (caches, page faults) and is not kept.
        for round in 0..=rounds {
            for case in &mut cases {
                let (s, setup) = (&case.structure, case.setup);
                let times = [
                    best_time(1, || s.trace_single(&setup.primary)),
                    best_time(1, || s.trace_packets(&setup.primary_packets)),
                    best_time(1, || s.trace_single(&setup.random)),
                    best_time(1, || s.trace_packets(&setup.random_packets)),
                ];
                if round > 0 {
                    for (b, t) in case.best.iter_mut().zip(times) {
                        *b = (*b).min(t);
                    }
                }
            }
        }
        Ok(cases
            .iter()
            .map(|case| {
                let first = cases
                    .iter()
                    .find(|c| c.engine == case.engine)
                    .expect("the case itself")
                    .per_ray();
                let own = case.per_ray();
                let growth = |k: usize| own[k] / first[k];
                let growth = Growth {
                    primary_single: growth(0),
                    primary_packet: growth(1),
                    random_single: growth(2),
                    random_packet: growth(3),
                };
                row(case, threads, rounds, growth)
            })
            .collect())
    })
}

/// The table row of `case`: its best times as Mrays/s, and for raypack the
/// traversal counts of one more (untimed) pass of each kind.
fn row(case: &Case<'_>, threads: usize, rounds: usize, growth_vs_first: Growth) -> TraversalRow {
    let setup = case.setup;
    let mrays = |n: usize, t: Duration| n as f64 / t.as_secs_f64() / 1e6;
    let stats = match &case.structure {
        Structure::Raypack(bvh) => {
            let mut stats = [TraversalStats::default(); 3];
            for p in &setup.primary_packets {
                bvh.intersect_packet_with_stats(p, &mut stats[0]);
            }
            for r in &setup.primary {
                bvh.intersect_with_stats(r, &mut stats[1]);
            }
            for p in &setup.random_packets {
                bvh.intersect_packet_with_stats(p, &mut stats[2]);
            }
            stats.map(Some)
        }
        #[cfg(feature = "embree")]
        Structure::Embree(_) => [None; 3],
    };
    TraversalRow {
        scene: setup.name.clone(),
        primitives: setup.prims.len(),
        engine: case.engine,
        threads,
        build_s: case.build.as_secs_f64(),
        resolution: setup.resolution,
        primary_single_mrays: mrays(setup.primary.len(), case.best[0]),
        primary_packet_mrays: mrays(setup.primary.len(), case.best[1]),
        random_single_mrays: mrays(setup.random.len(), case.best[2]),
        random_packet_mrays: mrays(setup.random.len(), case.best[3]),
        primary_packet_stats: stats[0],
        primary_single_stats: stats[1],
        random_packet_stats: stats[2],
        growth_vs_first,
        rounds,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn primary_packets_hold_the_primary_rays_in_order() {
        let s = TraversalSetup::generated("mesh", 500, 40, 20, 100).expect("known kind");
        assert_eq!(s.primary.len(), 800);
        assert_eq!(s.random_packets.len(), 13);
        let mut k = 0;
        for p in &s.primary_packets {
            for lane in 0..8 {
                if p.is_active(lane) {
                    assert_eq!(p.ray(lane), s.primary[k]);
                    k += 1;
                }
            }
        }
        assert_eq!(k, s.primary.len());
        let bvh = Bvh::new(&s.prims);
        let brute = crate::accel::BruteForce::new(&s.prims);
        assert_eq!(trace_single(&bvh, &s.primary), trace_single(&brute, &s.primary));
        assert_eq!(
            trace_packets(&bvh, &s.primary_packets),
            trace_packets(&brute, &s.primary_packets)
        );
    }
}
