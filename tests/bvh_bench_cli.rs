//! `raypack bench traversal`: a tiny run reports every figure, and a scene
//! file that cannot be read is the user's error (exit 2), not a panic.

mod cli_support;

use cli_support::{TINY_TRAVERSAL, raypack, scratch, stderr};

#[test]
fn traversal_bench_reports_json_rows() {
    let out = raypack(&[&TINY_TRAVERSAL[..], &["--threads", "1", "--json"]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    let rows: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON on stdout");
    let rows = rows.as_array().expect("an array of rows");
    assert_eq!(rows.len(), 2);
    for row in rows {
        assert!(row["scene"].as_str().unwrap().starts_with("mesh-"));
        assert_eq!(row["engine"], "raypack");
        assert!(row["primitives"].as_u64().unwrap() > 100);
        for key in [
            "primary_single_mrays",
            "primary_packet_mrays",
            "random_single_mrays",
            "random_packet_mrays",
        ] {
            assert!(row[key].as_f64().unwrap() > 0.0, "{key}");
        }
        assert_eq!(row["primary_packet_stats"]["rays"].as_u64(), Some(32 * 16));
        assert_eq!(row["random_packet_stats"]["rays"].as_u64(), Some(256));
    }
    // Time per ray against the first scene: exactly 1 for the first, and a
    // measured ratio (of the times behind the Mrays/s figures) for the second.
    let growth = |row: &serde_json::Value, key: &str| row["growth_vs_first"][key].as_f64().unwrap();
    for (key, mrays) in [
        ("primary_single", "primary_single_mrays"),
        ("primary_packet", "primary_packet_mrays"),
        ("random_single", "random_single_mrays"),
        ("random_packet", "random_packet_mrays"),
    ] {
        assert_eq!(growth(&rows[0], key), 1.0, "{key}");
        let from_rates = rows[0][mrays].as_f64().unwrap() / rows[1][mrays].as_f64().unwrap();
        let g = growth(&rows[1], key);
        assert!((g / from_rates - 1.0).abs() < 1e-9, "{key}: {g} vs {from_rates}");
    }
}

#[test]
fn traversal_bench_prints_growth_from_the_first_scene() {
    let out = raypack(&[
        "bench",
        "traversal",
        "--sizes",
        "200,400,800",
        "--width",
        "32",
        "--height",
        "16",
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
    assert!(growth[1].contains("primary single ") && growth[1].contains("random single "));
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
    let out = raypack(&["bench", "traversal", "--file", path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert!(err.contains("scene.unknown"), "{err}");
    assert!(out.stdout.is_empty());
    std::fs::remove_dir_all(&dir).unwrap();
}
