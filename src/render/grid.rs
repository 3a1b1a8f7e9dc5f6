//! The primary rays of a frame: a camera's grid of pixel centres or corners,
//! walked tile by tile in batches of one pixel block.

use crate::camera::Camera;
use crate::ray::Ray;
use crate::render::batch::{BATCH, Rays};
use crate::render::{Block, Sampling, Tile};

/// The primary rays of a camera at pixel centres or corners. 76 bytes.
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

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::render::tiles::tiles;

    fn camera() -> Camera {
        Camera::new(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 60.0, 40.0, 13, 7).unwrap()
    }

    #[test]
    fn centres_and_corners_give_the_cameras_rays() {
        let c = camera();
        let centres = Grid::new(c, Sampling::PixelCentres);
        assert_eq!((centres.width, centres.height), (13, 7));
        assert_eq!(centres.ray(4, 2), c.pixel_ray(4, 2));
        let corners = Grid::new(c, Sampling::PixelCorners);
        assert_eq!((corners.width, corners.height), (14, 8));
        assert_eq!(corners.ray(0, 0), c.ray(0.0, 0.0));
        assert_eq!(corners.ray(13, 7), c.ray(13.0, 7.0));
    }

    #[test]
    fn blocks_cover_every_pixel_of_a_tile_once_with_its_own_ray() {
        let grid = Grid::new(camera(), Sampling::PixelCentres);
        for block in [Block::B4x4, Block::B8x2] {
            for size in [3, 5, 16] {
                for tile in tiles(grid.width, grid.height, size) {
                    let mut seen = vec![0; tile.pixels()];
                    for_each_block(&grid, &tile, block, |rays, active, index| {
                        for lane in (0..BATCH).filter(|l| active >> l & 1 == 1) {
                            let k = index[lane];
                            seen[k] += 1;
                            let (x, y) = (tile.x + k as u32 % tile.width, tile.y + k as u32 / tile.width);
                            assert_eq!(rays[lane], grid.ray(x, y));
                        }
                    });
                    assert!(seen.iter().all(|&n| n == 1), "{block:?} {tile:?}");
                }
            }
        }
    }
}
