//! Renders the scenes built in `tests/render_support` into timing-annotated PNGs (the
//! README's pictures), through the same library calls as `raypack render`:
//! `cargo run --release --example render_demo -- OUT_DIR`.

#[path = "../tests/render_support/mod.rs"]
mod render_support;

use std::path::PathBuf;

use raypack::accel::BruteForce;
use raypack::render::annotate::annotate_render;
use raypack::render::output::{AtomicFile, png_bytes};
use raypack::render::report::{RenderReport, RunInfo};
use raypack::render::{Block, KernelKind, Mode, RenderSettings, Sampling, render};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| "docs".into()));
    let pool = rayon::ThreadPoolBuilder::new().build()?;
    let mut mixed = render_support::mixed_scene(60, 5);
    mixed.source = "mixed (60 spheres, glass, mirrors)".into();
    let mut cloud = render_support::sphere_cloud(300, 1, 512);
    cloud.source = "300 spheres".into();
    let jobs = [
        (&mixed, Mode::Whitted, KernelKind::Packet8, 512, "whitted"),
        (&mixed, Mode::Normals, KernelKind::Packet8, 384, "normals"),
        (&cloud, Mode::Cast, KernelKind::Scalar, 384, "cast-scalar"),
        (&cloud, Mode::Cast, KernelKind::Packet8, 384, "cast-packet8"),
    ];
    for (scene, mode, kernel, size, name) in jobs {
        let camera = scene.camera.unwrap().camera_at(size, size)?;
        let settings = RenderSettings {
            mode,
            kernel,
            block: Block::B4x2,
            tile_size: 16,
            max_depth: 5,
            sampling: Sampling::PixelCentres,
        };
        let accel = BruteForce::new(&scene.primitives);
        let out = render(scene, &accel, &camera, &settings, &pool, || {});
        let info = RunInfo {
            kernel,
            block: settings.block,
            mode,
            accel: "none",
            threads: pool.current_num_threads(),
            tile_size: settings.tile_size,
            max_depth: settings.max_depth,
            load_seconds: 0.0,
            setup_seconds: 0.0,
        };
        let report = RenderReport::new(scene, &out, &info);
        let path = dir.join(format!("render-{name}.png"));
        AtomicFile::create(&path)?.commit(&png_bytes(&annotate_render(&out, &report, true)))?;
        println!(
            "{}: {:.1} ms, {:.2} Mrays/s",
            path.display(),
            report.trace_ms,
            report.mrays_per_s
        );
    }
    Ok(())
}
