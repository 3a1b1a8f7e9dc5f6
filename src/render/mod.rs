//! Rendering: rayon tiles, ray casting and Whitted ray tracing through the
//! scalar or the packet kernels, ray statistics, and timing-annotated images.
//!
//! [`render`] traces a grid of primary rays (pixel centres for images, pixel
//! corners for the SPD's statistics) tile by tile. Inside a tile the rays go in
//! batches of 16, a 4×4 or 8×2 pixel block, through a [`TraceKernel`]: every query
//! of a batch, primary, reflection, refraction or shadow, is one 16-wide packet
//! query with a lane mask (or two 8-wide ones, or 16 scalar queries), and the
//! shading between queries is the same scalar code for every kernel. Scalar and packet renders therefore trace
//! the same rays and give the same images and ray counts.
//!
//! [`render_counted`] also counts the traversal work of every ray ([`counting`]):
//! node visits, primitive tests and SIMD lane use, per tile and optionally per
//! pixel. The counter is a type parameter of the tile loop, so [`render`] (and
//! `bench scene`) compile without it.

pub mod batch;
pub mod counting;
pub mod frame;
pub mod grid;
pub mod kernel;
pub mod optics;
pub mod settings;
pub mod shade;
pub mod spd;
pub mod spd_published;
pub mod stats;
pub mod surface;
pub mod tiles;
pub mod whitted;

use std::time::Instant;

use glam::Vec3;

pub use counting::{Counting, Traversal};
pub use frame::Frame;
pub use grid::{Grid, for_each_block};
pub use kernel::{Packet8Kernel, Packet16Kernel, PacketKernel, ScalarKernel, TraceKernel};
pub use settings::{Block, KernelKind, Mode, RenderSettings, Sampling};
pub use stats::RayCounts;
pub use tiles::Tile;
pub use whitted::Tracer;

use crate::accel::stats::NoStats;
use crate::accel::{Accel, TraversalCounter, TraversalStats};
use crate::camera::Camera;
use crate::scene::Scene;
use batch::BATCH;
use counting::{Tally, TileCounter};
use whitted::lanes;

/// A finished render: the frame, the tiles with their times, the ray counts,
/// the traversal statistics if counted. 304 bytes plus the frame's, the tiles'
/// and the statistics' heap buffers.
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
    /// Traversal statistics of all the render's rays, counted while it was
    /// timed; None when not counted.
    pub traversal: Option<Traversal>,
}

/// Render `scene` through `accel` with `camera` on the threads of `pool`;
/// `on_tile` is called as each tile finishes. Traversal is not counted.
pub fn render<A: Accel>(
    scene: &Scene,
    accel: &A,
    camera: &Camera,
    settings: &RenderSettings,
    pool: &rayon::ThreadPool,
    on_tile: &(dyn Fn() + Sync),
) -> Render {
    render_counted(scene, accel, camera, settings, Counting::Off, pool, on_tile)
}

/// [`render`], counting the traversal work of every ray as `counting` says
/// where the structure reports it ([`Accel::COUNTS_WORK`]; otherwise the
/// render's `traversal` is `None`, as with [`Counting::Off`]).
pub fn render_counted<A: Accel>(
    scene: &Scene,
    accel: &A,
    camera: &Camera,
    settings: &RenderSettings,
    counting: Counting,
    pool: &rayon::ThreadPool,
    on_tile: &(dyn Fn() + Sync),
) -> Render {
    let counting = if A::COUNTS_WORK { counting } else { Counting::Off };
    let inputs = RenderInputs {
        scene,
        accel,
        camera,
        settings,
        pool,
        on_tile,
    };
    match counting {
        Counting::Off => inputs.counted(NoStats),
        Counting::Totals => inputs.counted(TraversalCounter::totals()),
        Counting::PerPixel => inputs.counted(TraversalCounter::per_lane()),
    }
}

/// One render's inputs, on their way to the instantiation of the trace loop
/// for the chosen kernel and counter.
/// (`on_tile` is a trait object so that every caller shares one instantiation
/// per structure: the trace loop is instantiated for every kernel and counter.)
struct RenderInputs<'a, A> {
    scene: &'a Scene,
    accel: &'a A,
    camera: &'a Camera,
    settings: &'a RenderSettings,
    pool: &'a rayon::ThreadPool,
    on_tile: &'a (dyn Fn() + Sync),
}

impl<A: Accel> RenderInputs<'_, A> {
    /// Render counting with a copy of `counter` per tile, through the kernel
    /// the settings name.
    fn counted<C: TileCounter>(self, counter: C) -> Render {
        match self.settings.kernel {
            KernelKind::Scalar => self.traced::<ScalarKernel, C>(counter),
            KernelKind::Packet8 => self.traced::<Packet8Kernel, C>(counter),
            KernelKind::Packet16 => self.traced::<Packet16Kernel, C>(counter),
        }
    }

    /// Render through kernel `K`, counting with a copy of `counter` per tile.
    fn traced<K: TraceKernel, C: TileCounter>(self, counter: C) -> Render {
        let (scene, accel, camera, settings) = (self.scene, self.accel, self.camera, self.settings);
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
            self.pool,
            &tiles,
            |tile| trace_tile::<K, C, A>(&tracer, &grid, tile, settings, counter.clone()),
            self.on_tile,
        );
        let trace_seconds = start.elapsed().as_secs_f64();

        // Assemble the frame (and the pixel costs) from the tiles.
        let mut frame = Frame::new(grid.width, grid.height);
        let per_pixel = counter.counts_per_pixel();
        let mut pixel_cost = vec![0; if per_pixel { frame.prim.len() } else { 0 }];
        for (tile, out) in tiles.iter().zip(&done) {
            for row in 0..tile.height {
                let src = (row * tile.width) as usize..((row + 1) * tile.width) as usize;
                let dst = frame.index(tile.x, tile.y + row);
                let dst = dst..dst + tile.width as usize;
                frame.color[dst.clone()].copy_from_slice(&out.value.color[src.clone()]);
                frame.depth[dst.clone()].copy_from_slice(&out.value.depth[src.clone()]);
                frame.prim[dst.clone()].copy_from_slice(&out.value.prim[src.clone()]);
                if per_pixel {
                    pixel_cost[dst].copy_from_slice(&out.value.cost[src]);
                }
            }
        }
        if settings.mode == Mode::Depth {
            frame.color = shade::depth(&frame.depth);
        }
        let traversal = done
            .iter()
            .map(|d| d.value.traversal)
            .collect::<Option<Vec<_>>>()
            .map(|per_tile| Traversal {
                total: per_tile.iter().fold(TraversalStats::default(), |mut t, s| {
                    t += s;
                    t
                }),
                tiles: per_tile,
                pixel_cost: per_pixel.then_some(pixel_cost),
            });
        Render {
            frame,
            tile_seconds: done.iter().map(|d| d.seconds).collect(),
            counts: done.iter().map(|d| d.value.counts).sum(),
            tiles,
            trace_seconds,
            tiles_x: grid.width.div_ceil(tile_size),
            traversal,
        }
    }
}

/// One tile's pixels, in row-major order within the tile, and what it counted.
/// 216 bytes plus buffers.
struct TileOut {
    color: Vec<Vec3>,
    depth: Vec<f32>,
    prim: Vec<u32>,
    /// Each pixel's traversal cost; empty unless counted per pixel.
    cost: Vec<u64>,
    counts: RayCounts,
    traversal: Option<TraversalStats>,
}

fn trace_tile<K: TraceKernel, C: TileCounter, A: Accel>(
    tracer: &Tracer<A>,
    grid: &Grid,
    tile: &Tile,
    settings: &RenderSettings,
    counter: C,
) -> TileOut {
    let n = tile.pixels();
    let mut color = vec![Vec3::ZERO; n];
    let mut depth = vec![f32::INFINITY; n];
    let mut prim = vec![crate::ray::NO_HIT; n];
    let mut cost = vec![0; if counter.counts_per_pixel() { n } else { 0 }];
    let mut tally = Tally {
        rays: RayCounts::default(),
        traversal: counter,
    };
    let scene = tracer.scene;
    for_each_block(grid, tile, settings.block, |rays, active, index| {
        let hits = K::intersect(tracer.accel, rays, active, &mut tally.traversal);
        tally.rays.eye_rays += u64::from(active.count_ones());
        tally.rays.eye_hits += lanes(active).filter(|&i| hits[i].is_hit()).count() as u64;
        let shaded: [Vec3; BATCH] = match settings.mode {
            Mode::Whitted => tracer.shade::<K, C>(rays, active, &hits, 1, &mut tally),
            Mode::Cast => std::array::from_fn(|i| shade::cast(scene, &rays[i], &hits[i])),
            Mode::Normals => std::array::from_fn(|i| shade::normals(scene, &rays[i], &hits[i])),
            Mode::Id => std::array::from_fn(|i| shade::id(&hits[i])),
            // Depth needs the whole image's range: coloured after the trace.
            Mode::Depth => [Vec3::ZERO; BATCH],
        };
        // The batch's ray trees are done: each lane's cost is its pixel's.
        tally.traversal.end_batch(active, index, &mut cost);
        for i in lanes(active) {
            color[index[i]] = shaded[i];
            depth[index[i]] = if hits[i].is_hit() {
                hits[i].t
            } else {
                f32::INFINITY
            };
            prim[index[i]] = hits[i].prim;
        }
    });
    TileOut {
        color,
        depth,
        prim,
        cost,
        counts: tally.rays,
        traversal: tally.traversal.totals(),
    }
}
