//! The `render`, `stats` and `bench scene` command lines: bad input is a clear
//! error with exit code 2 and leaves no file behind; every scene file shipped
//! in `scenes/` renders in every mode.

use std::path::{Path, PathBuf};

use crate::support::cli::{raypack, scratch, stderr};

use raypack::accel::BruteForce;
use raypack::render::{Block, KernelKind, Mode, RenderSettings, Sampling, render};

#[test]
fn an_output_path_that_cannot_be_written_is_a_clear_error() {
    let dir = scratch("unwritable");
    let missing = dir.join("no/such/dir/out.png");
    let o = raypack(&["render", "scene.nff", "-o", missing.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains(missing.to_str().unwrap()) && e.contains("does not exist"),
        "{e}"
    );

    // A directory as output.
    let o = raypack(&["render", "scene.nff", "-o", dir.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("cannot write"), "{}", stderr(&o));

    // Not a PNG name.
    let jpg = dir.join("out.jpg");
    let o = raypack(&["render", "scene.nff", "-o", jpg.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains(".png"), "{}", stderr(&o));

    // An unwritable sidecar path fails too, before any work.
    let o = raypack(&[
        "render",
        "scene.nff",
        "-o",
        dir.join("ok.png").to_str().unwrap(),
        "--stats-json",
        missing.with_extension("json").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("out.json"), "{}", stderr(&o));
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0, "files left behind");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_scene_that_cannot_be_read_leaves_no_output_file() {
    let dir = scratch("bad-scene");
    let out = dir.join("out.png");
    let o = raypack(&[
        "render",
        dir.join("missing.nff").to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("missing.nff"), "{}", stderr(&o));
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0, "files left behind");
    for args in [
        vec!["stats", "missing.nff", "--spd"],
        vec!["bench", "scene", "missing.nff"],
    ] {
        let o = raypack(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_options_are_rejected() {
    for args in [
        vec!["render", "s.nff", "--tile", "0"],
        vec!["render", "s.nff", "--size", "0x10"],
        vec!["render", "s.nff", "--size", "100"],
        vec!["render", "s.nff", "--kernel", "packet32"],
        vec!["render", "s.nff", "--block", "4x2"],
        vec!["render", "s.nff", "--depth", "0"],
        vec!["bench", "scene", "s.nff", "--threads", "1,0"],
        vec!["stats", "s.nff"],
    ] {
        let o = raypack(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
    }
}

/// The scene files of the repository (none until the loaders land).
fn scene_files() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    assert!(!files.is_empty(), "no scene files in {}", dir.display());
    files
}

#[test]
fn every_scene_file_renders_in_every_mode() {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    for path in scene_files() {
        let scene = raypack::scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let spec = scene.camera.unwrap_or_else(|| scene.default_camera());
        // Small images: every mode on every scene, with brute force.
        let camera = spec.camera_at(48, 48).unwrap();
        let accel = BruteForce::new(&scene.primitives);
        for mode in [Mode::Cast, Mode::Normals, Mode::Depth, Mode::Id, Mode::Whitted] {
            let settings = RenderSettings {
                mode,
                kernel: KernelKind::Packet8,
                block: Block::B4x4,
                tile_size: 16,
                max_depth: 5,
                sampling: Sampling::PixelCentres,
            };
            let r = render(&scene, &accel, &camera, &settings, &pool, &|| {});
            assert_eq!(r.counts.eye_rays, 48 * 48, "{} {mode:?}", path.display());
            assert!(
                r.frame.color.iter().all(|c| c.is_finite()),
                "{} {mode:?}",
                path.display()
            );
        }
    }
}

#[test]
fn the_first_scene_file_renders_through_the_command_line_with_a_sidecar() {
    let path = scene_files().swap_remove(0);
    let dir = scratch("first-scene");
    let (png, json) = (dir.join("out.png"), dir.join("out.json"));
    let o = raypack(&[
        "render",
        path.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
        "--size",
        "64x48",
        "--heatmap",
        "--stats-json",
        json.to_str().unwrap(),
        "--threads",
        "2",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let img = image::open(&png).unwrap();
    assert!(img.width() > 2 * 64 && img.height() > 48);
    let report: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert_eq!(report["width"], 64);
    assert_eq!(report["rays"]["eye_rays"], 64 * 48);
    assert_eq!(report["threads"], 2);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn every_kernel_renders_the_same_counts_through_the_command_line() {
    let path = scene_files().swap_remove(0);
    let dir = scratch("kernels");
    let mut seen = Vec::new();
    for (kernel, block) in [("scalar", "4x4"), ("packet8", "8x2"), ("packet16", "4x4")] {
        let json = dir.join(format!("{kernel}.json"));
        let o = raypack(&[
            "render",
            path.to_str().unwrap(),
            "-o",
            dir.join(format!("{kernel}.png")).to_str().unwrap(),
            "--size",
            "40x30",
            "--kernel",
            kernel,
            "--block",
            block,
            "--stats-json",
            json.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{kernel}: {}", stderr(&o));
        let report: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
        assert_eq!(report["kernel"], kernel);
        assert_eq!(report["block"], block);
        seen.push(report["rays"].clone());
    }
    assert!(seen.iter().all(|r| *r == seen[0]), "{seen:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[cfg(not(feature = "embree"))]
#[test]
fn asking_for_embree_without_the_feature_is_a_clear_error() {
    let dir = scratch("no-embree");
    let out = dir.join("x.png");
    let o = raypack(&[
        "render",
        "scenes/lecture.toml",
        "-o",
        out.to_str().unwrap(),
        "--engine",
        "embree",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("embree"), "{}", stderr(&o));
    assert!(!out.exists());
}

#[test]
fn stats_prints_the_spd_counts_as_json_and_the_traversal_work_on_stderr() {
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/spd_tetra_small.nff");
    for accel in ["bvh", "none"] {
        let o = raypack(&["stats", scene, "--spd", "--accel", accel]);
        assert!(o.status.success(), "{}", stderr(&o));
        let counts: serde_json::Value = serde_json::from_slice(&o.stdout).expect("JSON on stdout");
        let keys = [
            "eye_rays",
            "eye_hits",
            "reflect_rays",
            "refract_rays",
            "total_internal_reflections",
            "shadow_rays",
            "shadow_blocked",
        ];
        for key in keys {
            assert!(counts[key].is_u64(), "{key}: {counts}");
        }
        assert_eq!(counts["eye_rays"], 513 * 513);
        let e = stderr(&o);
        assert!(
            e.contains("traversal, counted in this run:") && e.contains("prims/ray"),
            "{e}"
        );
        // Brute force visits no nodes; the BVH does.
        assert_eq!(e.contains(" 0.0 nodes/ray"), accel == "none", "{e}");
    }
}

/// A scene without lights (here a PLY mesh, which cannot carry any) gets a
/// headlight at the eye in whitted mode: said on stderr, in the caption's
/// light count and in the sidecar, and it lights the surface the eye sees.
/// `--no-headlight` leaves the scene unlit (ambient only, a darker image).
#[test]
fn a_scene_without_lights_gets_a_headlight_unless_told_not_to() {
    let dir = scratch("headlight");
    let ply = dir.join("quad.ply");
    std::fs::write(
        &ply,
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
         element face 2\nproperty list uchar int vertex_indices\nend_header\n\
         -1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n3 0 1 2\n3 0 2 3\n",
    )
    .unwrap();
    let brightness = |extra: &[&str]| {
        let (png, json) = (dir.join("out.png"), dir.join("out.json"));
        let mut args = vec!["render", ply.to_str().unwrap(), "-o", png.to_str().unwrap()];
        args.extend([
            "--size",
            "32x32",
            "--no-caption",
            "--stats-json",
            json.to_str().unwrap(),
        ]);
        args.extend(extra);
        let o = raypack(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        let report: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
        let image = image::open(&png).unwrap().to_luma8();
        let mean = image.pixels().map(|p| f64::from(p.0[0])).sum::<f64>() / 1024.0;
        (stderr(&o), report, mean)
    };
    let (lit_err, lit, lit_mean) = brightness(&[]);
    assert!(lit_err.contains("headlight"), "{lit_err}");
    assert_eq!(
        (lit["lights"].as_u64(), lit["headlight"].as_bool()),
        (Some(1), Some(true))
    );
    let (dark_err, dark, dark_mean) = brightness(&["--no-headlight"]);
    assert!(!dark_err.contains("headlight"), "{dark_err}");
    assert_eq!(
        (dark["lights"].as_u64(), dark["headlight"].as_bool()),
        (Some(0), Some(false))
    );
    assert!(lit_mean > 2.0 * dark_mean, "lit {lit_mean} vs unlit {dark_mean}");
    // Other modes need no light and get none.
    let (_, normals, _) = brightness(&["--mode", "normals"]);
    assert_eq!(normals["lights"].as_u64(), Some(0));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// An image larger than the memory its buffers need is refused up front
/// (exit 2), and nothing is left beside the target.
#[test]
fn an_image_too_large_for_memory_is_refused_before_any_work() {
    let dir = scratch("huge");
    let out = dir.join("huge.png");
    let o = raypack(&[
        "render",
        "scenes/spd_tetra_small.nff",
        "--size",
        "65536x65536",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("needs about 206.2 GB"), "{}", stderr(&o));
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0, "nothing written");
}

/// A render stopped by SIGTERM (as `timeout` sends) or SIGINT (Ctrl-C)
/// removes its temporary outputs and exits with 128 + the signal.
#[test]
fn a_render_stopped_by_a_signal_leaves_no_temporary_behind() {
    for (signal, name) in [(libc::SIGTERM, "term"), (libc::SIGINT, "int")] {
        let dir = scratch(&format!("signal-{name}"));
        let out = dir.join("gears.png");
        let json = dir.join("gears.json");
        // Long enough to be in flight when the signal comes: SPD gears at
        // 4000x4000 on one thread takes tens of seconds.
        let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_raypack"))
            .args(["render", "gen:gears", "--size", "4000x4000", "--threads", "1"])
            .args([
                "-o",
                out.to_str().unwrap(),
                "--stats-json",
                json.to_str().unwrap(),
            ])
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        // Wait until both temporaries exist, i.e. the render has claimed its outputs.
        let temporaries = || {
            std::fs::read_dir(&dir)
                .unwrap()
                .filter(|e| {
                    e.as_ref()
                        .unwrap()
                        .file_name()
                        .to_string_lossy()
                        .ends_with(".tmp")
                })
                .count()
        };
        let start = std::time::Instant::now();
        while temporaries() < 2 {
            assert!(
                start.elapsed().as_secs() < 60,
                "the render never claimed its outputs"
            );
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        // SAFETY: `kill` only sends a signal to the child we spawned and still own.
        assert_eq!(unsafe { libc::kill(child.id() as i32, signal) }, 0);
        let status = child.wait().unwrap();
        assert_eq!(status.code(), Some(128 + signal), "{name}: {status:?}");
        let left: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert!(left.is_empty(), "{name}: left behind {left:?}");
    }
}
