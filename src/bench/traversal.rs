//! Traversal throughput: Mrays/s of single-ray and 8-ray packet traversal of the
//! BVH on the standard ray kinds ([`RayKind`]: primary, shadow, ambient
//! occlusion, diffuse and random rays), build times and the tree's SAH cost;
//! shared by `raypack bench traversal` and the criterion bench `benches/traversal.rs`.
//! With the `embree` feature, Embree's BVH is timed on the same rays alongside
//! (`rtcIntersect1`/`rtcOccluded1` and `rtcIntersect8`/`rtcOccluded8`; its
//! build gets the same thread count as raypack's).
//!
//! Rays are made before timing ([`RaySource`]), so only traversal is measured.
//! Threads take whole tiles of 256 rays (rayon). Thread counts, scenes,
//! engines, kinds and variants are interleaved round by round, backwards in
//! odd rounds, and every round is kept, so a drift of a shared machine's speed
//! hits every scene alike and nothing is always measured first: each figure is a
//! median with its interval, and the ratios (packets over single rays, one
//! scene's time per ray over the first's, raypack over Embree) are taken
//! round by round ([`Summary::paired_ratio`]).

use std::hint::black_box;
use std::time::Instant;

use glam::Vec3;
use rayon::prelude::*;

use crate::accel::stats::NoStats;
use crate::accel::{Accel, Bvh, TraversalStats};
use crate::bench::figure::{Better, Figure};
use crate::bench::rays::{Query, RayKind, RaySet, RaySource, default_light};
use crate::bench::timing_hooks::TimingHooks;
use crate::bounds::Aabb;
use crate::camera::Camera;
use crate::engine::{EmbreeIsa, Engine};
use crate::geometry::Primitive;
use crate::packet::RayPacket;
use crate::ray::{Hit, Ray};
use crate::render::batch::BATCH;
use crate::scene::generate::random::{bumpy_sphere, framing_camera, random_spheres};
use crate::simd::SimdFloat;
use crate::statistics::Summary;

/// Rays per tile: 16×16 pixels, 32 packets of 4×2 or 16 of 4×4.
pub const TILE_RAYS: usize = 256;

/// A scene and the rays it is measured on.
pub struct TraversalSetup {
    /// Name in reports (`mesh-1000`, `dragon`…).
    pub name: String,
    /// The primitives.
    pub prims: Vec<Primitive>,
    /// The rays of each kind measured, in the order asked.
    pub sets: Vec<RaySet>,
    /// Image size of the primary rays.
    pub resolution: (u32, u32),
}

impl TraversalSetup {
    /// The rays of `kinds` for `prims` seen by `camera` (`width`, `height`
    /// multiples of 16 are best: partial tiles get inactive lanes), shadow rays
    /// going to `light` (or [`default_light`]), plus `random` random rays.
    pub fn new(
        name: impl Into<String>,
        prims: Vec<Primitive>,
        camera: &Camera,
        light: Option<Vec3>,
        random: usize,
        kinds: &[RayKind],
    ) -> Self {
        let bounds = scene_bounds(&prims);
        let sets = RaySource {
            prims: &prims,
            bounds,
            camera,
            light: light.unwrap_or_else(|| default_light(bounds)),
            random,
            seed: 2,
        }
        .make(kinds);
        Self {
            name: name.into(),
            prims,
            sets,
            resolution: (camera.width, camera.height),
        }
    }

    /// A generated scene of about `n` primitives: `kind` is `mesh` (bumpy-sphere
    /// triangles) or `spheres`; seen by [`framing_camera`].
    pub fn generated(
        kind: &str,
        n: usize,
        (width, height): (u32, u32),
        random: usize,
        kinds: &[RayKind],
    ) -> Option<Self> {
        let prims = match kind {
            "mesh" => bumpy_sphere(n, 1),
            "spheres" => random_spheres(n, 1),
            _ => return None,
        };
        let camera = framing_camera(scene_bounds(&prims), width, height);
        Some(Self::new(
            format!("{kind}-{n}"),
            prims,
            &camera,
            None,
            random,
            kinds,
        ))
    }

    /// The rays of `kind`, if measured.
    pub fn set(&self, kind: RayKind) -> Option<&RaySet> {
        self.sets.iter().find(|s| s.kind == kind)
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

/// Trace the rays of `set` one by one with its kind's query, tiles spread over
/// the current rayon pool; returns how many hit. The rays go in batches of
/// [`BATCH`], as the renderer's scalar kernel hands them over: a BVH enters its
/// instruction set's code once per batch, not once per ray
/// ([`Accel::intersect_each_counted`]); an outside engine still takes them one
/// call per ray (`rtcIntersect1`).
pub fn trace_single(accel: &impl Accel, set: &RaySet) -> u64 {
    let query = set.kind.query();
    set.rays
        .par_chunks(TILE_RAYS)
        .map(|tile| {
            tile.chunks(BATCH)
                .map(|rays| trace_batch(accel, rays, query))
                .sum::<u64>()
        })
        .sum()
}

/// Trace one batch of up to [`BATCH`] single rays (at least one) with
/// `query`, in one call of `accel`; returns how many hit.
#[inline]
pub fn trace_batch(accel: &impl Accel, rays: &[Ray], query: Query) -> u64 {
    let all = u32::MAX >> (32 - rays.len());
    match query {
        Query::Nearest => {
            // Every record is overwritten: the first ray's will do.
            let mut hits = [Hit::none(&rays[0]); BATCH];
            accel.intersect_each_counted(rays, all, &mut hits, &mut NoStats);
            hits[..rays.len()].iter().filter(|h| h.is_hit()).count() as u64
        }
        Query::AnyHit => u64::from(accel.occluded_each_counted(rays, all, &mut NoStats).count_ones()),
    }
}

/// Trace the 8-ray packets of `set` with its kind's query, tiles spread over
/// the current rayon pool; returns how many rays hit.
pub fn trace_packets(accel: &impl Accel, set: &RaySet) -> u64 {
    trace_packed(accel, &set.packets, set.kind.query())
}

/// [`trace_packets`] with the 16-ray packets of `set`.
pub fn trace_packets16(accel: &impl Accel, set: &RaySet) -> u64 {
    trace_packed(accel, &set.packets16, set.kind.query())
}

/// Trace `packets` with `query`, tiles spread over the current rayon pool;
/// returns how many rays hit.
fn trace_packed<F: SimdFloat>(accel: &impl Accel, packets: &[RayPacket<F>], query: Query) -> u64 {
    packets
        .par_chunks(TILE_RAYS / F::LANES)
        .map(|tile| {
            tile.iter()
                .map(|p| {
                    let hit = match query {
                        Query::Nearest => accel.intersect_packet(p).hit_mask(),
                        Query::AnyHit => accel.occluded_packet(p),
                    };
                    u64::from(hit.bitmask().count_ones())
                })
                .sum::<u64>()
        })
        .sum()
}

/// An engine as measured: Embree with the kernels of one ISA setting.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EngineVariant {
    /// The engine.
    pub engine: Engine,
    /// Embree's ISA setting (None for raypack).
    pub embree_isa: Option<EmbreeIsa>,
}

impl EngineVariant {
    /// `raypack`, `embree(avx2)`, `embree(default)`.
    pub fn name(self) -> String {
        match (self.engine, self.embree_isa) {
            (Engine::Raypack, _) => "raypack".into(),
            (Engine::Embree, Some(isa)) => format!("embree({})", isa.name()),
            (Engine::Embree, None) => "embree".into(),
        }
    }
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
    /// Trace `set`'s rays one by one ([`trace_single`]) or in packets ([`trace_packets`]).
    fn trace(&self, set: &RaySet, packets: bool) -> u64 {
        match (self, packets) {
            (Self::Raypack(bvh), false) => trace_single(bvh, set),
            (Self::Raypack(bvh), true) => trace_packets(bvh, set),
            #[cfg(feature = "embree")]
            (Self::Embree(scene), false) => trace_single(scene, set),
            #[cfg(feature = "embree")]
            (Self::Embree(scene), true) => trace_packets(scene, set),
        }
    }
}

/// `engines` as measured, in the order given, Embree once per setting of
/// `embree_isas`.
fn engine_variants(engines: &[Engine], embree_isas: &[EmbreeIsa]) -> anyhow::Result<Vec<EngineVariant>> {
    anyhow::ensure!(!engines.is_empty(), "no engine to measure");
    let mut variants: Vec<EngineVariant> = Vec::new();
    for &engine in engines {
        let isas = match engine {
            Engine::Raypack => vec![None],
            Engine::Embree => embree_isas.iter().copied().map(Some).collect(),
        };
        for embree_isa in isas {
            let variant = EngineVariant { engine, embree_isa };
            if !variants.contains(&variant) {
                variants.push(variant);
            }
        }
    }
    anyhow::ensure!(!variants.is_empty(), "no Embree ISA setting to measure");
    Ok(variants)
}

/// Builds each engine's structure with `threads` threads; holds Embree's
/// devices (one per ISA setting) when Embree is measured.
pub struct Builder {
    #[cfg(feature = "embree")]
    devices: Vec<(EmbreeIsa, std::sync::Arc<crate::embree::Device>)>,
}

impl Builder {
    /// A builder for `engines` on `threads` threads, Embree at each setting of
    /// `embree_isas`: Embree's devices (on [`EmbreeIsa::config`]`(threads)`,
    /// so its build gets as many threads as raypack's) are made here, so a
    /// missing feature or a failing device is reported before any scene is
    /// generated.
    ///
    /// Embree's thread limit is the task scheduler's, shared by every device
    /// of the process: drop one builder before making the next.
    pub fn new(engines: &[Engine], embree_isas: &[EmbreeIsa], threads: usize) -> anyhow::Result<Self> {
        let variants = engine_variants(engines, embree_isas)?;
        #[cfg(feature = "embree")]
        {
            let threads = threads.max(1);
            let devices = variants
                .iter()
                .filter_map(|v| v.embree_isa)
                .map(|isa| {
                    let device = crate::embree::Device::new(&isa.config(threads))?;
                    Ok((isa, std::sync::Arc::new(device)))
                })
                .collect::<anyhow::Result<_>>()?;
            Ok(Self { devices })
        }
        #[cfg(not(feature = "embree"))]
        {
            let _ = threads;
            let embree = variants.iter().any(|v| v.engine == Engine::Embree);
            anyhow::ensure!(!embree, crate::engine::EMBREE_MISSING);
            Ok(Self {})
        }
    }

    /// Build `variant`'s structure over `prims`.
    pub fn build(&self, variant: EngineVariant, prims: &[Primitive]) -> anyhow::Result<Structure> {
        match variant.engine {
            Engine::Raypack => Ok(Structure::Raypack(Bvh::new(prims))),
            #[cfg(feature = "embree")]
            Engine::Embree => {
                let device = self
                    .devices
                    .iter()
                    .find(|(isa, _)| Some(*isa) == variant.embree_isa)
                    .map(|(_, device)| device.clone())
                    .ok_or_else(|| {
                        anyhow::anyhow!("{} was not among the builder's engines", variant.name())
                    })?;
                Ok(Structure::Embree(crate::embree::EmbreeScene::new(device, prims)?))
            }
            #[cfg(not(feature = "embree"))]
            Engine::Embree => anyhow::bail!(crate::engine::EMBREE_MISSING),
        }
    }
}

/// One row of the traversal table: a scene, an engine and a thread count.
#[derive(Clone, Debug, serde::Serialize)]
pub struct TraversalRow {
    /// Scene name.
    pub scene: String,
    /// Primitives in the scene.
    pub primitives: usize,
    /// Engine whose structure was traversed.
    pub engine: Engine,
    /// Embree's ISA setting (None for raypack).
    pub embree_isa: Option<EmbreeIsa>,
    /// Threads of the rayon pool.
    pub threads: usize,
    /// Build time, ms, of three builds.
    pub build_ms: Summary,
    /// The tree's SAH cost (raypack only: Embree does not report its tree).
    pub sah_cost: Option<f64>,
    /// Primary rays: image size.
    pub resolution: (u32, u32),
    /// The figures of each ray kind, in the order measured.
    pub kinds: Vec<KindRow>,
    /// Timed rounds per variant.
    pub rounds: usize,
}

impl TraversalRow {
    /// The engine as measured (with Embree's ISA setting).
    pub fn variant(&self) -> EngineVariant {
        EngineVariant {
            engine: self.engine,
            embree_isa: self.embree_isa,
        }
    }

    /// The row's figures: build time, each kind's single-ray and packet
    /// throughput, their ratio, and the growth of time per ray from the first scene.
    pub fn figures(&self) -> Vec<Figure> {
        let labels = |extra: &[(&'static str, String)]| -> Vec<(&'static str, String)> {
            let mut l = vec![
                ("scene", self.scene.clone()),
                ("primitives", self.primitives.to_string()),
                ("engine", self.variant().name()),
                ("threads", self.threads.to_string()),
            ];
            l.extend_from_slice(extra);
            l
        };
        let mut figures = vec![Figure::new(
            "build",
            "ms",
            Better::Lower,
            &labels(&[]),
            self.build_ms,
        )];
        for k in &self.kinds {
            let kind = ("rays", k.kind.name().to_string());
            for (v, (kernel, s)) in [("single", k.single_mrays), ("packet8", k.packet_mrays)]
                .into_iter()
                .enumerate()
            {
                let l = labels(&[kind.clone(), ("kernel", kernel.to_string())]);
                figures.push(Figure::new("throughput", "Mrays/s", Better::Higher, &l, s));
                let growth = k.growth_vs_first[v];
                figures.push(Figure::new(
                    "time per ray vs first scene",
                    "x",
                    Better::Neither,
                    &l,
                    growth,
                ));
                if let Some(vs) = k.vs_embree {
                    figures.push(Figure::new("raypack/embree", "x", Better::Neither, &l, vs[v]));
                }
            }
            figures.push(Figure::new(
                "packet8/single",
                "x",
                Better::Neither,
                &labels(&[kind]),
                k.packet_vs_single,
            ));
        }
        figures
    }
}

/// The figures of one ray kind in a [`TraversalRow`].
#[derive(Clone, Debug, serde::Serialize)]
pub struct KindRow {
    /// The kind.
    pub kind: RayKind,
    /// Its query.
    pub query: Query,
    /// Rays traced.
    pub rays: usize,
    /// Rays that hit (nearest) or found something (any hit), single-ray traversal.
    pub hits: u64,
    /// Single-ray traversal, Mrays/s.
    pub single_mrays: Summary,
    /// 8-ray packets, Mrays/s.
    pub packet_mrays: Summary,
    /// `packet_mrays / single_mrays`, round by round.
    pub packet_vs_single: Summary,
    /// Counts of the single-ray pass (raypack only: Embree does not report them).
    pub single_stats: Option<TraversalStats>,
    /// Counts of the packet pass (raypack only).
    pub packet_stats: Option<TraversalStats>,
    /// Time per ray against the same engine and kind on the first scene
    /// measured alongside, round by round (1 for itself): single rays, packets.
    pub growth_vs_first: [Summary; 2],
    /// raypack rows: Mrays/s over Embree's on the same rays, round by round,
    /// when Embree was measured alongside: single rays, packets.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vs_embree: Option<[Summary; 2]>,
}

impl KindRow {
    /// The faster of single rays and packets by median, Mrays/s, and which it was.
    pub fn best(&self) -> (f64, &'static str) {
        if self.packet_mrays.median > self.single_mrays.median {
            (self.packet_mrays.median, "packet8")
        } else {
            (self.single_mrays.median, "single")
        }
    }
}

/// A scene and an engine measured on it: the structure traced and the rays it hit.
struct Case<'a> {
    setup: &'a TraversalSetup,
    variant: EngineVariant,
    structure: Structure,
    /// Per ray set: rays hit by single rays.
    hits: Vec<u64>,
}

/// One thread count's figures of a [`Case`].
struct Timings {
    /// Build times, ms.
    build_ms: Vec<f64>,
    /// Per ray set: each round's seconds per ray of single rays and packets.
    per_ray: Vec<[Vec<f64>; 2]>,
}

/// Timed builds of every structure per thread count, after an untimed round.
const BUILD_ROUNDS: usize = 3;

/// `0..n` in round `round`'s order: forwards in even rounds, backwards in odd
/// ones, so that nothing is measured first (or last) in every round.
fn round_order(round: usize, n: usize) -> Vec<usize> {
    let mut order: Vec<usize> = (0..n).collect();
    if round % 2 == 1 {
        order.reverse();
    }
    order
}

/// A rayon pool of `threads` threads; with Embree among the engines every
/// thread sets FTZ/DAZ, so both engines run in that mode.
fn pool(threads: usize, variants: &[EngineVariant]) -> anyhow::Result<rayon::ThreadPool> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads);
    #[cfg(feature = "embree")]
    let pool = if variants.iter().any(|v| v.engine == Engine::Embree) {
        pool.start_handler(|_| crate::embree::flush_denormals())
    } else {
        pool
    };
    #[cfg(not(feature = "embree"))]
    let _ = variants;
    Ok(pool.build()?)
}

/// Measure `engines` (Embree at each of `embree_isas`) on `setups` at every
/// thread count of `threads`, one rayon pool per count, with no order
/// favouring any of them:
///
/// - builds: three rounds after an untimed one, each building every
///   structure on every thread count (a fresh [`Builder`] per count, since
///   Embree's thread limit is process-wide);
/// - traversal: single rays and packets of every ray set of every scene and
///   engine on every thread count, `rounds` rounds after a warm-up round, all
///   on the structures of the last build.
///
/// Each round goes through thread counts, scenes, engines, kinds and
/// variants, backwards in odd rounds; times pass through
/// the bench timing hooks `hooks`. Rows come per thread count in the order
/// given, then per scene and engine.
pub fn measure(
    setups: &[TraversalSetup],
    engines: &[Engine],
    embree_isas: &[EmbreeIsa],
    threads: &[usize],
    rounds: usize,
    hooks: &TimingHooks,
) -> anyhow::Result<Vec<TraversalRow>> {
    let mut thread_counts: Vec<usize> = Vec::new();
    for t in threads.iter().map(|&t| t.max(1)) {
        if !thread_counts.contains(&t) {
            thread_counts.push(t);
        }
    }
    anyhow::ensure!(!thread_counts.is_empty(), "no thread count to measure");
    let variants = engine_variants(engines, embree_isas)?;
    let pools = thread_counts
        .iter()
        .map(|&t| pool(t, &variants))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let keys: Vec<(&TraversalSetup, EngineVariant)> = setups
        .iter()
        .flat_map(|setup| variants.iter().map(move |&v| (setup, v)))
        .collect();
    let empty = |setup: &TraversalSetup| Timings {
        build_ms: Vec::new(),
        per_ray: vec![Default::default(); setup.sets.len()],
    };
    // timings[t][c]: thread count t, case c.
    let mut timings: Vec<Vec<Timings>> = thread_counts
        .iter()
        .map(|_| keys.iter().map(|(setup, _)| empty(setup)).collect())
        .collect();

    // Build every structure on every thread count, round by round; the
    // structures of the very last builds are kept for tracing, every other
    // one is dropped before the next builder exists (it holds its device).
    let mut structures: Vec<Option<Structure>> = keys.iter().map(|_| None).collect();
    for round in 0..=BUILD_ROUNDS {
        let order = round_order(round, thread_counts.len());
        for (step, &t) in order.iter().enumerate() {
            let keep = round == BUILD_ROUNDS && step + 1 == order.len();
            let builder = Builder::new(engines, embree_isas, thread_counts[t])?;
            pools[t].install(|| -> anyhow::Result<()> {
                for c in round_order(round, keys.len()) {
                    let (setup, variant) = keys[c];
                    let start = Instant::now();
                    let structure = builder.build(variant, &setup.prims)?;
                    let ms = 1e3 * start.elapsed().as_secs_f64();
                    if round > 0 {
                        timings[t][c].build_ms.push(ms);
                    }
                    if keep {
                        structures[c] = Some(structure);
                    }
                }
                Ok(())
            })?;
        }
    }
    let mut cases = keys
        .iter()
        .zip(structures)
        .map(|(&(setup, variant), structure)| {
            Ok(Case {
                setup,
                variant,
                structure: structure.ok_or_else(|| anyhow::anyhow!("{} was not built", variant.name()))?,
                hits: vec![0; setup.sets.len()],
            })
        })
        .collect::<anyhow::Result<Vec<_>>>()?;

    // Trace; round 0 warms every pool and structure up (caches, page faults)
    // and is not kept.
    let steps: Vec<(usize, usize)> = (0..thread_counts.len())
        .flat_map(|t| (0..cases.len()).map(move |c| (t, c)))
        .collect();
    for round in 0..=rounds {
        for step in round_order(round, steps.len()) {
            let (t, c) = steps[step];
            let case = &mut cases[c];
            let timing = &mut timings[t][c];
            pools[t].install(|| {
                for (k, set) in case.setup.sets.iter().enumerate() {
                    for (v, variant) in ["single", "packet8"].into_iter().enumerate() {
                        let start = Instant::now();
                        let hits = black_box(case.structure.trace(set, v == 1));
                        let rays = set.rays.len() as f64;
                        let seconds = hooks.apply(variant, rays, start.elapsed().as_secs_f64());
                        if round == 0 && v == 0 {
                            case.hits[k] = hits;
                        }
                        if round > 0 {
                            timing.per_ray[k][v].push(seconds / set.rays.len().max(1) as f64);
                        }
                    }
                }
            });
        }
    }

    let mut rows = Vec::with_capacity(timings.len() * cases.len());
    for (t, of_threads) in timings.iter().enumerate() {
        for (case, timing) in cases.iter().zip(of_threads) {
            // The first case of the engine: the case itself at the latest.
            let first = cases.iter().position(|c| c.variant == case.variant).unwrap_or(0);
            // Embree on the same rays: its first ISA setting measured.
            let embree = cases.iter().position(|c| {
                case.variant.engine == Engine::Raypack
                    && c.variant.engine == Engine::Embree
                    && std::ptr::eq(c.setup, case.setup)
            });
            rows.push(row(
                case,
                timing,
                &of_threads[first].per_ray,
                embree.map(|e| &of_threads[e].per_ray[..]),
                thread_counts[t],
                rounds,
            )?);
        }
    }
    Ok(rows)
}

/// The table row of `case`: its times as Mrays/s, the ratios, the growth of
/// time per ray from `first_per_ray` (the engine's first scene, `timing`
/// being the case's own figures at the row's thread count), the speed
/// over Embree's on the same rays (`embree_per_ray`, when measured), and for
/// raypack the SAH cost and the traversal counts of one more (untimed) pass of each variant.
fn row(
    case: &Case<'_>,
    timing: &Timings,
    first_per_ray: &[[Vec<f64>; 2]],
    embree_per_ray: Option<&[[Vec<f64>; 2]]>,
    threads: usize,
    rounds: usize,
) -> anyhow::Result<TraversalRow> {
    let setup = case.setup;
    let mrays = |per_ray: &[f64]| Summary::of(&per_ray.iter().map(|t| 1e-6 / t).collect::<Vec<_>>());
    let kinds = setup
        .sets
        .iter()
        .enumerate()
        .map(|(k, set)| -> anyhow::Result<KindRow> {
            let [single, packet] = &timing.per_ray[k];
            // Per kind, the first scene's sets are the same kinds in the same order.
            let first = first_per_ray.get(k).unwrap_or(&timing.per_ray[k]);
            let stats = match &case.structure {
                Structure::Raypack(bvh) => {
                    let [single, packet] = counted(bvh, set);
                    (Some(single), Some(packet))
                }
                #[cfg(feature = "embree")]
                Structure::Embree(_) => (None, None),
            };
            Ok(KindRow {
                kind: set.kind,
                query: set.kind.query(),
                rays: set.rays.len(),
                hits: case.hits[k],
                single_mrays: mrays(single)?,
                packet_mrays: mrays(packet)?,
                packet_vs_single: Summary::paired_ratio(single, packet)?,
                single_stats: stats.0,
                packet_stats: stats.1,
                growth_vs_first: [
                    Summary::paired_ratio(single, &first[0])?,
                    Summary::paired_ratio(packet, &first[1])?,
                ],
                vs_embree: match embree_per_ray.and_then(|e| e.get(k)) {
                    Some([e_single, e_packet]) => Some([
                        Summary::paired_ratio(e_single, single)?,
                        Summary::paired_ratio(e_packet, packet)?,
                    ]),
                    None => None,
                },
            })
        })
        .collect::<anyhow::Result<_>>()?;
    let sah_cost = match &case.structure {
        Structure::Raypack(bvh) => Some(bvh.info().sah_cost),
        #[cfg(feature = "embree")]
        Structure::Embree(_) => None,
    };
    Ok(TraversalRow {
        scene: setup.name.clone(),
        primitives: setup.prims.len(),
        engine: case.variant.engine,
        embree_isa: case.variant.embree_isa,
        threads,
        build_ms: Summary::of(&timing.build_ms)?,
        sah_cost,
        resolution: setup.resolution,
        kinds,
        rounds,
    })
}

/// The traversal counts of `set` on `bvh`: single rays, packets.
fn counted(bvh: &Bvh, set: &RaySet) -> [TraversalStats; 2] {
    let mut stats = [TraversalStats::default(); 2];
    for r in &set.rays {
        match set.kind.query() {
            Query::Nearest => _ = bvh.intersect_counted(r, &mut stats[0]),
            Query::AnyHit => _ = bvh.occluded_counted(r, &mut stats[0]),
        }
    }
    for p in &set.packets {
        match set.kind.query() {
            Query::Nearest => _ = bvh.intersect_packet_counted(p, &mut stats[1]),
            Query::AnyHit => _ = bvh.occluded_packet_counted(p, &mut stats[1]),
        }
    }
    stats
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn odd_rounds_go_backwards() {
        assert_eq!(round_order(0, 3), [0, 1, 2]);
        assert_eq!(round_order(1, 3), [2, 1, 0]);
        assert_eq!(round_order(2, 3), [0, 1, 2]);
        assert!(round_order(1, 0).is_empty());
    }

    #[test]
    fn every_thread_count_gets_a_row_per_scene_with_every_round_kept() {
        let kinds = [RayKind::Primary, RayKind::Ao];
        let setups = [
            TraversalSetup::generated("mesh", 100, (16, 16), 32, &kinds).expect("known kind"),
            TraversalSetup::generated("mesh", 300, (16, 16), 32, &kinds).expect("known kind"),
        ];
        let hooks = TimingHooks::default();
        let rows = measure(&setups, &[Engine::Raypack], &[], &[2, 1, 2], 3, &hooks).unwrap();
        // A thread count given twice is measured once, in the order given.
        let layout: Vec<_> = rows.iter().map(|r| (r.threads, r.primitives)).collect();
        let [small, large] = setups.each_ref().map(|s| s.prims.len());
        assert!(small < large);
        assert_eq!(layout, [(2, small), (2, large), (1, small), (1, large)]);
        for row in &rows {
            assert_eq!(row.build_ms.samples, BUILD_ROUNDS, "{}", row.scene);
            for k in &row.kinds {
                assert_eq!(k.single_mrays.samples, 3);
                assert_eq!(k.packet_mrays.samples, 3);
            }
        }
        // The same structures and rays at either thread count: the same hits.
        for (two, one) in rows[..2].iter().zip(&rows[2..]) {
            let hits = |r: &TraversalRow| r.kinds.iter().map(|k| k.hits).collect::<Vec<_>>();
            assert_eq!(hits(two), hits(one));
            assert!(hits(one)[0] > 0, "the camera sees the mesh");
        }
        assert!(measure(&setups, &[Engine::Raypack], &[], &[], 1, &hooks).is_err());
    }

    #[test]
    fn single_rays_and_packets_agree_with_brute_force_on_every_kind() {
        let s = TraversalSetup::generated("mesh", 500, (40, 20), 100, &RayKind::ALL).expect("known kind");
        assert_eq!(s.set(RayKind::Primary).expect("primary").rays.len(), 800);
        let bvh = Bvh::new(&s.prims);
        let brute = crate::accel::BruteForce::new(&s.prims);
        for set in &s.sets {
            let hits = trace_single(&brute, set);
            assert_eq!(trace_single(&bvh, set), hits, "{:?}", set.kind);
            assert_eq!(trace_packets(&bvh, set), hits, "{:?}", set.kind);
            assert_eq!(trace_packets(&brute, set), hits, "{:?}", set.kind);
        }
    }
}
