//! `raypack info`: works on every scene (text and JSON), describes its BVH
//! (`--bvh`), and exits 2 with `file:line: message` and nothing on stdout
//! for a bad one; `raypack env` describes the machine and the build.

use std::path::PathBuf;
use std::process::{Command, Output};

use crate::support::scratch::Scratch;

fn info(args: &[&std::ffi::OsStr]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_raypack"))
        .arg("info")
        .args(args)
        .output()
        .expect("run raypack")
}

#[test]
fn info_describes_every_scene() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut checked = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if !path.extension().is_some_and(|e| e == "nff" || e == "toml") {
            continue;
        }
        let scene = raypack::scene::load(&path).unwrap();
        let out = info(&[path.as_os_str()]);
        assert!(
            out.status.success(),
            "{}: {}",
            path.display(),
            String::from_utf8_lossy(&out.stderr)
        );
        let text = String::from_utf8(out.stdout).unwrap();
        assert!(
            text.contains(&format!("primitives  {}\n", scene.id_count())),
            "{text}"
        );
        if let Some(i) = scene.instancing_summary() {
            assert!(text.contains(&format!("instances   {}\n", i.line())), "{text}");
        }
        assert!(
            text.contains(&format!("lights      {}\n", scene.lights.len())),
            "{text}"
        );
        for (kind, n) in scene.counts() {
            assert!(
                text.contains(&format!("{:<12} {n}\n", format!("{kind:?}").to_lowercase())),
                "{text}"
            );
        }
        let out = info(&[path.as_os_str(), "--json".as_ref()]);
        assert!(out.status.success());
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("valid JSON");
        assert_eq!(json["primitives"], scene.id_count());
        assert_eq!(json["lights"].as_array().unwrap().len(), scene.lights.len());
        assert_eq!(json["materials"].as_array().unwrap().len(), scene.materials.len());
        let counted: u64 = json["counts"]
            .as_object()
            .unwrap()
            .values()
            .map(|v| v.as_u64().unwrap())
            .sum();
        assert_eq!(counted, scene.id_count());
        assert_eq!(json["camera"].is_null(), scene.camera.is_none());
        assert!(json["bounds"]["min"].is_array() && json["load_seconds"].as_f64().unwrap() >= 0.0);
        checked += 1;
    }
    assert!(checked >= 3);
}

/// Every SCENE argument also takes a generated scene, `gen:NAME[:N[:SEED]]`;
/// a misspelt one is bad input.
#[test]
fn info_takes_generated_scenes() {
    let out = info(&["gen:spheres:123:4".as_ref(), "--json".as_ref()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("valid JSON");
    assert_eq!(json["primitives"], 123);
    assert_eq!(json["counts"]["sphere"], 123);
    for (spec, expected) in [
        ("gen:nope", "unknown generated scene `nope`"),
        ("gen:mesh:many", "must be a whole number, got `many`"),
    ] {
        let out = info(&[spec.as_ref()]);
        assert_eq!(out.status.code(), Some(2), "{spec}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(expected), "{spec}: {err}");
        assert!(out.stdout.is_empty());
    }
}

/// `info --bvh` builds raypack's BVH as the engines do and describes each
/// level (a flat scene's one tree; an instanced scene's own, top and mesh
/// trees): every primitive of the scene is in one level's tree once (the top
/// tree holds the instances), each binary tree has one node fewer than twice
/// its leaves, what single rays walk is part of the whole, and trees this
/// small stay in the cache (shared packet walks, scattered lanes one after
/// another). The text names the same figures.
#[test]
fn info_bvh_describes_each_level_of_the_tree() {
    for spec in ["gen:mesh:3000", "gen:spheres:123:4", "gen:city:10"] {
        let out = info(&[spec.as_ref(), "--bvh".as_ref(), "--json".as_ref()]);
        assert!(
            out.status.success(),
            "{spec}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("valid JSON");
        let bvh = &json["bvh"];
        assert!(bvh["build_seconds"].as_f64().unwrap() >= 0.0, "{spec}: {bvh}");
        let cache = bvh["cache_bytes"].as_u64().unwrap();
        let levels = bvh["levels"].as_array().unwrap();
        let figure = |level: &serde_json::Value, key: &str| level[key].as_u64().unwrap();
        let mut held = 0;
        for level in levels {
            let (leaves, nodes) = (figure(level, "leaves"), figure(level, "nodes"));
            assert!(leaves >= 1 && nodes == 2 * leaves - 1, "{spec}: {level}");
            let (bytes, walked) = (figure(level, "bytes"), figure(level, "walked_bytes"));
            assert!(0 < walked && walked < bytes && walked < cache, "{spec}: {level}");
            assert_eq!(level["incoherent_packets"], "shared", "{spec}: {level}");
            assert_eq!(level["scattered_packets"], "one after another", "{spec}: {level}");
            let in_tree = figure(level, "primitives");
            if level["name"] == "top" {
                assert_eq!(
                    in_tree,
                    json["instancing"]["instances"].as_u64().unwrap(),
                    "{spec}"
                );
            } else {
                held += in_tree + figure(level, "unbounded") + figure(level, "skipped");
            }
        }
        match json["instancing"]["unique_primitives"].as_u64() {
            Some(unique) => {
                let meshes = json["instancing"]["meshes"].as_u64().unwrap() as usize;
                assert_eq!(levels.len(), 2 + meshes, "{spec}: own, top and the meshes");
                assert_eq!(held, unique, "{spec}");
            }
            None => {
                assert_eq!(levels.len(), 1, "{spec}");
                assert_eq!(held, json["primitives"].as_u64().unwrap(), "{spec}");
            }
        }
        let out = info(&[spec.as_ref(), "--bvh".as_ref()]);
        let text = String::from_utf8(out.stdout).unwrap();
        assert!(text.contains("\nbvh         built in "), "{text}");
        for level in levels {
            let line = format!(
                "  {:<9} {} primitives, {} leaves",
                level["name"].as_str().unwrap(),
                level["primitives"],
                level["leaves"]
            );
            assert!(text.contains(&line), "{line} in {text}");
        }
    }
}

#[test]
fn info_on_a_bad_scene_exits_2_with_file_and_line() {
    let dir = Scratch::new("cli-info");
    let cases = [
        ("truncated.nff", "s 0 0 0 1\np 3\n0 0 0\n1 0 0\n", ":4: expected"),
        ("garbage.nff", "\u{1}\u{2}\u{3}", ":1: expected"),
        (
            "wrong.toml",
            "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = \"x\"\n",
            ":4: expected",
        ),
        ("unknown.obj2", "", ": unknown scene format"),
    ];
    for (name, text, needle) in cases {
        let path = dir.write(name, text);
        for json in [false, true] {
            let mut args = vec![path.as_os_str()];
            if json {
                args.push("--json".as_ref());
            }
            let out = info(&args);
            assert_eq!(out.status.code(), Some(2), "{name}");
            assert!(
                out.stdout.is_empty(),
                "{name}: stdout {:?}",
                String::from_utf8_lossy(&out.stdout)
            );
            let err = String::from_utf8(out.stderr).unwrap();
            assert!(
                err.starts_with(&format!("error: {}{needle}", path.display())),
                "{name}: {err}"
            );
        }
    }
    let out = info(&[dir.path().join("missing.nff").as_os_str()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("missing.nff: cannot read"));
}

/// `raypack env`: the machine and build, as text and as JSON, with the commit
/// the binary was built from.
#[test]
fn env_describes_the_machine_and_the_build() {
    let run = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_raypack"))
            .args(args)
            .output()
            .expect("run raypack")
    };
    let out = run(&["env"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).unwrap();
    let text_row = |text: &str, name: &str| -> String {
        let line = text
            .lines()
            .find(|l| l.starts_with(&format!("{name} ")))
            .unwrap_or_default();
        line[name.len()..].trim().to_string()
    };
    for row in [
        "cpu ",
        "isa (build) ",
        "isa (cpu) ",
        "thp ",
        "cache ",
        "rustc ",
        "profile ",
        "commit ",
        "date ",
        "engines ",
    ] {
        assert!(
            text.lines().any(|l| l.starts_with(row)),
            "no {row:?} row in\n{text}"
        );
    }

    let out = run(&["env", "--json"]);
    assert!(out.status.success());
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("valid JSON");
    assert!(json["threads"].as_u64().unwrap() >= 1);
    assert!(json["rustc"].as_str().unwrap().starts_with("rustc 1."), "{json}");
    assert!(json["date"].as_str().unwrap().ends_with('Z'), "{json}");
    // The last-level cache, where the kernel says: a level and a size.
    let cache = &json["last_level_cache"];
    assert!(
        cache.is_null() || (cache["level"].as_u64().unwrap() >= 1 && cache["bytes"].as_u64().unwrap() > 0),
        "{json}"
    );
    let head = Command::new("git")
        .args(["rev-parse", "HEAD"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string());
    if let Some(head) = head {
        assert_eq!(json["git_commit"], head.as_str());
        // Marked as modified exactly when the sources differ from HEAD (the
        // binary under test was built from them as they are now).
        let status = Command::new("git")
            .args([
                "status",
                "--porcelain",
                "--",
                "src",
                "build.rs",
                "Cargo.toml",
                "Cargo.lock",
            ])
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .output()
            .unwrap();
        assert!(status.status.success());
        assert_eq!(json["git_modified"], !status.stdout.is_empty(), "{json}");
    }
    assert_eq!(json["embree"].is_object(), cfg!(feature = "embree"), "{json}");
    // The features as cargo built them; the engines the registry links.
    let features: Vec<&str> = json["features"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_str().unwrap())
        .collect();
    let engines = text_row(&text, "engines");
    for (feature, on) in [
        ("embree", cfg!(feature = "embree")),
        ("obvhs", cfg!(feature = "obvhs")),
        ("bvh", cfg!(feature = "bvh")),
    ] {
        assert_eq!(features.contains(&feature), on, "{features:?}");
        assert_eq!(engines.split(' ').any(|e| e == feature), on, "{engines}");
    }
    assert!(engines.starts_with("raypack"), "{engines}");

    let out = run(&["env", "--no-such-flag"]);
    assert_eq!(out.status.code(), Some(2));
}
