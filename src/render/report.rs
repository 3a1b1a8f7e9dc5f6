//! The numbers of one render, printed in the image's caption and written as the
//! JSON sidecar: what was rendered, how, how long it took, and which rays it cost.

use std::collections::BTreeMap;

use crate::render::{Block, KernelKind, Mode, RayCounts, Render};
use crate::scene::Scene;

/// Everything a reader needs to interpret a render's timing. 272 bytes plus
/// its strings, map and per-tile times.
#[derive(Clone, Debug, serde::Serialize)]
pub struct RenderReport {
    /// Scene file (or generator) name.
    pub scene: String,
    /// Always `raypack`.
    pub engine: &'static str,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Shading mode.
    pub mode: Mode,
    /// Kernel.
    pub kernel: KernelKind,
    /// Pixel block per packet.
    pub block: Block,
    /// Acceleration structure.
    pub accel: &'static str,
    /// Worker threads.
    pub threads: usize,
    /// Tile edge in pixels.
    pub tile_size: u32,
    /// Maximum ray depth (whitted mode).
    pub max_depth: u32,
    /// Number of primitives.
    pub primitives: usize,
    /// Primitives by kind.
    pub primitive_kinds: BTreeMap<String, usize>,
    /// Lights.
    pub lights: usize,
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
    /// Per-tile CPU time.
    pub tiles: TileTimes,
}

/// Per-tile CPU times, row-major (the heat map's data). 56 bytes plus 8 per tile.
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
}

/// How a render was set up, besides its settings. 56 bytes.
#[derive(Clone, Copy, Debug)]
pub struct RunInfo {
    /// Kernel.
    pub kernel: KernelKind,
    /// Pixel block.
    pub block: Block,
    /// Mode.
    pub mode: Mode,
    /// Acceleration structure name.
    pub accel: &'static str,
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
            engine: "raypack",
            width: render.frame.width,
            height: render.frame.height,
            mode: info.mode,
            kernel: info.kernel,
            block: info.block,
            accel: info.accel,
            threads: info.threads,
            tile_size: info.tile_size,
            max_depth: info.max_depth,
            primitives: scene.primitives.len(),
            primitive_kinds: scene
                .counts()
                .into_iter()
                .map(|(k, n)| (format!("{k:?}").to_lowercase(), n))
                .collect(),
            lights: scene.lights.len(),
            load_ms: 1e3 * info.load_seconds,
            setup_ms: 1e3 * info.setup_seconds,
            trace_ms: 1e3 * render.trace_seconds,
            mrays_per_s: render.counts.total() as f64 / render.trace_seconds.max(1e-12) / 1e6,
            rays: render.counts,
            rays_total: render.counts.total(),
            tiles: TileTimes {
                columns,
                rows: (ms.len() as u32).div_ceil(columns),
                min_ms: ms.iter().copied().fold(f64::INFINITY, f64::min),
                mean_ms: ms.iter().sum::<f64>() / ms.len().max(1) as f64,
                max_ms: ms.iter().copied().fold(0.0, f64::max),
                ms,
            },
        }
    }

    /// The caption: one paragraph each for the setup, the times and the rays.
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
        vec![
            format!(
                "{}  {}x{}  mode: {}  kernel: {} ({} blocks)  accel: {}  threads: {}  tiles: {}px",
                self.scene,
                self.width,
                self.height,
                mode,
                self.kernel.name(),
                self.block.name(),
                self.accel,
                self.threads,
                self.tile_size
            ),
            format!(
                "primitives: {} ({})  lights: {}  setup: {:.1} ms  trace: {:.1} ms  {:.2} Mrays/s",
                self.primitives,
                kinds.join(", "),
                self.lights,
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
        ]
    }

    /// The heat map's legend line: what its colours measure.
    pub fn heat_caption(&self) -> String {
        format!(
            "heat map: CPU time per pixel of each {}px tile, black 0 to yellow = slowest; tiles {:.2}-{:.2} ms, mean {:.2} ms",
            self.tile_size, self.tiles.min_ms, self.tiles.max_ms, self.tiles.mean_ms
        )
    }
}
