//! `raypack bench traversal`: a tiny run reports every figure, and a scene
//! file that cannot be read is the user's error (exit 2), not a panic.

use std::process::Command;

#[test]
fn traversal_bench_reports_json_rows() {
    let out = Command::new(env!("CARGO_BIN_EXE_raypack"))
        .args([
            "bench",
            "traversal",
            "--sizes",
            "200,400",
            "--width",
            "32",
            "--height",
            "16",
        ])
        .args(["--random", "256", "--rounds", "1", "--threads", "1", "--json"])
        .output()
        .expect("raypack runs");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let rows: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON on stdout");
    let rows = rows.as_array().expect("an array of rows");
    assert_eq!(rows.len(), 2);
    for row in rows {
        assert!(row["scene"].as_str().unwrap().starts_with("mesh-"));
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
}

#[test]
fn unreadable_scene_file_exits_with_code_2() {
    let dir = std::env::temp_dir().join("raypack-bvh-bench-cli");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("scene.unknown");
    std::fs::write(&path, "not a scene\n").unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_raypack"))
        .args(["bench", "traversal", "--file"])
        .arg(&path)
        .output()
        .expect("raypack runs");
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("scene.unknown"), "{stderr}");
    assert!(out.stdout.is_empty());
}
