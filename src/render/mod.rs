//! Rendering: rayon tiles, ray casting and Whitted ray tracing through the
//! scalar or the packet kernels, ray statistics, and timing-annotated images.
//!
//! [`render`] traces a grid of primary rays (pixel centres for images, pixel
//! corners for the SPD's statistics) tile by tile. Inside a tile the rays go in
//! batches of 8, a 4×2 or 8×1 pixel block, through a [`TraceKernel`]: every query
//! of a batch, primary, reflection, refraction or shadow, is one packet query
//! with a lane mask (or 8 scalar queries), and the shading between queries is the
//! same scalar code for both kernels. Scalar and packet renders therefore trace
//! the same rays and give the same images and ray counts.

pub mod annotate;
pub mod colormap;
pub mod engine;
pub mod frame;
pub mod kernel;
pub mod optics;
pub mod output;
pub mod progress;
pub mod report;
pub mod shade;
pub mod spd;
pub mod stats;
pub mod surface;
pub mod text;
pub mod tiles;
pub mod whitted;

use std::time::Instant;

use glam::Vec3;

pub use frame::Frame;
pub use kernel::{Packet8Kernel, PacketKernel, ScalarKernel, TraceKernel};
pub use stats::RayCounts;
pub use tiles::Tile;
pub use whitted::Tracer;

use crate::accel::Accel;
use crate::camera::Camera;
use crate::ray::Ray;
use crate::scene::Scene;
use kernel::{BATCH, Rays};
use whitted::lanes;

/// What a pixel shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    /// Ray casting: the nearest object's colour under a headlight.
    Cast,
    /// The shading normal as a colour.
    Normals,
    /// Distance of the primary hit as grey levels.
    Depth,
    /// A colour per primitive.
    Id,
    /// Recursive ray tracing: shadows, reflection, refraction.
    Whitted,
}

impl Mode {
    /// Name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Cast => "cast",
            Mode::Normals => "normals",
            Mode::Depth => "depth",
            Mode::Id => "id",
            Mode::Whitted => "whitted",
        }
    }
}

/// Which kernels trace the rays.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum KernelKind {
    /// One ray at a time.
    Scalar,
    /// 8-wide SIMD packets.
    Packet8,
}

impl KernelKind {
    /// Name in reports.
    pub fn name(self) -> &'static str {
        match self {
            KernelKind::Scalar => "scalar",
            KernelKind::Packet8 => "packet8",
        }
    }
}

/// The pixel block traced as one batch (one packet).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
pub enum Block {
    /// 4 pixels wide, 2 high.
    #[value(name = "4x2")]
    #[serde(rename = "4x2")]
    B4x2,
    /// 8 pixels wide, 1 high.
    #[value(name = "8x1")]
    #[serde(rename = "8x1")]
    B8x1,
}

impl Block {
    /// `(width, height)` in pixels.
    pub fn dims(self) -> (u32, u32) {
        match self {
            Block::B4x2 => (4, 2),
            Block::B8x1 => (8, 1),
        }
    }

    /// Name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Block::B4x2 => "4x2",
            Block::B8x1 => "8x1",
        }
    }
}

/// Where the primary rays go through the image plane.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sampling {
    /// Pixel centres: `width × height` rays (images).
    PixelCentres,
    /// Pixel corners: `(width + 1) × (height + 1)` rays (the SPD's statistics).
    PixelCorners,
}

/// How to render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    /// What a pixel shows.
    pub mode: Mode,
    /// Scalar or packet kernels.
    pub kernel: KernelKind,
    /// Pixel block per batch.
    pub block: Block,
    /// Tile edge in pixels.
    pub tile_size: u32,
    /// Maximum ray tree depth in `whitted` mode (eye ray = 1).
    pub max_depth: u32,
    /// Pixel centres or corners.
    pub sampling: Sampling,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            mode: Mode::Whitted,
            kernel: KernelKind::Packet8,
            block: Block::B4x2,
            tile_size: 16,
            max_depth: 5,
            sampling: Sampling::PixelCentres,
        }
    }
}

/// A finished render: the frame, the tiles with their times, the ray counts.
#[derive(Clone, Debug)]
pub struct Render {
    /// The image and its primary hits (one entry per primary ray).
    pub frame: Frame,
    /// The tiles, in row-major order.
    pub tiles: Vec<Tile>,
    /// CPU seconds spent in each tile (see [`tiles`]).
    pub tile_seconds: Vec<f64>,
    /// Rays traced, by kind.
    pub counts: RayCounts,
    /// Wall-clock seconds of the whole trace.
    pub trace_seconds: f64,
    /// Tiles per row.
    pub tiles_x: u32,
}

/// The primary rays of a camera at pixel centres or corners.
#[derive(Clone, Copy, Debug)]
pub struct Grid {
    camera: Camera,
    sampling: Sampling,
    /// Rays per row.
    pub width: u32,
    /// Rays per column.
    pub height: u32,
}

impl Grid {
    /// The grid of `camera` under `sampling`.
    pub fn new(camera: Camera, sampling: Sampling) -> Self {
        let extra = match sampling {
            Sampling::PixelCentres => 0,
            Sampling::PixelCorners => 1,
        };
        Self {
            camera,
            sampling,
            width: camera.width + extra,
            height: camera.height + extra,
        }
    }

    /// The primary ray `(x, y)` of the grid.
    #[inline]
    pub fn ray(&self, x: u32, y: u32) -> Ray {
        match self.sampling {
            Sampling::PixelCentres => self.camera.pixel_ray(x, y),
            Sampling::PixelCorners => self.camera.ray(x as f32, y as f32),
        }
    }
}

/// Render `scene` through `accel` with `camera` on the threads of `pool`;
/// `on_tile` is called as each tile finishes.
pub fn render<A: Accel>(
    scene: &Scene,
    accel: &A,
    camera: &Camera,
    settings: &RenderSettings,
    pool: &rayon::ThreadPool,
    on_tile: impl Fn() + Sync,
) -> Render {
    match settings.kernel {
        KernelKind::Scalar => render_with::<ScalarKernel, A>(scene, accel, camera, settings, pool, on_tile),
        KernelKind::Packet8 => render_with::<Packet8Kernel, A>(scene, accel, camera, settings, pool, on_tile),
    }
}

/// One tile's pixels, in row-major order within the tile.
struct TileOut {
    color: Vec<Vec3>,
    depth: Vec<f32>,
    prim: Vec<u32>,
    counts: RayCounts,
}

fn render_with<K: TraceKernel, A: Accel>(
    scene: &Scene,
    accel: &A,
    camera: &Camera,
    settings: &RenderSettings,
    pool: &rayon::ThreadPool,
    on_tile: impl Fn() + Sync,
) -> Render {
    let grid = Grid::new(*camera, settings.sampling);
    let tracer = Tracer {
        scene,
        accel,
        epsilon: whitted::ray_epsilon(scene, camera.eye),
        max_depth: settings.max_depth.max(1),
    };
    let tile_size = settings.tile_size.max(1);
    let tiles = tiles::tiles(grid.width, grid.height, tile_size);
    let start = Instant::now();
    let done = tiles::run(
        pool,
        &tiles,
        |tile| trace_tile::<K, A>(&tracer, &grid, tile, settings),
        on_tile,
    );
    let trace_seconds = start.elapsed().as_secs_f64();

    // Assemble the frame from the tiles.
    let mut frame = Frame::new(grid.width, grid.height);
    for (tile, out) in tiles.iter().zip(&done) {
        for row in 0..tile.height {
            let src = (row * tile.width) as usize..((row + 1) * tile.width) as usize;
            let dst = frame.index(tile.x, tile.y + row);
            let dst = dst..dst + tile.width as usize;
            frame.color[dst.clone()].copy_from_slice(&out.value.color[src.clone()]);
            frame.depth[dst.clone()].copy_from_slice(&out.value.depth[src.clone()]);
            frame.prim[dst].copy_from_slice(&out.value.prim[src]);
        }
    }
    if settings.mode == Mode::Depth {
        frame.color = shade::depth(&frame.depth);
    }
    Render {
        frame,
        tile_seconds: done.iter().map(|d| d.seconds).collect(),
        counts: done.iter().map(|d| d.value.counts).sum(),
        tiles,
        trace_seconds,
        tiles_x: grid.width.div_ceil(tile_size),
    }
}

/// Call `f` on every block of primary rays of a tile, left to right, top to
/// bottom: the rays, the lane mask of pixels inside the tile, and each lane's
/// pixel index within the tile (row-major).
#[inline]
pub fn for_each_block(
    grid: &Grid,
    tile: &Tile,
    block: Block,
    mut f: impl FnMut(&Rays, u32, &[usize; BATCH]),
) {
    let (bw, bh) = block.dims();
    for by in (0..tile.height).step_by(bh as usize) {
        for bx in (0..tile.width).step_by(bw as usize) {
            let mut rays = [grid.ray(tile.x, tile.y); BATCH];
            let mut active = 0u32;
            let mut index = [0usize; BATCH];
            for lane in 0..BATCH as u32 {
                let (x, y) = (bx + lane % bw, by + lane / bw);
                if x < tile.width && y < tile.height {
                    rays[lane as usize] = grid.ray(tile.x + x, tile.y + y);
                    active |= 1 << lane;
                    index[lane as usize] = (y * tile.width + x) as usize;
                }
            }
            f(&rays, active, &index);
        }
    }
}

fn trace_tile<K: TraceKernel, A: Accel>(
    tracer: &Tracer<A>,
    grid: &Grid,
    tile: &Tile,
    settings: &RenderSettings,
) -> TileOut {
    let n = tile.pixels();
    let mut out = TileOut {
        color: vec![Vec3::ZERO; n],
        depth: vec![f32::INFINITY; n],
        prim: vec![crate::ray::NO_HIT; n],
        counts: RayCounts::default(),
    };
    let scene = tracer.scene;
    for_each_block(grid, tile, settings.block, |rays, active, index| {
        let hits = K::intersect(tracer.accel, rays, active);
        out.counts.eye_rays += u64::from(active.count_ones());
        out.counts.eye_hits += lanes(active).filter(|&i| hits[i].is_hit()).count() as u64;
        let color: [Vec3; BATCH] = match settings.mode {
            Mode::Whitted => tracer.shade::<K>(rays, active, &hits, 1, &mut out.counts),
            Mode::Cast => std::array::from_fn(|i| shade::cast(scene, &rays[i], &hits[i])),
            Mode::Normals => std::array::from_fn(|i| shade::normals(scene, &rays[i], &hits[i])),
            Mode::Id => std::array::from_fn(|i| shade::id(&hits[i])),
            // Depth needs the whole image's range: coloured after the trace.
            Mode::Depth => [Vec3::ZERO; BATCH],
        };
        for i in lanes(active) {
            out.color[index[i]] = color[i];
            out.depth[index[i]] = if hits[i].is_hit() {
                hits[i].t
            } else {
                f32::INFINITY
            };
            out.prim[index[i]] = hits[i].prim;
        }
    });
    out
}
