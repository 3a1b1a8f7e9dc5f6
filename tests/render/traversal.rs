//! Traversal statistics counted by the renderer: the totals are those of the
//! same queries made directly, each pixel's cost is its rays' node visits plus
//! primitive tests, counting changes no pixel, and the cost heat map puts the
//! cost where the geometry is.

use crate::support;
use crate::support::cli::{raypack, scratch, stderr};

use glam::Vec3;
use raypack::accel::{Accel, BruteForce, Bvh, TraversalCounter, TraversalStats};
use raypack::camera::Camera;
use raypack::geometry::{Primitive, Sphere};
use raypack::packet::{RayPacket8, RayPacket16};
use raypack::picture::annotate::GAP;
use raypack::picture::heat_map::{HeatMap, HeatMapKind};
use raypack::render::tiles::tiles;
use raypack::render::{
    Block, Counting, Grid, KernelKind, Mode, Render, RenderSettings, Sampling, for_each_block, render,
    render_counted,
};
use raypack::scene::{Light, Scene};

fn pool() -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap()
}

fn settings(mode: Mode, kernel: KernelKind, block: Block) -> RenderSettings {
    RenderSettings {
        mode,
        kernel,
        block,
        tile_size: 16,
        max_depth: 5,
        sampling: Sampling::PixelCentres,
    }
}

/// The totals of tracing every pixel's primary ray on its own, and each ray's cost.
fn scalar_primary<A: Accel>(accel: &A, camera: &Camera) -> (TraversalStats, Vec<u64>) {
    let mut total = TraversalStats::default();
    let mut cost = Vec::new();
    for y in 0..camera.height {
        for x in 0..camera.width {
            let mut one = TraversalCounter::totals();
            accel.intersect_counted(&camera.pixel_ray(x, y), &mut one);
            let one = one.total();
            cost.push(one.nodes_visited + one.prim_tests);
            total += one;
        }
    }
    (total, cost)
}

/// The totals of tracing the primary rays as the renderer's packets: the same
/// tiles and pixel blocks, one masked 16-wide packet per block, or one 8-wide
/// packet per half block that has a pixel.
fn packet_primary<A: Accel>(accel: &A, camera: &Camera, s: &RenderSettings) -> TraversalStats {
    let grid = Grid::new(*camera, s.sampling);
    let mut total = TraversalCounter::totals();
    for tile in tiles(grid.width, grid.height, s.tile_size) {
        for_each_block(&grid, &tile, s.block, |rays, active, _| match s.kernel {
            KernelKind::Packet16 => {
                accel.intersect_packet_counted(&RayPacket16::from_rays_masked(rays, active), &mut total);
            }
            KernelKind::Packet8 => {
                for (half, rays) in rays.chunks(8).enumerate() {
                    let mask = active >> (8 * half) & 0xff;
                    if mask != 0 {
                        accel.intersect_packet_counted(&RayPacket8::from_rays_masked(rays, mask), &mut total);
                    }
                }
            }
            KernelKind::Scalar => unreachable!("packet kernels only"),
        });
    }
    *total.total()
}

/// Render counted per pixel, checking it against the plain and the totals-only
/// renders: counting changes no pixel and no count.
fn counted(scene: &Scene, accel: &impl Accel, camera: &Camera, s: &RenderSettings) -> Render {
    let pool = pool();
    let plain = render(scene, accel, camera, s, &pool, &|| {});
    let totals = render_counted(scene, accel, camera, s, Counting::Totals, &pool, &|| {});
    let per_pixel = render_counted(scene, accel, camera, s, Counting::PerPixel, &pool, &|| {});
    assert!(plain.traversal.is_none());
    for r in [&totals, &per_pixel] {
        assert_eq!(r.frame, plain.frame);
        assert_eq!(r.counts, plain.counts);
    }
    let (t, p) = (totals.traversal.unwrap(), per_pixel.traversal.clone().unwrap());
    assert_eq!(t.total, p.total);
    assert_eq!(t.tiles, p.tiles);
    assert!(t.pixel_cost.is_none());
    assert_eq!(p.tiles.len(), per_pixel.tiles.len());
    let mut sum = TraversalStats::default();
    p.tiles.iter().for_each(|s| sum += s);
    assert_eq!(sum, p.total);
    // Every ray traced is counted once, and the pixels' costs add up to the totals.
    assert_eq!(p.total.rays, per_pixel.counts.total());
    let cost = p.pixel_cost.unwrap();
    assert_eq!(cost.len(), (camera.width * camera.height) as usize);
    assert_eq!(
        cost.iter().sum::<u64>(),
        p.total.nodes_visited + p.total.prim_tests
    );
    per_pixel
}

#[test]
fn ray_casting_counts_equal_the_primary_rays_traced_directly() {
    let mut scene = support::render::mixed_scene(60, 5);
    scene.camera.as_mut().unwrap().width = 53;
    scene.camera.as_mut().unwrap().height = 37;
    let camera = scene.camera.unwrap().camera().unwrap();
    let bvh = Bvh::new(&scene.primitives);
    let brute = BruteForce::new(&scene.primitives);
    for mode in [Mode::Cast, Mode::Depth] {
        for block in [Block::B4x4, Block::B8x2] {
            let what = format!("{mode:?} {block:?}");
            // Scalar: the same totals, and each pixel's cost is its ray's.
            let s = settings(mode, KernelKind::Scalar, block);
            let r = counted(&scene, &bvh, &camera, &s);
            let t = r.traversal.unwrap();
            let (direct, cost) = scalar_primary(&bvh, &camera);
            assert_eq!(t.total, direct, "{what}");
            assert_eq!(t.pixel_cost.unwrap(), cost, "{what}");
            assert_eq!(t.total.packets, 0);
            assert!(t.total.nodes_per_ray() > 1.0, "{what}: {:?}", t.total);

            for kernel in [KernelKind::Packet8, KernelKind::Packet16] {
                let what = format!("{what} {kernel:?}");
                // Packets: the same totals as the same packets traced directly.
                let p = settings(mode, kernel, block);
                let r = counted(&scene, &bvh, &camera, &p);
                let t = r.traversal.unwrap();
                assert_eq!(t.total, packet_primary(&bvh, &camera, &p), "{what}");
                assert_eq!(t.total.rays, u64::from(camera.width * camera.height));
                assert!(t.total.lane_utilisation() > 0.3 && t.total.lane_utilisation() <= 1.0);

                // Brute force: every ray tests every primitive.
                let r = counted(&scene, &brute, &camera, &p);
                let t = r.traversal.unwrap();
                assert_eq!(t.total, packet_primary(&brute, &camera, &p), "{what}");
                assert_eq!(t.total.prims_per_ray(), scene.primitives.len() as f64);
                assert_eq!(t.total.nodes_visited, 0);
            }
        }
    }
}

#[test]
fn whitted_counts_every_ray_of_every_pixel_once() {
    let scene = support::render::mixed_scene(40, 8);
    let camera = scene.camera.unwrap().camera_at(48, 40).unwrap();
    let bvh = Bvh::new(&scene.primitives);
    for kernel in [KernelKind::Scalar, KernelKind::Packet8, KernelKind::Packet16] {
        let r = counted(
            &scene,
            &bvh,
            &camera,
            &settings(Mode::Whitted, kernel, Block::B4x4),
        );
        assert!(r.counts.shadow_rays > 0 && r.counts.reflect_rays > 0 && r.counts.refract_rays > 0);
        let t = r.traversal.unwrap();
        // Secondary and shadow rays cost more than the primary ray alone.
        let (primary, _) = scalar_primary(&bvh, &camera);
        assert!(t.total.nodes_visited > primary.nodes_visited);
    }
}

/// One sphere in the middle of a 40×40 image, lit from the camera's side.
fn one_sphere() -> Scene {
    let mut scene = support::render::with_materials(vec![support::render::material(
        Vec3::new(0.8, 0.2, 0.2),
        0.8,
        0.2,
        20.0,
        0.0,
        1.0,
    )]);
    scene.push(Primitive::Sphere(Sphere::new(Vec3::ZERO, 1.0)), 0);
    scene.lights = vec![Light {
        position: Vec3::new(2.0, 3.0, 8.0),
        color: Vec3::ONE,
    }];
    scene.camera = Some(support::render::camera(Vec3::new(0.0, 0.0, 6.0), Vec3::ZERO, 40));
    scene
}

#[test]
fn pixels_on_the_sphere_cost_more_than_the_background() {
    let scene = one_sphere();
    let camera = scene.camera.unwrap().camera().unwrap();
    sphere_costs_more(&scene, &camera, &BruteForce::new(&scene.primitives));
    sphere_costs_more(&scene, &camera, &Bvh::new(&scene.primitives));
}

/// On `accel`, with either kernel: pixels on the sphere of [`one_sphere`]
/// cost more than the background, and the heat map shows those costs.
fn sphere_costs_more(scene: &Scene, camera: &Camera, accel: &impl Accel) {
    for kernel in [KernelKind::Scalar, KernelKind::Packet8] {
        let r = counted(
            scene,
            accel,
            camera,
            &settings(Mode::Whitted, kernel, Block::B4x4),
        );
        let cost = r.traversal.as_ref().unwrap().pixel_cost.clone().unwrap();
        let on = |k: usize| r.frame.prim[k] != u32::MAX;
        let hits = (0..cost.len()).filter(|&k| on(k)).count();
        assert!(hits > 100 && hits < cost.len() - 100, "{hits}");
        let mean = |want: bool| {
            let c: Vec<u64> = (0..cost.len())
                .filter(|&k| on(k) == want)
                .map(|k| cost[k])
                .collect();
            c.iter().sum::<u64>() as f64 / c.len() as f64
        };
        assert!(
            mean(true) > mean(false),
            "{kernel:?}: {} vs {}",
            mean(true),
            mean(false)
        );
        let costliest = (0..cost.len()).max_by_key(|&k| cost[k]).unwrap();
        assert!(on(costliest), "{kernel:?}: the costliest pixel is background");

        // The heat map shows the same values, brightest on the sphere.
        let hm = HeatMap::pixel_costs(camera.width, camera.height, &cost);
        assert_eq!(hm.max(), cost[costliest] as f64);
        let (x, y) = (costliest as u32 % camera.width, costliest as u32 / camera.width);
        assert_eq!(hm.value(x, y), hm.max());
    }
}

/// One sphere at the origin, seen from +z, as an NFF file.
const SPHERE_NFF: &str = "v\nfrom 0 0 6\nat 0 0 0\nup 0 1 0\nangle 45\nhither 0.01\nresolution 64 64\n\
                          b 0.1 0.1 0.2\nl 2 3 8\nf 0.8 0.2 0.2 0.8 0.2 20 0 1\ns 0 0 0 1\n";

fn luma(p: &image::Rgb<u8>) -> f64 {
    0.299 * f64::from(p.0[0]) + 0.587 * f64::from(p.0[1]) + 0.114 * f64::from(p.0[2])
}

#[test]
fn heatmap_cost_paints_the_sphere_and_the_sidecar_holds_the_counts() {
    let dir = scratch("cost");
    let scene = dir.join("sphere.nff");
    std::fs::write(&scene, SPHERE_NFF).unwrap();
    let (png, json) = (dir.join("cost.png"), dir.join("cost.json"));
    let o = raypack(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
        "--heatmap",
        "cost",
        "--stats-json",
        json.to_str().unwrap(),
        "--threads",
        "2",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let img = image::open(&png).unwrap().to_rgb8();
    // The render, the heat map beside it, the legend, the caption band below.
    assert!(img.width() > 2 * 64 + 2 * GAP && img.height() > 64);
    let heat = |x: u32, y: u32| luma(img.get_pixel(64 + GAP + x, y));
    // The sphere (centre) is hot, the background corner is black.
    assert!(
        heat(32, 32) > heat(1, 1) + 50.0,
        "{} vs {}",
        heat(32, 32),
        heat(1, 1)
    );

    let report: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert_eq!(report["traversal_counted"], true);
    let t = &report["traversal"];
    let rays = t["rays"].as_u64().unwrap();
    assert_eq!(Some(rays), report["rays_total"].as_u64());
    let nodes = t["nodes_visited"].as_u64().unwrap() as f64;
    assert!((t["nodes_per_ray"].as_f64().unwrap() - nodes / rays as f64).abs() < 1e-12);
    assert_eq!(
        report["tiles"]["cost_per_ray"].as_array().unwrap().len(),
        report["tiles"]["ms"].as_array().unwrap().len()
    );

    // Plain `--heatmap` is the time heat map; a bad kind is rejected.
    for (args, ok) in [
        (vec!["--heatmap"], true),
        (vec!["--heatmap", "time"], true),
        (vec!["--heatmap", "nodes"], false),
    ] {
        let out = dir.join("time.png");
        let mut all = vec![
            "render",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--size",
            "32x32",
        ];
        all.extend(args.iter().copied());
        let o = raypack(&all);
        assert_eq!(o.status.success(), ok, "{args:?}: {}", stderr(&o));
        if !ok {
            assert_eq!(o.status.code(), Some(2));
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn traversal_stats_can_be_left_out_but_not_under_a_cost_heat_map() {
    let dir = scratch("off");
    let scene = dir.join("sphere.nff");
    std::fs::write(&scene, SPHERE_NFF).unwrap();
    let (png, json) = (dir.join("off.png"), dir.join("off.json"));
    let o = raypack(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
        "--no-traversal-stats",
        "--stats-json",
        json.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert_eq!(report["traversal_counted"], false);
    assert!(report["traversal"].is_null());
    assert!(report["tiles"]["cost_per_ray"].is_null());

    // A cost heat map without counts, or through Embree: a clear error, no file.
    let out = dir.join("cost.png");
    for extra in [["--no-traversal-stats"], ["--engine=embree"]] {
        let mut args = vec![
            "render",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--heatmap",
            "cost",
        ];
        args.extend(extra);
        let o = raypack(&args);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", stderr(&o));
        assert!(
            stderr(&o).contains("cost heat map needs raypack's traversal statistics"),
            "{}",
            stderr(&o)
        );
        assert!(!out.exists());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_cost_heat_map_is_refused_without_pixel_costs() {
    let scene = one_sphere();
    let camera = scene.camera.unwrap().camera().unwrap();
    let accel = Bvh::new(&scene.primitives);
    let s = settings(Mode::Cast, KernelKind::Packet8, Block::B4x4);
    let plain = render(&scene, &accel, &camera, &s, &pool(), &|| {});
    let info = raypack::picture::render_report::RunInfo {
        engine: raypack::engines::Engine::Raypack,
        kernel: s.kernel,
        block: s.block,
        mode: s.mode,
        accel: "bvh",
        settings: "raypack 0.1.0, bvh".to_string(),
        threads: 2,
        tile_size: 16,
        max_depth: 5,
        load_seconds: 0.0,
        setup_seconds: 0.0,
        headlight: false,
    };
    let report = raypack::picture::render_report::RenderReport::new(&scene, &plain, &info);
    assert!(
        report
            .caption()
            .join("\n")
            .contains("traversal stats: not counted")
    );
    let e =
        raypack::picture::annotate::annotate_render(&plain, &report, Some(HeatMapKind::Cost)).unwrap_err();
    assert!(e.to_string().contains("traversal statistics"), "{e}");
    assert!(raypack::picture::annotate::annotate_render(&plain, &report, Some(HeatMapKind::Time)).is_ok());
}
