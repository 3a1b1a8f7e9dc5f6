//! `raypack check` and `raypack trace --engine embree` end to end.

use std::process::Command;

use crate::support::cli::{TINY_TRAVERSAL, scratch, stderr};

use raypack::compare::csv::format_rays;
use raypack::compare::random_rays;
use raypack::scene::generate::test_scenes;

fn raypack() -> Command {
    Command::new(env!("CARGO_BIN_EXE_raypack"))
}

/// The JSON report of `check SCENE` on `n` random rays and primary rays of
/// `size`, which must pass its bars.
fn check_json(scene: &str, n: usize, size: &str) -> serde_json::Value {
    let output = raypack()
        .args(["check", scene, "--n", &n.to_string(), "--size", size, "--json"])
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", stderr(&output));
    serde_json::from_slice(&output.stdout).unwrap()
}

#[test]
fn check_reports_agreement_and_exits_by_the_bars() {
    let report = check_json("gen:mixed:200:7", 20000, "96x64");
    let sets = report["sets"].as_array().unwrap();
    assert_eq!(sets.len(), 2);
    assert_eq!(sets[0]["count"], 96 * 64);
    assert_eq!(sets[1]["count"], 20000);
    for set in sets {
        assert!(set["hit_agreement"].as_f64().unwrap() >= 0.9999);
        assert!(set["agreement"]["t_error"]["p99"].as_f64().unwrap() <= 1e-5);
    }
    assert_eq!(report["engines"], serde_json::json!(["raypack", "embree"]));
    assert_eq!(report["engine"]["translation"]["user"], 3, "the three planes");

    // An impossible bar: exit 1 and say which set failed.
    let output = raypack()
        .args([
            "check",
            "gen:spheres:100:7",
            "--rays",
            "random",
            "--n",
            "5000",
            "--max-t-error",
            "0",
        ])
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("agreement below the bars") && stderr.contains("random"),
        "{stderr}"
    );
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        stdout.contains("t error") && stdout.contains("5000 random rays"),
        "{stdout}"
    );
}

/// `check` on a scene of 10⁹ instanced triangles: both engines trace it
/// through their instances, and the classifier places the primitives it needs
/// one at a time (flattened, the scene is too large to make).
#[test]
fn check_compares_instances_without_flattening_the_scene() {
    let report = check_json("gen:forest:56000", 20000, "64x64");
    for set in report["sets"].as_array().unwrap() {
        assert!(set["hit_agreement"].as_f64().unwrap() >= 0.9999, "{set}");
        assert!(set["agreement"]["same_primitive"].as_u64().unwrap() > 0, "{set}");
    }
}

/// Two squares sharing the edge x = 0 of the plane z = 0, seen head-on by a
/// 7×7 camera: the middle column of pixel centres hits the shared edge exactly.
const SHARED_EDGE_NFF: &str = "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 45\nhither 0.01\nresolution 7 7\n\
b 0 0 0\nl 0 0 10\nf 1 1 1 0.8 0.2 10 0 1\n\
p 4\n-1 -1 0\n0 -1 0\n0 1 0\n-1 1 0\np 4\n0 -1 0\n1 -1 0\n1 1 0\n0 1 0\n";

#[test]
fn check_classifies_a_shared_edge_as_a_tie_in_counts_json_and_diff_image() {
    let dir = scratch("check-shared-edge");
    let scene = dir.join("edge.nff");
    std::fs::write(&scene, SHARED_EDGE_NFF).unwrap();
    let png = dir.join("diff.png");
    let output = raypack()
        .arg("check")
        .arg(&scene)
        .args([
            "--triangle",
            "barycentric",
            "--rays",
            "primary",
            "--json",
            "--diff-image",
        ])
        .arg(&png)
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", stderr(&output));
    let report: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let set = &report["sets"][0];
    let classes = &set["classes"];
    // On the edge each engine may pick either square: raypack's crossing test
    // (`--triangle barycentric`) the one right of it (the half-open rule),
    // Embree (4.4.0) the other on the 3 pixels whose rays meet the edge.
    // (Under the watertight pieces both take the lower index here.)
    let ties = classes["edge_tie"].as_u64().unwrap();
    assert!(ties >= 1, "no tie seen: {set:#}");
    for class in ["hit_miss", "coincident", "different_primitive", "t_beyond_ulps"] {
        assert_eq!(classes[class], 0, "{class}: {set:#}");
    }
    for d in set["agreement"]["disagreements"].as_array().unwrap() {
        assert_eq!(d["kind"], "tie", "{d}");
        assert_eq!(d["origin"][0], 0.0, "on the middle column: {d}");
    }
    assert!(report["environment"]["cpu_model"].is_string(), "{report:#}");
    assert_eq!(report["max_ulps"], 16);

    // The picture: the render is 7×7 (the caption band below it); the tie
    // pixels are blue, in the middle column.
    let img = image::open(&png).unwrap().to_rgb8();
    let blue = raypack::compare::diff_image::colour(raypack::compare::DisagreementKind::Tie);
    let marked: Vec<(u32, u32)> = (0..7)
        .flat_map(|y| (0..7).map(move |x| (x, y)))
        .filter(|&(x, y)| *img.get_pixel(x, y) == blue)
        .collect();
    assert_eq!(marked.len() as u64, ties, "{marked:?}");
    assert!(marked.iter().all(|&(x, _)| x == 3), "{marked:?}");

    // The same on random rays only is bad input (exit 2), and so is a non-PNG name.
    let output = raypack()
        .arg("check")
        .arg(&scene)
        .args(["--rays", "random", "--diff-image"])
        .arg(&png)
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(2));
    assert!(stderr(&output).contains("primary"));
    let output = raypack()
        .arg("check")
        .arg(&scene)
        .args(["--diff-image"])
        .arg(dir.join("diff.jpg"))
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(2));
    assert!(!dir.join("diff.jpg").exists());
}

#[test]
fn trace_through_embree_matches_raypack_on_the_same_file() {
    let dir = scratch("embree-trace");
    let scene = test_scenes::by_name("transformed", 150, 2).unwrap();
    std::fs::write(
        dir.join("rays.csv"),
        format_rays(&random_rays(scene.bounds(), 2000, 4)),
    )
    .unwrap();
    let trace = |engine: &str, kernel: &str| {
        let out = dir.join(format!("{engine}-{kernel}.csv"));
        let o = crate::support::cli::trace(
            "gen:transformed:150:2",
            &dir.join("rays.csv"),
            &out,
            &["--engine", engine, "--kernel", kernel],
        );
        assert!(o.status.success(), "{}", stderr(&o));
        std::fs::read_to_string(out).unwrap()
    };
    let raypack_hits = trace("raypack", "packet8");
    for kernel in ["scalar", "packet8"] {
        let embree_hits = trace("embree", kernel);
        let (mut same, mut total) = (0, 0);
        for (a, b) in raypack_hits.lines().zip(embree_hits.lines()).skip(1) {
            let (ta, pa) = a.split_once(',').unwrap();
            let (tb, pb) = b.split_once(',').unwrap();
            total += 1;
            if pa == pb {
                same += 1;
                let (ta, tb): (f32, f32) = (ta.parse().unwrap(), tb.parse().unwrap());
                assert!(ta == tb || (ta - tb).abs() <= 1e-3 * ta, "{a} vs {b}");
            }
        }
        assert_eq!(total, 2000);
        assert!(same >= 1999, "{same} of {total} agree ({kernel})");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn render_and_bench_scene_run_through_embree() {
    let dir = std::env::temp_dir().join(format!("raypack-embree-render-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let png = dir.join("lecture.png");
    let json = dir.join("lecture.json");
    // `render --engine embree` with `extra` arguments, writing `png` and `json`.
    let render = |extra: &[&str], png: &std::path::Path| {
        raypack()
            .args([
                "render",
                "scenes/lecture.toml",
                "-o",
                png.to_str().unwrap(),
                "--size",
                "64x48",
            ])
            .args(["--engine", "embree", "--stats-json", json.to_str().unwrap()])
            .args(extra)
            .output()
            .unwrap()
    };
    let o = render(&[], &png);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(png.exists());
    let report = std::fs::read_to_string(&json).unwrap();
    assert!(report.contains("embree"), "{report}");
    // Embree reports no traversal work: no counts rather than zeros.
    let parsed: serde_json::Value = serde_json::from_str(&report).unwrap();
    assert!(parsed["traversal"].is_null(), "{report}");
    assert_eq!(parsed["traversal_counted"], false);
    // The settings it ran with: the default pairing, Embree's AVX2 kernels.
    let settings = parsed["settings"].as_str().unwrap();
    assert!(settings.contains("\"threads=1,isa=avx2\", fast"), "{settings}");

    // Embree's own choice of kernels, robust mode; a configuration Embree
    // refuses is a clear error, with nothing written.
    let o = render(&["--embree-config", "threads=1", "--embree-mode", "robust"], &png);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let parsed: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let settings = parsed["settings"].as_str().unwrap();
    assert!(settings.contains("\"threads=1\", robust"), "{settings}");
    let refused = dir.join("refused.png");
    let o = render(&["--embree-config", "threads=abc"], &refused);
    assert_eq!(o.status.code(), Some(2), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("threads=abc"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(!refused.exists());

    let o = raypack()
        .args([
            "bench",
            "scene",
            "scenes/lecture.toml",
            "--size",
            "32x32",
            "--runs",
            "1",
        ])
        .args(["--threads", "1", "--engine", "raypack,embree", "--json"])
        .args(["--rays", "primary,shadow"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let result: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let rows = result["rows"].as_array().unwrap();
    let engines: Vec<&str> = rows.iter().map(|r| r["engine"].as_str().unwrap()).collect();
    for engine in ["raypack", "embree(avx2)", "embree(default)"] {
        assert!(engines.contains(&engine), "{engine} missing: {engines:?}");
    }
    // Both engines see the same rays, so they report the same number of hits
    // (raypack and Embree at each ISA setting, two kernels each).
    for kind in ["primary", "shadow"] {
        let hits: Vec<u64> = rows
            .iter()
            .filter(|r| r["rays_kind"] == kind)
            .map(|r| r["hits"].as_u64().unwrap())
            .collect();
        assert_eq!(hits.len(), 6, "{kind}");
        assert!(hits.windows(2).all(|w| w[0] == w[1]), "{kind}: {hits:?}");
    }
    // raypack's rows are compared with the faster Embree setting on the same
    // kernel, block and threads, and name it.
    let median = |r: &serde_json::Value| r["median"].as_f64().unwrap();
    for row in rows.iter().filter(|r| r["engine"] == "raypack") {
        let embree: Vec<&serde_json::Value> = rows
            .iter()
            .filter(|o| {
                o["rays_kind"] == row["rays_kind"]
                    && o["kernel"] == row["kernel"]
                    && o["engine"].as_str().unwrap().starts_with("embree")
            })
            .collect();
        let fastest = embree
            .iter()
            .max_by(|a, b| median(a).total_cmp(&median(b)))
            .unwrap();
        assert_eq!(row["vs_embree_engine"], fastest["engine"], "{row}");
        assert!(row["vs_embree"]["median"].as_f64().is_some(), "{row}");
    }
    // The environment names the Embree the figures were measured with.
    assert!(result["environment"]["embree"]["version"].is_string(), "{result}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bench_traversal_measures_both_engines_with_their_own_growth() {
    let args = [
        &TINY_TRAVERSAL[..],
        &["--engine", "raypack,embree", "--embree-isa", "avx2"],
    ]
    .concat();
    let o = raypack().args(&args).arg("--json").output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let result: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let rows = result["rows"].as_array().unwrap();
    // Scene by scene, engine by engine.
    let order: Vec<(&str, &str)> = rows
        .iter()
        .map(|r| (r["scene"].as_str().unwrap(), r["engine"].as_str().unwrap()))
        .collect();
    assert_eq!(
        order,
        [
            ("mesh-200", "raypack"),
            ("mesh-200", "embree"),
            ("mesh-400", "raypack"),
            ("mesh-400", "embree"),
        ]
    );
    for row in rows {
        assert!(row["build_ms"]["median"].as_f64().unwrap() > 0.0);
        // Embree cannot count its traversal work nor report its tree: no
        // figures rather than zeros.
        let counted = row["engine"] == "raypack";
        assert_eq!(!row["sah_cost"].is_null(), counted, "{row}");
        for k in row["kinds"].as_array().unwrap() {
            let paths = k["paths"].as_array().unwrap();
            assert_eq!(paths.len(), 3, "{row}");
            for p in paths {
                assert!(p["mrays"]["median"].as_f64().unwrap() > 0.0);
                // raypack's rows carry their speed over Embree's, from the same rounds.
                assert_eq!(p["vs_embree"]["median"].is_f64(), counted, "{row}");
                assert_eq!(!p["stats"].is_null(), counted, "{row}");
            }
        }
    }
    // Both engines trace the same rays of every kind.
    for (ours, theirs) in [(0, 1), (2, 3)] {
        let rays = |row: usize| {
            let kinds = rows[row]["kinds"].as_array().unwrap();
            kinds
                .iter()
                .map(|k| k["rays"].as_u64().unwrap())
                .collect::<Vec<_>>()
        };
        assert_eq!(rays(ours), rays(theirs));
        assert_eq!(rays(ours).len(), 5);
    }
    // Each engine's growth is measured from its own first scene.
    let random = |row: usize| &rows[row]["kinds"][4];
    assert_eq!(rows[0]["kinds"][0]["paths"][0]["growth_vs_first"]["median"], 1.0);
    assert_eq!(rows[1]["kinds"][0]["paths"][0]["growth_vs_first"]["median"], 1.0);
    let single = |row: usize| random(row)["paths"][0]["mrays"]["median"].as_f64().unwrap();
    let embree_from_rates = single(1) / single(3);
    let g = random(3)["paths"][0]["growth_vs_first"]["median"]
        .as_f64()
        .unwrap();
    assert!(
        (g / embree_from_rates - 1.0).abs() < 1e-9,
        "{g} vs {embree_from_rates}"
    );

    // Two thread counts, interleaved round by round: Embree gets a fresh
    // device of each count for each build round (its thread limit is
    // process-wide), and builds are compared at the same count.
    let o = raypack().args(&args).args(["--threads", "1,2"]).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8(o.stdout).unwrap();
    for start in [
        "time per ray, raypack, mesh-200 -> mesh-400 (1t",
        "time per ray, embree(avx2), mesh-200 -> mesh-400 (1t",
        "raypack / Embree, mesh-200 (1t",
        "raypack / Embree, mesh-400 (1t",
        "time per ray, embree(avx2), mesh-200 -> mesh-400 (2t",
        "raypack / Embree, mesh-400 (2t",
        "  ao       Mrays/s vs embree(avx2): single ",
        "growth of time per ray (best path), raypack vs Embree, mesh-200 -> mesh-400 (1t): primary ",
        "growth of time per ray (best path), raypack vs Embree, mesh-200 -> mesh-400 (2t): primary ",
    ] {
        assert!(text.lines().any(|l| l.starts_with(start)), "{start}\n{text}");
    }
    // By default Embree runs twice, with its 8-wide kernels and with its own
    // choice for the CPU, each an engine of its own; raypack's best path is
    // set against the faster of the two.
    let defaults = [&TINY_TRAVERSAL[..], &["--engine", "raypack,embree"]].concat();
    let o = raypack().args(&defaults).arg("--json").output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let result: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let engines: Vec<String> = result["rows"].as_array().unwrap()[..3]
        .iter()
        .map(|r| format!("{} {}", r["engine"], r["embree_isa"]))
        .collect();
    assert_eq!(
        engines,
        [
            "\"raypack\" null",
            "\"embree\" \"avx2\"",
            "\"embree\" \"default\""
        ]
    );
    let o = raypack().args(&defaults).output().unwrap();
    let both = String::from_utf8(o.stdout).unwrap();
    for engine in [" prims embree(avx2) 1t ", " prims embree(default) 1t "] {
        assert_eq!(
            both.lines().filter(|l| l.contains(engine)).count(),
            2,
            "{engine}\n{both}"
        );
    }
    let start = "time per ray, embree(default), mesh-200 -> mesh-400 (1t";
    assert!(both.lines().any(|l| l.starts_with(start)), "{start}\n{both}");
    assert!(both.contains("vs embree(avx2): single ") && both.contains("; vs embree(default): single "));

    let two_threads = text
        .lines()
        .find(|l| l.starts_with("raypack / Embree, mesh-200 (2t"))
        .unwrap();
    assert!(
        two_threads.contains("build time ") && two_threads.ends_with("(both on 2t)"),
        "{two_threads}"
    );
}
