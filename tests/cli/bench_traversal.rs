//! `raypack bench traversal`: a tiny run reports every figure, and a scene
//! file that cannot be read is the user's error (exit 2), not a panic.

use crate::support::cli::{TINY_TRAVERSAL, raypack, scratch, stderr};

#[test]
fn traversal_bench_reports_json_rows_of_every_ray_kind() {
    let out = raypack(&[&TINY_TRAVERSAL[..], &["--threads", "1", "--json"]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    let result: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON on stdout");
    let rows = result["rows"].as_array().expect("an array of rows");
    assert_eq!(rows.len(), 2);
    for row in rows {
        assert!(row["scene"].as_str().unwrap().starts_with("mesh-"));
        assert_eq!(row["engine"], "raypack");
        assert!(row["primitives"].as_u64().unwrap() > 100);
        assert!(row["sah_cost"].as_f64().unwrap() > 0.0);
        let kinds: Vec<&str> = row["kinds"]
            .as_array()
            .unwrap()
            .iter()
            .map(|k| k["kind"].as_str().unwrap())
            .collect();
        assert_eq!(kinds, ["primary", "shadow", "ao", "diffuse", "random"]);
        for k in row["kinds"].as_array().unwrap() {
            let kind = k["kind"].as_str().unwrap();
            let any_hit = matches!(kind, "shadow" | "ao");
            assert_eq!(k["query"], if any_hit { "any-hit" } else { "nearest" }, "{kind}");
            let rays = k["rays"].as_u64().unwrap();
            assert!(rays > 0 && k["hits"].as_u64().unwrap() <= rays, "{kind}");
            let paths = k["paths"].as_array().unwrap();
            let names: Vec<&str> = paths.iter().map(|p| p["path"].as_str().unwrap()).collect();
            assert_eq!(names, ["single", "packet8", "packet16"], "{kind}");
            for p in paths {
                for key in ["mrays", "vs_single"] {
                    assert!(p[key]["median"].as_f64().unwrap() > 0.0, "{kind} {p}");
                    assert_eq!(p[key]["samples"].as_u64(), Some(1), "{kind} {p}");
                }
                // Every ray of the kind is counted once by each pass.
                assert_eq!(p["stats"]["rays"].as_u64(), Some(rays), "{kind} {p}");
            }
            // Single rays against themselves: exactly 1.
            assert_eq!(paths[0]["vs_single"]["median"].as_f64(), Some(1.0), "{kind}");
        }
        // Secondary rays start at primary hits: no more of them than primary rays that hit.
        let primary_hits = row["kinds"][0]["hits"].as_u64().unwrap();
        assert_eq!(row["kinds"][0]["rays"].as_u64(), Some(32 * 16));
        assert_eq!(row["kinds"][4]["rays"].as_u64(), Some(256));
        for k in 1..4 {
            assert_eq!(row["kinds"][k]["rays"].as_u64(), Some(primary_hits), "{k}");
        }
    }
    // Time per ray against the first scene: exactly 1 for the first, and a
    // measured ratio (of the times behind the Mrays/s figures: one round, so
    // the ratio of the two rounds) for the second.
    let (first, second) = (
        rows[0]["kinds"].as_array().unwrap(),
        rows[1]["kinds"].as_array().unwrap(),
    );
    for (a, b) in first.iter().zip(second) {
        let (a, b) = (a["paths"].as_array().unwrap(), b["paths"].as_array().unwrap());
        for (a, b) in a.iter().zip(b) {
            assert_eq!(a["growth_vs_first"]["median"].as_f64(), Some(1.0));
            let from_rates = a["mrays"]["median"].as_f64().unwrap() / b["mrays"]["median"].as_f64().unwrap();
            let g = b["growth_vs_first"]["median"].as_f64().unwrap();
            assert!(
                (g / from_rates - 1.0).abs() < 1e-9,
                "{a} {b}: {g} vs {from_rates}"
            );
        }
    }
}

#[test]
fn traversal_bench_measures_the_ray_kinds_asked_for() {
    for kind in ["primary", "shadow", "ao", "diffuse", "random"] {
        let out = raypack(&[&TINY_TRAVERSAL[..], &["--rays", kind, "--json"]].concat());
        assert!(out.status.success(), "{kind}: {}", stderr(&out));
        let result: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON on stdout");
        for row in result["rows"].as_array().unwrap() {
            let kinds = row["kinds"].as_array().unwrap();
            assert_eq!(kinds.len(), 1);
            assert_eq!(kinds[0]["kind"], kind);
            assert!(
                kinds[0]["paths"][0]["mrays"]["median"].as_f64().unwrap() > 0.0,
                "{kind}"
            );
        }
    }
    let out = raypack(&[&TINY_TRAVERSAL[..], &["--rays", "bounce"]].concat());
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn traversal_bench_prints_growth_from_the_first_scene() {
    let out = raypack(&[
        "bench",
        "traversal",
        "--sizes",
        "200,400,800",
        "--size",
        "32x16",
        "--random",
        "64",
        "--rounds",
        "1",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8(out.stdout).unwrap();
    let growth: Vec<&str> = text.lines().filter(|l| l.starts_with("time per ray, ")).collect();
    assert_eq!(growth.len(), 2, "{text}");
    assert!(
        growth[0].starts_with("time per ray, raypack, mesh-200 -> mesh-400 (1t"),
        "{text}"
    );
    assert!(
        growth[1].starts_with("time per ray, raypack, mesh-200 -> mesh-800 (1t"),
        "{text}"
    );
    for kind in ["primary", "shadow", "ao", "diffuse", "random"] {
        assert!(growth[1].contains(&format!("{kind} single ")), "{kind}: {text}");
    }
}

/// Without the `embree` feature, asking for Embree is the user's error, said
/// before any scene is generated.
#[cfg(not(feature = "embree"))]
#[test]
fn embree_engine_without_the_feature_exits_with_code_2() {
    let out = raypack(&[
        "bench",
        "traversal",
        "--engine",
        "raypack,embree",
        "--sizes",
        "200",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert!(err.contains("without the `embree` feature"), "{err}");
    assert!(out.stdout.is_empty());
}

#[test]
fn unreadable_scene_file_exits_with_code_2() {
    let dir = scratch("bvh-bench");
    let path = dir.join("scene.unknown");
    std::fs::write(&path, "not a scene\n").unwrap();
    let out = raypack(&["bench", "traversal", path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert!(err.contains("scene.unknown"), "{err}");
    assert!(out.stdout.is_empty());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn instructions_per_ray_are_counted_under_callgrind_or_said_to_be_na() {
    let valgrind = std::process::Command::new("valgrind").arg("--version").output();
    let has_valgrind = valgrind.is_ok_and(|o| o.status.success());
    let args = [
        &TINY_TRAVERSAL[..],
        &["--threads", "1", "--instructions", "--json"],
    ]
    .concat();
    let out = raypack(&args);
    assert!(out.status.success(), "{}", stderr(&out));
    let result: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON on stdout");
    let kinds = result["rows"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|r| r["kinds"].as_array().unwrap());
    for k in kinds {
        for p in k["paths"].as_array().unwrap() {
            let per_ray = &p["instructions_per_ray"];
            if !has_valgrind {
                assert!(per_ray.is_null(), "{k}");
                continue;
            }
            // Every path of raypack traced and counted: a ray costs tens to
            // thousands of instructions on a mesh of a few hundred triangles.
            let n = per_ray.as_f64().unwrap();
            assert!((20.0..20_000.0).contains(&n), "{} {}: {n}", k["kind"], p["path"]);
        }
    }
    if !has_valgrind {
        assert!(stderr(&out).contains("instructions per ray n/a: valgrind is not installed"));
    }
}
