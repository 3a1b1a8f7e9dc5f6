//! The engine registry from the command line: every engine this build links
//! traces (and agrees with raypack), every engine it left out says how to get
//! it, and what an engine cannot do is refused or left out with its reason.

use crate::support::cli::{raypack, stderr};
use raypack::engines::Engine;

/// The engines behind a cargo feature of their name, and whether this build has them.
fn feature_engines() -> Vec<(&'static str, bool)> {
    Engine::ALL
        .iter()
        .filter(|&&e| e != Engine::Raypack)
        .map(|e| (e.name(), e.linked()))
        .collect()
}

/// The engines that trace single rays only (the peers).
fn single_ray_engines() -> Vec<&'static str> {
    Engine::ALL
        .iter()
        .filter(|e| e.traces_lanes(8).is_err())
        .map(|e| e.name())
        .collect()
}

#[test]
fn each_engine_agrees_with_raypack_or_says_how_to_get_it() {
    for (engine, linked) in feature_engines() {
        let out = raypack(&[
            "check",
            "gen:tetra",
            "--engine",
            engine,
            "--kernel",
            "scalar",
            "--rays",
            "random",
            "--n",
            "20000",
            "--json",
        ]);
        if linked {
            assert!(out.status.success(), "{engine}: {}", stderr(&out));
            let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON on stdout");
            assert_eq!(json["engines"], serde_json::json!(["raypack", engine]));
            for set in json["sets"].as_array().unwrap() {
                assert!(
                    set["hit_agreement"].as_f64().unwrap() >= 0.9999,
                    "{engine}: {set}"
                );
            }
        } else {
            assert_eq!(out.status.code(), Some(2), "{engine}: {}", stderr(&out));
            let err = stderr(&out);
            // Which feature (and, for tinybvh8, which compiler flags) to build with.
            assert!(err.contains("build with") && err.contains("--features "), "{err}");
            assert!(out.stdout.is_empty());
        }
    }
}

#[test]
fn a_single_ray_engine_refuses_packets_and_primitives_it_does_not_take() {
    for engine in single_ray_engines() {
        let linked = feature_engines().iter().any(|&(e, l)| e == engine && l);
        // Packets: refused before any work, whether linked or not.
        let out = raypack(&["check", "gen:tetra", "--engine", engine, "--kernel", "packet8"]);
        assert_eq!(out.status.code(), Some(2), "{engine}");
        let err = stderr(&out);
        assert!(
            err.contains(&format!("n/a: {engine} traces single rays only")),
            "{err}"
        );
        if !linked {
            continue;
        }
        // Spheres: the build says what the engine takes.
        let out = raypack(&[
            "check",
            "gen:spheres:50",
            "--engine",
            engine,
            "--kernel",
            "scalar",
            "--n",
            "100",
        ]);
        assert_eq!(out.status.code(), Some(2), "{engine}");
        let err = stderr(&out);
        assert!(
            err.contains(&format!("n/a: {engine} takes triangles and polygons only")),
            "{err}"
        );
        assert!(err.contains("50 other primitives"), "{err}");
    }
}

/// A tiny `bench traversal --json` of `engines` on the generated scenes `scenes` names.
fn tiny_traversal(engines: &str, scenes: &[&str]) -> std::process::Output {
    let tiny = ["--size", "32x32", "--random", "2048", "--rounds", "2", "--json"];
    raypack(&[&["bench", "traversal", "--engine", engines], scenes, &tiny[..]].concat())
}

#[test]
fn bench_traversal_measures_every_engine_it_can_and_says_what_it_left_out() {
    let linked: Vec<&str> = single_ray_engines()
        .into_iter()
        .filter(|&e| feature_engines().contains(&(e, true)))
        .collect();
    if linked.is_empty() {
        return;
    }
    let engines = format!("raypack,{}", linked.join(","));
    let out = tiny_traversal(&engines, &["--generated", "spheres", "--sizes", "300"]);
    // Spheres: only raypack measured, the peers left out with their reason.
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    for engine in &linked {
        assert!(err.contains(&format!("n/a: {engine} takes triangles")), "{err}");
    }
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON on stdout");
    let engines_measured: Vec<&str> = json["rows"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["engine"].as_str().unwrap())
        .collect();
    assert_eq!(engines_measured, ["raypack"]);
    // A mesh: every engine, the peers' packets n/a (null), their single rays hitting what raypack's hit.
    let out = tiny_traversal(&engines, &["--sizes", "1000"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON on stdout");
    let rows = json["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 1 + linked.len());
    let err = stderr(&out);
    for row in &rows[1..] {
        let engine = row["engine"].as_str().unwrap();
        // An engine without an any-hit query has no shadow or AO rows, and says why.
        let any_hit = Engine::ALL
            .iter()
            .any(|e| e.name() == engine && e.finds_any_hit().is_ok());
        let kinds: Vec<&str> = row["kinds"]
            .as_array()
            .unwrap()
            .iter()
            .map(|k| k["kind"].as_str().unwrap())
            .collect();
        for kind in ["shadow", "ao"] {
            assert_eq!(kinds.contains(&kind), any_hit, "{engine}: {kinds:?}");
        }
        if !any_hit {
            assert!(err.contains(&format!("n/a: {engine} has no any-hit")), "{err}");
        }
        for k in row["kinds"].as_array().unwrap() {
            let paths = k["paths"].as_array().unwrap();
            assert_eq!(paths.len(), 1, "single rays only: {row}");
            assert_eq!(paths[0]["path"], "single", "{row}");
            assert!(paths[0]["mrays"]["median"].as_f64().unwrap() > 0.0, "{row}");
        }
        // Kind by kind, the peer hits what raypack hits.
        let ours: Vec<(&str, u64)> = kinds_hits(&rows[0]);
        for (kind, theirs) in kinds_hits(row) {
            let (_, a) = ours
                .iter()
                .find(|(k, _)| *k == kind)
                .expect("raypack traced every kind");
            assert!(
                a.abs_diff(theirs) * 1000 <= *a,
                "{engine} {kind}: {a} vs {theirs}"
            );
        }
    }
}

/// Each kind of a traversal row with its hit count.
fn kinds_hits(row: &serde_json::Value) -> Vec<(&str, u64)> {
    row["kinds"]
        .as_array()
        .unwrap()
        .iter()
        .map(|k| (k["kind"].as_str().unwrap(), k["hits"].as_u64().unwrap()))
        .collect()
}

#[test]
fn an_engine_without_any_hit_renders_what_needs_none_only() {
    let dir = tempfile::tempdir().unwrap();
    let image = dir.path().join("out.png");
    let image = image.to_str().unwrap();
    for engine in Engine::ALL
        .iter()
        .filter(|e| e.linked() && e.finds_any_hit().is_err())
    {
        let render = |mode: &str| {
            let args = [
                "render",
                "gen:tetra",
                "--engine",
                engine.name(),
                "--kernel",
                "scalar",
            ];
            raypack(&[&args[..], &["--size", "32x32", "--mode", mode, "-o", image]].concat())
        };
        let out = render("whitted");
        assert_eq!(out.status.code(), Some(2), "{engine}: {}", stderr(&out));
        assert!(stderr(&out).contains("no any-hit"), "{}", stderr(&out));
        assert!(!std::path::Path::new(image).exists(), "nothing written");
        let out = render("cast");
        assert!(out.status.success(), "{engine}: {}", stderr(&out));
        assert!(std::path::Path::new(image).exists());
        std::fs::remove_file(image).unwrap();
    }
}
