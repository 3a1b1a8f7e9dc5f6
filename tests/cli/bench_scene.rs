//! `raypack bench scene --json`: one row per engine, kernel, block and thread
//! count, each a median with its interval, with the ratios the benchmark
//! targets are quoted from, all computed from the runs of the same run; and
//! the environment the result was measured on.

use crate::support::cli::{bench_scene_json, raypack, stderr};

#[test]
fn rows_carry_consistent_ratios() {
    let result = bench_scene_json(&[
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
    ]);
    let rows = result["rows"].as_array().expect("an array of rows");
    assert_eq!(rows.len(), 4);
    let mrays = |r: &serde_json::Value| r["median"].as_f64().unwrap();
    let first = mrays(&rows[0]);
    for r in rows {
        for key in ["scene", "engine", "kernel", "accel"] {
            assert!(r[key].is_string(), "{key}");
        }
        assert_eq!(r["engine"], "raypack");
        assert_eq!(r["rays"].as_u64(), Some(64 * 32));
        assert!(mrays(r) > 0.0);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b.abs();
        // One run: each ratio's median is the ratio of the two runs.
        assert!(close(r["ratio"]["median"].as_f64().unwrap(), mrays(r) / first));
        let one_thread = rows
            .iter()
            .find(|o| o["kernel"] == r["kernel"] && o["threads"].as_u64() == Some(1))
            .expect("a 1-thread row per kernel");
        assert!(close(
            r["vs_fewest_threads"]["median"].as_f64().unwrap(),
            mrays(r) / mrays(one_thread)
        ));
        assert_eq!(r["hits"], rows[0]["hits"], "every variant traces the same rays");
    }
}

/// Every ray kind gets a row per kernel; the secondary kinds hold one ray per
/// primary hit, and the ratios are taken within a kind.
#[test]
fn every_ray_kind_gets_its_rows() {
    let result = bench_scene_json(&["--size", "32x16", "--runs", "1", "--threads", "1"]);
    let rows = result["rows"].as_array().expect("an array of rows");
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
        assert_eq!(pair[0]["ratio"]["median"].as_f64(), Some(1.0));
        assert!(pair[1]["median"].as_f64().unwrap() > 0.0);
    }
    for r in &rows[2..8] {
        assert_eq!(r["rays"].as_u64(), Some(primary_hits), "{}", r["rays_kind"]);
    }
}

/// Every row is a median of its runs with the order-statistics interval, a
/// noise flag and its sample count; the ratios carry their own intervals; the
/// result carries the environment `raypack env --json` prints, and every
/// figure named and labelled. (The values are timings: only their shape and
/// order are checked.)
#[test]
fn rows_carry_intervals_and_the_result_its_environment() {
    let result = bench_scene_json(&[
        "--engine",
        "raypack",
        "--size",
        "32x16",
        "--runs",
        "6",
        "--threads",
        "1",
        "--rays",
        "primary,shadow",
    ]);
    assert_eq!(result["command"], "scene");
    let rows = result["rows"].as_array().expect("rows");
    assert_eq!(rows.len(), 4);
    let interval = |s: &serde_json::Value| {
        let [low, median, high] = ["ci_low", "median", "ci_high"].map(|k| s[k].as_f64().unwrap());
        assert!(0.0 < low && low <= median && median <= high, "{s}");
        assert_eq!(s["samples"].as_u64(), Some(6), "{s}");
        // Six samples: [x(1), x(6)] covers 1 − 2/64 of the median's distribution.
        assert!((s["confidence"].as_f64().unwrap() - 0.96875).abs() < 1e-12, "{s}");
        assert!(s["noisy"].is_boolean(), "{s}");
    };
    for r in rows {
        assert_eq!(r["unit"], "Mrays/s");
        interval(r);
        interval(&r["ratio"]);
        interval(&r["vs_fewest_threads"]);
    }

    let env = raypack(&["env", "--json"]);
    assert!(env.status.success(), "{}", stderr(&env));
    let env: serde_json::Value = serde_json::from_slice(&env.stdout).unwrap();
    let keys = |v: &serde_json::Value| {
        let mut k: Vec<String> = v.as_object().expect("an object").keys().cloned().collect();
        k.sort();
        k
    };
    let measured = &result["environment"];
    assert_eq!(keys(measured), keys(&env));
    for key in [
        "cpu_model",
        "threads",
        "isa_build",
        "rustc",
        "profile",
        "git_commit",
    ] {
        assert_eq!(measured[key], env[key], "{key}");
    }

    let figures = result["figures"].as_array().expect("figures");
    // Per row: its throughput and its two ratios.
    assert_eq!(figures.len(), 3 * rows.len());
    for f in figures {
        interval(f);
        assert!(f["name"].is_string() && f["unit"].is_string(), "{f}");
        assert_eq!(f["labels"]["engine"], "raypack", "{f}");
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
    let result: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON on stdout");
    let row = &result["rows"].as_array().expect("an array of rows")[0];
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

#[test]
fn instructions_per_ray_are_counted_once_per_variant_or_said_to_be_na() {
    let valgrind = std::process::Command::new("valgrind").arg("--version").output();
    let has_valgrind = valgrind.is_ok_and(|o| o.status.success());
    let result = bench_scene_json(&[
        "--size",
        "32x32",
        "--runs",
        "1",
        "--threads",
        "1,2",
        "--kernel",
        "scalar,packet8",
        "--rays",
        "primary,ao",
        "--instructions",
    ]);
    let rows = result["rows"].as_array().expect("an array of rows");
    assert_eq!(rows.len(), 8);
    for r in rows {
        let n = &r["instructions_per_ray"];
        if !has_valgrind {
            assert!(n.is_null(), "{r}");
            continue;
        }
        let n = n.as_f64().expect("a count per row");
        assert!((20.0..50_000.0).contains(&n), "{r}");
        // Counted on one thread: a variant's count is the same at either thread count.
        let same = rows.iter().filter(|o| {
            o["kernel"] == r["kernel"] && o["rays_kind"] == r["rays_kind"] && o["threads"] != r["threads"]
        });
        for o in same {
            assert_eq!(o["instructions_per_ray"].as_f64(), Some(n), "{r} {o}");
        }
    }
}
