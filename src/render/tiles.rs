//! The image cut into square tiles, traced in parallel by rayon's work-stealing
//! scheduler, each tile timed on its own (the heat map's data).
//!
//! Every tile is one rayon task (`with_max_len(1)`), so an idle thread steals
//! whole tiles from a busy one: expensive regions (glass, mirrors, dense
//! geometry) do not leave a thread waiting at the end of a frame.
//!
//! A tile's time is the CPU time of the thread that traced it
//! (`CLOCK_THREAD_CPUTIME_ID`), not wall-clock time: on a shared machine a
//! thread can be preempted in the middle of a tile, and wall-clock time would
//! then paint a cheap tile as expensive. The frame's total stays wall-clock.

use rayon::prelude::*;

/// A rectangle of pixels `[x, x + width) × [y, y + height)`. 16 bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Tile {
    /// Left column.
    pub x: u32,
    /// Top row.
    pub y: u32,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
}

impl Tile {
    /// Number of pixels.
    pub fn pixels(&self) -> usize {
        self.width as usize * self.height as usize
    }
}

/// The tiles of a `width × height` grid, `size × size` each (smaller along the
/// right and bottom edges), in row-major order: tile `(tx, ty)` is at
/// `ty · tiles_x + tx`.
pub fn tiles(width: u32, height: u32, size: u32) -> Vec<Tile> {
    let size = size.max(1);
    let mut out = Vec::new();
    for y in (0..height).step_by(size as usize) {
        for x in (0..width).step_by(size as usize) {
            out.push(Tile {
                x,
                y,
                width: size.min(width - x),
                height: size.min(height - y),
            });
        }
    }
    out
}

/// CPU seconds used so far by the calling thread.
pub fn thread_cpu_seconds() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec; the clock id is a constant
    // every Linux and BSD kernel provides.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    assert_eq!(rc, 0, "CLOCK_THREAD_CPUTIME_ID is unavailable");
    ts.tv_sec as f64 + 1e-9 * ts.tv_nsec as f64
}

/// The result of one tile and the CPU seconds its closure took. 8 bytes plus `T`.
#[derive(Clone, Debug)]
pub struct Timed<T> {
    /// What the tile's closure returned.
    pub value: T,
    /// CPU seconds the tracing thread spent in the closure.
    pub seconds: f64,
}

/// Run `trace` on every tile inside `pool`, one rayon task per tile; results come
/// back in tile order. `done` is called after each tile (progress reporting).
pub fn run<T: Send>(
    pool: &rayon::ThreadPool,
    tiles: &[Tile],
    trace: impl Fn(&Tile) -> T + Sync,
    done: impl Fn() + Sync,
) -> Vec<Timed<T>> {
    pool.install(|| {
        tiles
            .par_iter()
            .with_max_len(1)
            .map(|tile| {
                let start = thread_cpu_seconds();
                let value = trace(tile);
                let seconds = thread_cpu_seconds() - start;
                done();
                Timed { value, seconds }
            })
            .collect()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_cover_every_pixel_exactly_once() {
        for (w, h, size) in [(37, 21, 8), (16, 16, 16), (5, 3, 16), (64, 48, 1), (100, 7, 7)] {
            let mut seen = vec![0u8; (w * h) as usize];
            for t in tiles(w, h, size) {
                assert!(t.width >= 1 && t.height >= 1 && t.width <= size && t.height <= size);
                for y in t.y..t.y + t.height {
                    for x in t.x..t.x + t.width {
                        seen[(y * w + x) as usize] += 1;
                    }
                }
            }
            assert!(seen.iter().all(|&n| n == 1), "{w}x{h} tiles of {size}");
        }
        assert!(tiles(0, 10, 4).is_empty());
    }

    #[test]
    fn results_come_back_in_tile_order_on_any_thread_count() {
        let grid = tiles(50, 30, 7);
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let count = std::sync::atomic::AtomicUsize::new(0);
            let out = run(
                &pool,
                &grid,
                |t| (t.x, t.y),
                || {
                    count.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                },
            );
            let expected: Vec<(u32, u32)> = grid.iter().map(|t| (t.x, t.y)).collect();
            assert_eq!(out.iter().map(|r| r.value).collect::<Vec<_>>(), expected);
            assert_eq!(count.into_inner(), grid.len());
            assert!(out.iter().all(|r| r.seconds >= 0.0));
        }
    }

    #[test]
    fn thread_cpu_time_counts_work_and_not_sleep() {
        let t0 = thread_cpu_seconds();
        std::thread::sleep(std::time::Duration::from_millis(30));
        let slept = thread_cpu_seconds() - t0;
        let t1 = thread_cpu_seconds();
        let mut x = 0u64;
        while thread_cpu_seconds() - t1 < 0.02 {
            x = std::hint::black_box(x.wrapping_add(1));
        }
        assert!(slept < 0.02, "sleeping used {slept} s of CPU");
        assert!(thread_cpu_seconds() - t1 >= 0.02 && x > 0);
    }
}
