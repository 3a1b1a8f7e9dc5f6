//! Scalar and packet renders trace the same rays and must give the same
//! images: pixel for pixel in `id` and `depth` modes (and the primary hit
//! records behind them), and in every other mode too, with the same ray counts.

use crate::support;
use raypack::accel::BruteForce;
use raypack::render::{Block, KernelKind, Mode, Render, RenderSettings, Sampling, render};
use raypack::scene::Scene;

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
}

fn run(scene: &Scene, settings: RenderSettings, threads: usize) -> Render {
    let camera = scene.camera.unwrap().camera().unwrap();
    render(
        scene,
        &BruteForce::new(&scene.primitives),
        &camera,
        &settings,
        &pool(threads),
        &|| {},
    )
}

fn settings(mode: Mode, kernel: KernelKind, block: Block, tile_size: u32) -> RenderSettings {
    RenderSettings {
        mode,
        kernel,
        block,
        tile_size,
        max_depth: 5,
        sampling: Sampling::PixelCentres,
    }
}

/// Compare two renders bit for bit, naming the first differing pixel.
fn assert_same(a: &Render, b: &Render, what: &str) {
    assert_eq!((a.frame.width, a.frame.height), (b.frame.width, b.frame.height));
    for k in 0..a.frame.prim.len() {
        let (x, y) = (k as u32 % a.frame.width, k as u32 / a.frame.width);
        assert_eq!(
            a.frame.prim[k], b.frame.prim[k],
            "{what}: primitive at ({x}, {y})"
        );
        assert_eq!(
            a.frame.depth[k].to_bits(),
            b.frame.depth[k].to_bits(),
            "{what}: depth at ({x}, {y})"
        );
        assert_eq!(
            a.frame.color[k].to_array().map(f32::to_bits),
            b.frame.color[k].to_array().map(f32::to_bits),
            "{what}: colour at ({x}, {y})"
        );
    }
    assert_eq!(a.frame.to_rgb8(), b.frame.to_rgb8(), "{what}: 8-bit image");
    assert_eq!(a.counts, b.counts, "{what}: ray counts");
}

#[test]
fn scalar_and_packet_renders_are_identical_in_id_and_depth_modes() {
    for seed in 1..=4 {
        let mut scene = support::render::mixed_scene(40, seed);
        scene.camera.as_mut().unwrap().width = 97;
        scene.camera.as_mut().unwrap().height = 61;
        for mode in [Mode::Id, Mode::Depth] {
            for (block, tile) in [(Block::B4x4, 16), (Block::B8x2, 7)] {
                let scalar = run(&scene, settings(mode, KernelKind::Scalar, block, tile), 1);
                let what = format!("seed {seed} {mode:?} {block:?} tile {tile}");
                for kernel in [KernelKind::Packet8, KernelKind::Packet16] {
                    let packet = run(&scene, settings(mode, kernel, block, tile), 2);
                    assert_same(&scalar, &packet, &format!("{what} {kernel:?}"));
                }
                // The image is not trivially empty or full.
                let hits = scalar.frame.prim.iter().filter(|&&p| p != u32::MAX).count();
                assert!(
                    hits > 100 && hits < scalar.frame.prim.len(),
                    "{what}: {hits} hits"
                );
                assert_eq!(scalar.counts.eye_rays, 97 * 61);
                assert_eq!(scalar.counts.eye_hits, hits as u64);
            }
        }
    }
}

#[test]
fn scalar_and_packet_renders_are_identical_in_every_mode() {
    let scene = support::render::mixed_scene(30, 9);
    for mode in [Mode::Cast, Mode::Normals, Mode::Whitted] {
        let scalar = run(&scene, settings(mode, KernelKind::Scalar, Block::B4x4, 16), 2);
        for kernel in [KernelKind::Packet8, KernelKind::Packet16] {
            let packet = run(&scene, settings(mode, kernel, Block::B4x4, 16), 1);
            assert_same(&scalar, &packet, &format!("{mode:?} {kernel:?}"));
        }
    }
    let w = run(
        &scene,
        settings(Mode::Whitted, KernelKind::Packet8, Block::B8x2, 5),
        2,
    );
    // Every secondary ray kind occurs in the mixed scene.
    assert!(
        w.counts.reflect_rays > 0 && w.counts.refract_rays > 0,
        "{:?}",
        w.counts
    );
    assert!(w.counts.shadow_rays > w.counts.shadow_blocked && w.counts.shadow_blocked > 0);
}

#[test]
fn images_do_not_depend_on_threads_tiles_or_blocks() {
    let scene = support::render::mixed_scene(25, 3);
    let reference = run(
        &scene,
        settings(Mode::Whitted, KernelKind::Scalar, Block::B4x4, 64),
        1,
    );
    for (threads, tile, block, kernel) in [
        (2, 1, Block::B8x2, KernelKind::Packet8),
        (3, 5, Block::B4x4, KernelKind::Packet16),
        (2, 16, Block::B8x2, KernelKind::Packet16),
    ] {
        let other = run(&scene, settings(Mode::Whitted, kernel, block, tile), threads);
        assert_same(
            &reference,
            &other,
            &format!("{threads} threads, tile {tile}, {block:?} {kernel:?}"),
        );
        assert_eq!(other.tiles.len(), other.tile_seconds.len());
        assert_eq!(other.tiles.len(), (64usize.div_ceil(tile as usize)).pow(2));
    }
}
