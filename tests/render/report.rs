//! The numbers around a render: the JSON sidecar and caption, the annotated
//! image, and the scene benchmark's measurements.

use crate::support;
use raypack::accel::BruteForce;
use raypack::bench::scene::{PrimaryFrame, Variant, measure};
use raypack::bench::timing_hooks::TimingHooks;
use raypack::engines::Engine;
use raypack::picture::annotate::annotate_render;
use raypack::picture::heat_map::HeatMapKind;
use raypack::picture::render_report::{RenderReport, RunInfo};
use raypack::render::{Block, Counting, KernelKind, Mode, RenderSettings, Sampling, render_counted};

#[test]
fn sidecar_caption_and_image_carry_the_same_numbers() {
    let scene = support::render::mixed_scene(20, 4);
    let camera = scene.camera.unwrap().camera_at(80, 40).unwrap();
    let settings = RenderSettings {
        mode: Mode::Whitted,
        kernel: KernelKind::Packet8,
        block: Block::B8x2,
        tile_size: 16,
        max_depth: 4,
        sampling: Sampling::PixelCentres,
    };
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    let out = render_counted(
        &scene,
        &BruteForce::new(&scene.primitives),
        &camera,
        &settings,
        Counting::Totals,
        &pool,
        &|| {},
    );
    let info = RunInfo {
        engine: Engine::Raypack,
        kernel: settings.kernel,
        block: settings.block,
        mode: settings.mode,
        accel: "none",
        settings: "raypack 0.1.0, none".to_string(),
        threads: 2,
        tile_size: 16,
        max_depth: 4,
        load_seconds: 0.001,
        setup_seconds: 0.002,
        headlight: false,
    };
    let report = RenderReport::new(&scene, &out, &info);
    let json: serde_json::Value = serde_json::to_value(&report).unwrap();
    assert_eq!(json["scene"], "mixed-20-4");
    assert_eq!(json["engine"], "raypack");
    assert_eq!(json["kernel"], "packet8");
    assert_eq!(json["block"], "8x2");
    assert_eq!(json["mode"], "whitted");
    assert_eq!(
        (json["width"].as_u64(), json["height"].as_u64()),
        (Some(80), Some(40))
    );
    assert_eq!(json["rays"]["eye_rays"], 3200);
    assert_eq!(json["rays_total"].as_u64(), Some(out.counts.total()));
    assert_eq!(json["primitives"].as_u64(), Some(scene.primitives.len() as u64));
    assert_eq!(json["primitive_kinds"]["sphere"], 20);
    assert!((json["setup_ms"].as_f64().unwrap() - 2.0).abs() < 1e-9);
    // 80x40 in 16px tiles: 5 columns, 3 rows.
    assert_eq!(
        (json["tiles"]["columns"].as_u64(), json["tiles"]["rows"].as_u64()),
        (Some(5), Some(3))
    );
    assert_eq!(json["tiles"]["ms"].as_array().unwrap().len(), 15);
    let mrays = out.counts.total() as f64 / out.trace_seconds / 1e6;
    assert!((json["mrays_per_s"].as_f64().unwrap() - mrays).abs() < 1e-9 * mrays.max(1.0));

    let caption = report.caption().join("\n");
    for needle in [
        "mixed-20-4".to_string(),
        "80x40".to_string(),
        "packet8".to_string(),
        "threads: 2".to_string(),
        format!("eye {}", out.counts.eye_rays),
        format!("shadow {}", out.counts.shadow_rays),
        format!("reflect {}", out.counts.reflect_rays),
        format!("{:.2} Mrays/s", report.mrays_per_s),
        format!(
            "traversal, counted in this render, brute force: {}",
            out.traversal.as_ref().unwrap().total.caption()
        ),
    ] {
        assert!(caption.contains(&needle), "caption lacks {needle:?}:\n{caption}");
    }

    // The traversal object: raw counters and the ratios derived from them.
    let traversal = out.traversal.as_ref().unwrap();
    let t = &json["traversal"];
    assert_eq!(json["traversal_counted"], true);
    assert_eq!(t["rays"].as_u64(), Some(out.counts.total()));
    assert_eq!(t["nodes_visited"].as_u64(), Some(traversal.total.nodes_visited));
    for key in [
        "packets",
        "prim_tests",
        "simd_steps",
        "simd_active_lanes",
        "simd_lane_slots",
        "fallback_rays",
    ] {
        assert!(t[key].is_u64(), "{key}: {t}");
    }
    let ratio = |a: &str, b: &str| t[a].as_u64().unwrap() as f64 / t[b].as_u64().unwrap() as f64;
    let close = |key: &str, want: f64| {
        let got = t[key].as_f64().unwrap();
        assert!(
            (got - want).abs() <= 1e-12 * want.abs().max(1.0),
            "{key}: {got} vs {want}"
        );
    };
    close("nodes_per_ray", ratio("nodes_visited", "rays"));
    close("prims_per_ray", ratio("prim_tests", "rays"));
    close("lane_utilisation", ratio("simd_active_lanes", "simd_lane_slots"));
    // Brute force: no nodes, every packet lane tests primitives.
    assert_eq!(t["nodes_visited"], 0);
    assert!(t["prims_per_ray"].as_f64().unwrap() > 1.0);
    assert!(t["lane_utilisation"].as_f64().unwrap() > 0.0 && t["lane_utilisation"].as_f64().unwrap() <= 1.0);
    let tile_costs = json["tiles"]["cost_per_ray"].as_array().unwrap();
    assert_eq!(tile_costs.len(), 15);
    for (c, s) in tile_costs.iter().zip(&traversal.tiles) {
        assert_eq!(c.as_f64(), Some(s.cost_per_ray()));
    }

    assert_eq!(json["settings"], "raypack 0.1.0, none");
    // Another engine's caption names its own settings (Embree's kernels and
    // mode), not raypack's instruction set.
    let embree_info = RunInfo {
        engine: Engine::Embree,
        accel: "embree",
        settings: "Embree 4.4.0 \"threads=1,isa=avx2\", fast".to_string(),
        ..info.clone()
    };
    let embree_caption = RenderReport::new(&scene, &out, &embree_info).caption()[0].clone();
    assert!(
        embree_caption.contains("(8x2 blocks)  accel: Embree 4.4.0 \"threads=1,isa=avx2\", fast"),
        "{embree_caption}"
    );
    assert!(
        caption.contains(&format!("(8x2 blocks, {})  accel: none", report.isa)),
        "{caption}"
    );

    let plain = annotate_render(&out, &report, None).unwrap();
    let heat = annotate_render(&out, &report, Some(HeatMapKind::Time)).unwrap();
    // Counted in total only: no per-pixel costs for a cost heat map.
    assert!(annotate_render(&out, &report, Some(HeatMapKind::Cost)).is_err());
    assert_eq!(plain.width(), 80);
    assert!(plain.height() > 40);
    assert!(heat.width() > 160);
    // The render sits unchanged in the top-left corner of both.
    let picture = out.frame.to_rgb8();
    for (x, y) in [(0, 0), (79, 39), (40, 20)] {
        assert_eq!(plain.get_pixel(x, y), picture.get_pixel(x, y));
        assert_eq!(heat.get_pixel(x, y), picture.get_pixel(x, y));
    }
}

#[test]
fn scene_bench_measures_every_variant_on_the_same_rays() {
    let scene = support::render::sphere_cloud(40, 3, 64);
    let camera = scene.camera.unwrap().camera().unwrap();
    let frame = PrimaryFrame::new(&camera, 16);
    let mut variants = Vec::new();
    for kernel in [KernelKind::Scalar, KernelKind::Packet8] {
        for block in [Block::B4x4, Block::B8x2] {
            for threads in [1, 2] {
                variants.push(Variant {
                    kernel,
                    block,
                    threads,
                });
            }
        }
    }
    let timings = measure(
        &BruteForce::new(&scene.primitives),
        &frame,
        &variants,
        2,
        &TimingHooks::default(),
    )
    .unwrap();
    assert_eq!(timings.len(), 8);
    let hits = timings[0].hits;
    assert!(hits > 0 && hits < 64 * 64);
    for (t, v) in timings.iter().zip(&variants) {
        assert_eq!(t.variant, *v);
        assert_eq!(t.rays, 64 * 64);
        assert_eq!(t.hits, hits);
        assert_eq!(t.seconds.len(), 2, "every run is kept");
        assert!(t.seconds.iter().all(|&s| s > 0.0));
        let m = t.mrays_per_s();
        assert_eq!(m.samples, 2);
        assert!(m.ci_low > 0.0 && m.ci_low <= m.median && m.median <= m.ci_high);
    }
}
