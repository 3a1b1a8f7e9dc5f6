//! Scene throughput: primary rays per second through the tile scheduler, per
//! kernel and thread count, shared by `raypack bench scene` and the criterion
//! bench `benches/render.rs`; and the other standard ray kinds
//! ([`RayKind`](crate::bench::rays::RayKind)) of the scene per kernel and thread count.
//!
//! Every variant traces the same rays (the camera's pixel centres, in the same
//! tiles and blocks) and only finds their nearest hits: no shading, no image.
//! The other kinds are traced as `bench traversal` traces them: one by one
//! for the scalar kernel, in their 8-ray packets for the packet kernel.
//! The variants, of every engine measured, are interleaved run by run after
//! one warm-up each ([`interleave`]), so drift of a shared machine hits them alike; every run's time is kept, so that each
//! variant's figure is a median with its interval and the ratio of two
//! variants is taken run by run ([`Summary::paired_ratio`]).

use std::time::Instant;

use crate::accel::Accel;
use crate::accel::stats::NoStats;
use crate::bench::pinned_pool::pinned_pool;
use crate::bench::rays::KindRays;
use crate::bench::timing_hooks::TimingHooks;
use crate::bench::traversal::trace_path;
use crate::camera::Camera;
use crate::engines::Engine;
use crate::render::kernel::TraceKernel;
use crate::render::tiles::{self, Tile};
use crate::render::whitted::lanes;
use crate::render::{
    Block, Grid, KernelKind, Packet8Kernel, Packet16Kernel, Sampling, ScalarKernel, for_each_block,
};
use crate::statistics::Summary;

/// A kernel, pixel block and thread count to measure. 16 bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Variant {
    /// Kernel.
    pub kernel: KernelKind,
    /// Pixel block per batch.
    pub block: Block,
    /// Worker threads.
    pub threads: usize,
}

/// The timing of one variant. 56 bytes plus 8 per run.
#[derive(Clone, Debug)]
pub struct Timing {
    /// What was measured.
    pub variant: Variant,
    /// Each run's time, seconds, in the order run (run `i` of every variant
    /// was timed in the same round).
    pub seconds: Vec<f64>,
    /// Rays per run.
    pub rays: u64,
    /// Rays that hit something (the same for every variant).
    pub hits: u64,
}

impl Timing {
    /// Million rays per second of each run.
    pub fn mrays(&self) -> Vec<f64> {
        self.seconds.iter().map(|s| self.rays as f64 / s / 1e6).collect()
    }

    /// The summary of [`mrays`](Self::mrays).
    pub fn mrays_per_s(&self) -> Summary {
        // Times are positive (a run takes time) and there is at least one run.
        Summary::of(&self.mrays()).expect("positive run times")
    }
}

/// The primary rays of one frame: the camera's grid cut into tiles.
/// 104 bytes plus 16 bytes per tile.
#[derive(Clone, Debug)]
pub struct PrimaryFrame {
    grid: Grid,
    tiles: Vec<Tile>,
}

impl PrimaryFrame {
    /// Rays through the pixel centres of `camera`, in `tile_size` tiles.
    pub fn new(camera: &Camera, tile_size: u32) -> Self {
        let grid = Grid::new(*camera, Sampling::PixelCentres);
        Self {
            tiles: tiles::tiles(grid.width, grid.height, tile_size),
            grid,
        }
    }

    /// Number of rays.
    pub fn rays(&self) -> u64 {
        u64::from(self.grid.width) * u64::from(self.grid.height)
    }

    /// Trace every primary ray's nearest hit on `pool` with `kernel`, in batches
    /// of `block` pixels; returns how many hit.
    pub fn trace<A: Accel>(
        &self,
        accel: &A,
        kernel: KernelKind,
        block: Block,
        pool: &rayon::ThreadPool,
    ) -> u64 {
        match kernel {
            KernelKind::Scalar => self.trace_with::<ScalarKernel, A>(accel, block, pool),
            KernelKind::Packet8 => self.trace_with::<Packet8Kernel, A>(accel, block, pool),
            KernelKind::Packet16 => self.trace_with::<Packet16Kernel, A>(accel, block, pool),
        }
    }

    fn trace_with<K: TraceKernel, A: Accel>(&self, accel: &A, block: Block, pool: &rayon::ThreadPool) -> u64 {
        // NoStats: the same queries as the renderer's plain path, with no counting compiled in.
        let per_tile = tiles::run(
            pool,
            &self.tiles,
            |tile| {
                let mut hits = 0u64;
                for_each_block(&self.grid, tile, block, |rays, active, _| {
                    let h = K::intersect(accel, rays, active, &mut NoStats);
                    hits += lanes(active).filter(|&i| h[i].is_hit()).count() as u64;
                });
                hits
            },
            || {},
        );
        per_tile.iter().map(|t| t.value).sum()
    }
}

/// One thing to time: a variant traced by one engine.
pub struct Unit<'a> {
    /// The variant.
    pub variant: Variant,
    /// The engine's index among those measured together: hits are compared
    /// within one engine only, since engines may disagree on a few rays
    /// (shared edges, coincident surfaces).
    pub engine: usize,
    /// Traces the rays on a pool of the variant's threads; returns the rays hit.
    pub trace: Box<dyn Fn(&rayon::ThreadPool) -> u64 + 'a>,
}

/// The rays a unit traces.
#[derive(Clone, Copy)]
pub enum Rays<'a> {
    /// The primary rays of a frame, through the tile scheduler in the variant's blocks.
    Primary(&'a PrimaryFrame),
    /// The rays of one kind: one by one for the scalar kernel, in its 8- or 16-ray packets
    /// (4×4-pixel blocks; the variant's block must be [`Block::B4x4`]) for the packet kernels.
    OfKind(&'a KindRays),
}

impl Rays<'_> {
    /// Rays per trace.
    pub fn count(&self) -> u64 {
        match self {
            Self::Primary(frame) => frame.rays(),
            Self::OfKind(set) => set.rays.len() as u64,
        }
    }
}

/// The units tracing `rays` with `accel` (engine number `engine`), one per variant.
pub fn units<'a, A: Accel>(
    accel: &'a A,
    rays: Rays<'a>,
    variants: &[Variant],
    engine: usize,
) -> Result<Vec<Unit<'a>>, String> {
    if let (Rays::OfKind(set), Some(v)) = (rays, variants.iter().find(|v| v.block != Block::B4x4)) {
        return Err(format!(
            "{v:?}: {} rays are packed in 4x4 blocks",
            set.kind.name()
        ));
    }
    Ok(variants
        .iter()
        .map(|&variant| {
            let trace: Box<dyn Fn(&rayon::ThreadPool) -> u64 + 'a> = match rays {
                Rays::Primary(frame) => {
                    Box::new(move |pool| frame.trace(accel, variant.kernel, variant.block, pool))
                }
                Rays::OfKind(set) => {
                    Box::new(move |pool| pool.install(|| trace_path(accel, set, variant.kernel)))
                }
            };
            Unit {
                variant,
                engine,
                trace,
            }
        })
        .collect())
}

/// Measure every variant `runs` times (interleaved, after a warm-up each),
/// times passed through the bench timing hooks `hooks`.
/// Fails if two variants disagree on the number of hits, which would mean the
/// kernels do not trace the same scene.
pub fn measure<A: Accel>(
    accel: &A,
    frame: &PrimaryFrame,
    variants: &[Variant],
    runs: usize,
    hooks: &TimingHooks,
) -> Result<Vec<Timing>, String> {
    let rays = Rays::Primary(frame);
    interleave(&units(accel, rays, variants, 0)?, &[], runs, hooks, rays.count())
}

/// Measure the rays of `set` per variant as [`measure`] does the primary rays
/// (see [`Rays::OfKind`]).
pub fn measure_set<A: Accel>(
    accel: &A,
    set: &KindRays,
    variants: &[Variant],
    runs: usize,
    hooks: &TimingHooks,
) -> Result<Vec<Timing>, String> {
    let rays = Rays::OfKind(set);
    interleave(&units(accel, rays, variants, 0)?, &[], runs, hooks, rays.count())
}

/// Time every unit (each trace `rays` rays) on a pool of its variant's
/// threads, `runs` times interleaved unit by unit after a warm-up each, so
/// that run `i` of every unit (of every engine among them) falls in round `i`;
/// times pass through the bench timing hooks `hooks`. Each unit has its own
/// pool, its workers pinned ([`pinned_pool`]). A unit's pool gets the
/// thread setup of its engine, `engines[unit.engine]` (none past the end of
/// `engines`). Fails if two units of one engine disagree on the number of hits.
pub fn interleave(
    units: &[Unit<'_>],
    engines: &[Engine],
    runs: usize,
    hooks: &TimingHooks,
    rays: u64,
) -> Result<Vec<Timing>, String> {
    let pools = units
        .iter()
        .map(|u| {
            let pool = pinned_pool(u.variant.threads)
                .map_err(|e| format!("cannot start {} threads: {e}", u.variant.threads))?;
            if let Some(&engine) = engines.get(u.engine) {
                Engine::prepare_threads(&[engine], &pool);
            }
            Ok(pool)
        })
        .collect::<Result<Vec<_>, String>>()?;
    let hits: Vec<u64> = units
        .iter()
        .zip(&pools)
        .map(|(u, pool)| (u.trace)(pool))
        .collect();
    for (k, u) in units.iter().enumerate() {
        if let Some(first) = units.iter().position(|o| o.engine == u.engine)
            && hits[first] != hits[k]
        {
            return Err(format!(
                "{:?} hits {} rays, {:?} hits {}",
                units[first].variant, hits[first], u.variant, hits[k]
            ));
        }
    }
    let mut samples = vec![Vec::with_capacity(runs); units.len()];
    for _ in 0..runs.max(1) {
        for (k, u) in units.iter().enumerate() {
            let start = Instant::now();
            std::hint::black_box((u.trace)(&pools[k]));
            // (A frame is the unit of work.)
            samples[k].push(hooks.apply(u.variant.kernel.name(), 1.0, start.elapsed().as_secs_f64()));
        }
    }
    Ok(units
        .iter()
        .zip(samples)
        .zip(hits)
        .map(|((u, seconds), hits)| Timing {
            variant: u.variant,
            seconds,
            rays,
            hits,
        })
        .collect())
}
