//! The numbers of one render, printed in the image's caption and written as the
//! JSON sidecar: what was rendered, how, how long it took, which rays it cost,
//! and what traversing the scene cost those rays.
//!
//! The traversal statistics come from the timed render itself (counting them
//! is part of its trace time; `--no-traversal-stats` leaves them out).

use std::collections::BTreeMap;

use crate::accel::TraversalStats;
use crate::engines::Engine;
use crate::picture::heat_map::HeatMapKind;
use crate::render::{Block, KernelKind, Mode, RayCounts, Render};
use crate::scene::Scene;
use crate::simd::Isa;

/// Everything a reader needs to interpret a render's timing. 392 bytes plus
/// its strings, map and per-tile figures.
#[derive(Clone, Debug, serde::Serialize)]
pub struct RenderReport {
    /// Scene file (or generator) name.
    pub scene: String,
    /// The engine that traced: raypack or Embree.
    pub engine: Engine,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Shading mode.
    pub mode: Mode,
    /// Kernel.
    pub kernel: KernelKind,
    /// Pixel block per batch.
    pub block: Block,
    /// The instruction set raypack's kernels ran on (`--isa`).
    pub isa: &'static str,
    /// Acceleration structure.
    pub accel: &'static str,
    /// The engine as it describes itself: raypack's version and structure,
    /// or Embree's version, device configuration (its kernels' ISA) and
    /// scene mode.
    pub settings: String,
    /// Worker threads.
    pub threads: usize,
    /// Tile edge in pixels.
    pub tile_size: u32,
    /// Maximum ray depth (whitted mode).
    pub max_depth: u32,
    /// Number of primitives (instanced ones once per instance).
    pub primitives: usize,
    /// The scene's instancing, if it has instances.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub instancing: Option<crate::scene::InstancingSummary>,
    /// Primitives by kind.
    pub primitive_kinds: BTreeMap<String, usize>,
    /// Lights.
    pub lights: usize,
    /// Whether the one light is a headlight at the eye, added because the
    /// scene has none (see `render --no-headlight`).
    pub headlight: bool,
    /// Milliseconds spent reading the scene.
    pub load_ms: f64,
    /// Milliseconds spent building the acceleration structure.
    pub setup_ms: f64,
    /// Milliseconds spent tracing (all tiles, wall clock).
    pub trace_ms: f64,
    /// Million rays (all kinds) per second of trace time.
    pub mrays_per_s: f64,
    /// Rays by kind.
    pub rays: RayCounts,
    /// All rays traced.
    pub rays_total: u64,
    /// Whether the timed render also counted its traversal work (then
    /// `traversal` holds the counts, and the times include counting them).
    pub traversal_counted: bool,
    /// What traversing the scene cost all the rays; None (`null`) when not
    /// counted, and always with Embree, which does not report it.
    pub traversal: Option<TraversalReport>,
    /// Per-tile CPU time (and traversal cost).
    pub tiles: TileTimes,
}

/// The traversal counters of a render and the ratios derived from them.
/// 104 bytes.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct TraversalReport {
    /// The raw counters.
    #[serde(flatten)]
    pub counts: TraversalStats,
    /// Node visits per ray.
    pub nodes_per_ray: f64,
    /// Ray-primitive tests per ray.
    pub prims_per_ray: f64,
    /// Active lanes / lane slots over the packets' SIMD steps (0 without packets).
    pub lane_utilisation: f64,
    /// Single-ray fallbacks of packet lanes per ray.
    pub fallbacks_per_ray: f64,
    /// Node visits plus primitive tests per ray.
    pub cost_per_ray: f64,
}

impl TraversalReport {
    /// The counters `counts` with their ratios.
    pub fn new(counts: TraversalStats) -> Self {
        Self {
            counts,
            nodes_per_ray: counts.nodes_per_ray(),
            prims_per_ray: counts.prims_per_ray(),
            lane_utilisation: counts.lane_utilisation(),
            fallbacks_per_ray: counts.fallbacks_per_ray(),
            cost_per_ray: counts.cost_per_ray(),
        }
    }
}

/// Per-tile CPU times and traversal costs, row-major (the time heat map's
/// data). 80 bytes plus 8 or 16 per tile.
#[derive(Clone, Debug, serde::Serialize)]
pub struct TileTimes {
    /// Tiles per row.
    pub columns: u32,
    /// Tile rows.
    pub rows: u32,
    /// Fastest tile, ms.
    pub min_ms: f64,
    /// Mean tile, ms.
    pub mean_ms: f64,
    /// Slowest tile, ms.
    pub max_ms: f64,
    /// Each tile's ms.
    pub ms: Vec<f64>,
    /// Each tile's traversal cost per ray (node visits plus primitive tests),
    /// when traversal was counted.
    pub cost_per_ray: Option<Vec<f64>>,
}

/// How a render was set up, besides its settings. 80 bytes.
#[derive(Clone, Debug)]
pub struct RunInfo {
    /// Engine.
    pub engine: Engine,
    /// Kernel.
    pub kernel: KernelKind,
    /// Pixel block.
    pub block: Block,
    /// Mode.
    pub mode: Mode,
    /// Acceleration structure name.
    pub accel: &'static str,
    /// The engine's description of itself (`Description::settings`).
    pub settings: String,
    /// Worker threads.
    pub threads: usize,
    /// Tile edge.
    pub tile_size: u32,
    /// Depth limit.
    pub max_depth: u32,
    /// Scene loading time, seconds.
    pub load_seconds: f64,
    /// Acceleration structure build time, seconds.
    pub setup_seconds: f64,
    /// Whether a headlight was added to a scene without lights.
    pub headlight: bool,
}

impl RenderReport {
    /// The report of `render` of `scene` made as `info` says.
    pub fn new(scene: &Scene, render: &Render, info: &RunInfo) -> Self {
        let ms: Vec<f64> = render.tile_seconds.iter().map(|s| 1e3 * s).collect();
        let columns = render.tiles_x.max(1);
        let name = std::path::Path::new(&scene.source)
            .file_name()
            .map_or_else(|| scene.source.clone(), |n| n.to_string_lossy().into_owned());
        Self {
            scene: name,
            engine: info.engine,
            width: render.frame.width,
            height: render.frame.height,
            mode: info.mode,
            kernel: info.kernel,
            block: info.block,
            isa: Isa::default_level().name(),
            accel: info.accel,
            settings: info.settings.clone(),
            threads: info.threads,
            tile_size: info.tile_size,
            max_depth: info.max_depth,
            primitives: scene.id_count() as usize,
            instancing: scene.instancing_summary(),
            primitive_kinds: scene
                .counts()
                .into_iter()
                .map(|(k, n)| (format!("{k:?}").to_lowercase(), n))
                .collect(),
            lights: scene.lights.len(),
            headlight: info.headlight,
            load_ms: 1e3 * info.load_seconds,
            setup_ms: 1e3 * info.setup_seconds,
            trace_ms: 1e3 * render.trace_seconds,
            mrays_per_s: render.counts.total() as f64 / render.trace_seconds.max(1e-12) / 1e6,
            rays: render.counts,
            rays_total: render.counts.total(),
            traversal_counted: render.traversal.is_some(),
            traversal: render.traversal.as_ref().map(|t| TraversalReport::new(t.total)),
            tiles: TileTimes {
                columns,
                rows: (ms.len() as u32).div_ceil(columns),
                min_ms: ms.iter().copied().fold(f64::INFINITY, f64::min),
                mean_ms: ms.iter().sum::<f64>() / ms.len().max(1) as f64,
                max_ms: ms.iter().copied().fold(0.0, f64::max),
                ms,
                cost_per_ray: render
                    .traversal
                    .as_ref()
                    .map(|t| t.tiles.iter().map(TraversalStats::cost_per_ray).collect()),
            },
        }
    }

    /// The caption: one paragraph each for the setup, the times, the rays and
    /// their traversal.
    pub fn caption(&self) -> Vec<String> {
        let kinds: Vec<String> = self
            .primitive_kinds
            .iter()
            .map(|(k, n)| format!("{k} {n}"))
            .collect();
        let r = &self.rays;
        let mode = match self.mode {
            Mode::Whitted => format!("whitted (depth {})", self.max_depth),
            m => m.name().to_string(),
        };
        // raypack's kernels run on `isa`; another engine's description names
        // its own (Embree's device configuration).
        let (blocks, accel) = match self.engine {
            Engine::Raypack => (
                format!("{} blocks, {}", self.block.name(), self.isa),
                self.accel.to_string(),
            ),
            _ => (format!("{} blocks", self.block.name()), self.settings.clone()),
        };
        let mut lines = vec![
            format!(
                "{}  {}x{}  mode: {}  kernel: {} ({blocks})  accel: {accel}  threads: {}  tiles: {}px",
                self.scene,
                self.width,
                self.height,
                mode,
                self.kernel.name(),
                self.threads,
                self.tile_size
            ),
            format!(
                "primitives: {} ({})  lights: {}{}  setup: {:.1} ms  trace: {:.1} ms  {:.2} Mrays/s",
                self.primitives,
                kinds.join(", "),
                self.lights,
                if self.headlight { " (headlight)" } else { "" },
                self.setup_ms,
                self.trace_ms,
                self.mrays_per_s
            ),
            format!(
                "rays: eye {} (hits {})  reflect {}  refract {}  shadow {} (blocked {})  total {}",
                r.eye_rays,
                r.eye_hits,
                r.reflect_rays,
                r.refract_rays,
                r.shadow_rays,
                r.shadow_blocked,
                self.rays_total
            ),
            self.traversal_caption(),
        ];
        if let Some(i) = &self.instancing {
            lines.insert(2, format!("instancing: {}", i.line()));
        }
        lines
    }

    /// The traversal paragraph, e.g. `traversal, counted in this render, BVH:
    /// 12.3 nodes/ray, 2.1 prims/ray, lanes 83% (packets), …`.
    fn traversal_caption(&self) -> String {
        match (&self.traversal, self.engine) {
            (Some(t), _) => {
                let accel = match self.accel {
                    "bvh" => "BVH",
                    "none" => "brute force",
                    other => other,
                };
                format!(
                    "traversal, counted in this render, {accel}: {}",
                    t.counts.caption()
                )
            }
            (None, engine) if !engine.capabilities().counts_work => {
                format!("traversal stats: not available from {engine}")
            }
            (None, _) => "traversal stats: not counted (--no-traversal-stats)".to_string(),
        }
    }

    /// The heat map's legend line: what its colours measure.
    pub fn heat_caption(&self, kind: HeatMapKind) -> String {
        match kind {
            HeatMapKind::Time => format!(
                "heat map: CPU time per pixel of each {}px tile, black 0 to yellow = 99th percentile of the pixels; tiles {:.2}-{:.2} ms, mean {:.2} ms",
                self.tile_size, self.tiles.min_ms, self.tiles.max_ms, self.tiles.mean_ms
            ),
            HeatMapKind::Cost => {
                let cost = self
                    .traversal
                    .map_or(0, |t| t.counts.nodes_visited + t.counts.prim_tests);
                let pixels = (u64::from(self.width) * u64::from(self.height)).max(1);
                format!(
                    "heat map: traversal cost per pixel = node visits + primitive tests of all its rays \
                     (primary, secondary, shadow; a packet step counts once per lane taking part), \
                     black 0 to yellow = 99th percentile of the pixels; mean {:.1} per pixel",
                    cost as f64 / pixels as f64
                )
            }
        }
    }
}
