//! `raypack bench scene --json`: one row per engine, kernel, block and thread
//! count, with the ratios the benchmark targets are quoted from, all computed
//! from the rows of the same run.

mod cli_support;

use cli_support::{raypack, stderr};

#[test]
fn rows_carry_consistent_ratios() {
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/spd_balls_small.nff");
    let out = raypack(&[
        "bench",
        "scene",
        scene,
        "--size",
        "64x32",
        "--runs",
        "1",
        "--threads",
        "1,2",
        "--kernel",
        "scalar,packet8",
        "--rays",
        "primary",
        "--json",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let rows: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON on stdout");
    let rows = rows.as_array().expect("an array of rows");
    assert_eq!(rows.len(), 4);
    let mrays = |r: &serde_json::Value| r["mrays_per_s"].as_f64().unwrap();
    let first = mrays(&rows[0]);
    for r in rows {
        for key in ["scene", "engine", "kernel", "accel"] {
            assert!(r[key].is_string(), "{key}");
        }
        assert_eq!(r["engine"], "raypack");
        assert_eq!(r["rays"].as_u64(), Some(64 * 32));
        assert!(mrays(r) > 0.0);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b.abs();
        assert!(close(r["ratio"].as_f64().unwrap(), mrays(r) / first));
        let one_thread = rows
            .iter()
            .find(|o| o["kernel"] == r["kernel"] && o["threads"].as_u64() == Some(1))
            .expect("a 1-thread row per kernel");
        assert!(close(
            r["vs_fewest_threads"].as_f64().unwrap(),
            mrays(r) / mrays(one_thread)
        ));
        assert_eq!(r["hits"], rows[0]["hits"], "every variant traces the same rays");
    }
}

/// Every ray kind gets a row per kernel; the secondary kinds hold one ray per
/// primary hit, and the ratios are taken within a kind.
#[test]
fn every_ray_kind_gets_its_rows() {
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/spd_balls_small.nff");
    let out = raypack(&[
        "bench",
        "scene",
        scene,
        "--size",
        "32x16",
        "--runs",
        "1",
        "--threads",
        "1",
        "--json",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let rows: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON on stdout");
    let rows = rows.as_array().expect("an array of rows");
    let kinds: Vec<(&str, &str)> = rows
        .iter()
        .map(|r| (r["rays_kind"].as_str().unwrap(), r["kernel"].as_str().unwrap()))
        .collect();
    let mut expected = Vec::new();
    for kind in ["primary", "shadow", "ao", "diffuse", "random"] {
        expected.extend([(kind, "scalar"), (kind, "packet8")]);
    }
    assert_eq!(kinds, expected);
    let primary_hits = rows[0]["hits"].as_u64().unwrap();
    assert_eq!(rows[0]["rays"].as_u64(), Some(32 * 16));
    for pair in rows.chunks(2) {
        assert_eq!(pair[0]["hits"], pair[1]["hits"], "{}", pair[0]["rays_kind"]);
        assert_eq!(pair[0]["ratio"].as_f64(), Some(1.0));
        assert!(pair[1]["mrays_per_s"].as_f64().unwrap() > 0.0);
    }
    for r in &rows[2..8] {
        assert_eq!(r["rays"].as_u64(), Some(primary_hits), "{}", r["rays_kind"]);
    }
}

/// A generated scene (`gen:NAME:N:SEED`, as `check` takes) is benchmarked like
/// a file, under its spec; a bad spec is the user's error (exit 2).
#[test]
fn generated_scenes_are_accepted_and_bad_specs_rejected() {
    let run = |spec: &str| {
        raypack(&[
            "bench",
            "scene",
            spec,
            "--size",
            "32x16",
            "--runs",
            "1",
            "--threads",
            "1",
            "--kernel",
            "packet8",
            "--json",
        ])
    };
    let out = run("gen:mesh:2000:3");
    assert!(out.status.success(), "{}", stderr(&out));
    let rows: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON on stdout");
    let row = &rows.as_array().expect("an array of rows")[0];
    assert_eq!(row["scene"], "gen:mesh:2000:3");
    assert!(
        row["hits"].as_u64().unwrap() > 0,
        "the framing camera sees the mesh"
    );

    for bad in ["gen:nothing:10", "gen:mesh:many"] {
        let out = run(bad);
        assert_eq!(out.status.code(), Some(2), "{bad}");
        let err = stderr(&out);
        assert!(err.contains(bad.split(':').nth(1).unwrap()), "{bad}: {err}");
    }
}
