//! `--save-baseline NAME` / `--baseline NAME`: a run stored, and a later run
//! compared with it figure by figure. The runs are timed by their work, not
//! the clock (the bench hook `RAYPACK_TEST_CLOCK=work`), so that the tests
//! assert on no timing: two runs of one build show no significant change on
//! any figure, and a variant slowed through the slowdown hook
//! (`RAYPACK_TEST_SLOWDOWN`) shows as slower. (How often a shared machine's
//! own noise crosses the ±5% threshold is a property of the machine, not of
//! raypack; docs/benchmarking.md has figures.)

use std::path::Path;
use std::process::{Command, Output};

use crate::support::cli::{scratch, stderr};

/// `raypack` with `args`, its baselines in `dir`, timed by the work clock, and `env` set.
fn raypack_in(dir: &Path, args: &[&str], env: &[(&str, &str)]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_raypack"))
        .args(args)
        .env("RAYPACK_BASELINE_DIR", dir)
        .env("RAYPACK_TEST_CLOCK", "work")
        .env_remove("RAYPACK_TEST_SLOWDOWN")
        .envs(env.iter().copied())
        .output()
        .unwrap()
}

/// A `bench kernels` of 40 figures (8 primitives: 4 kernels and a ratio): 10
/// rounds give a 97.9% interval of each median (fewer are too few to compare).
const KERNELS: [&str; 10] = [
    "bench",
    "kernels",
    "--rays",
    "64",
    "--rounds",
    "10",
    "--sample-ms",
    "1",
    "--seed",
    "3",
];

fn json(out: &Output) -> serde_json::Value {
    assert!(out.status.success(), "{}", stderr(out));
    serde_json::from_slice(&out.stdout).expect("JSON on stdout")
}

#[test]
fn an_unchanged_build_shows_no_significant_change_and_a_slowed_variant_shows_as_slower() {
    let dir = scratch("baseline");
    let saved = json(&raypack_in(
        &dir,
        &[&KERNELS[..], &["--json", "--save-baseline", "before"]].concat(),
        &[],
    ));
    assert!(dir.join("before.json").is_file());
    assert!(saved["comparison"].is_null());

    // The same build again: every figure the same (the work clock).
    let same = json(&raypack_in(
        &dir,
        &[&KERNELS[..], &["--json", "--baseline", "before"]].concat(),
        &[],
    ));
    let comparison = &same["comparison"];
    assert_eq!(comparison["baseline"], "before");
    assert_eq!(comparison["unmatched"].as_array().map(Vec::len), Some(0));
    let changes = comparison["changes"].as_array().unwrap();
    assert_eq!(changes.len(), 40);
    for c in changes {
        assert_eq!(c["verdict"], "no significant change", "{c}");
    }

    // The slowdown hook makes every packet8 sample ten times as long.
    let slowed = json(&raypack_in(
        &dir,
        &[&KERNELS[..], &["--json", "--baseline", "before"]].concat(),
        &[("RAYPACK_TEST_SLOWDOWN", "packet8:10")],
    ));
    let changes = slowed["comparison"]["changes"].as_array().unwrap();
    let packet8: Vec<&serde_json::Value> = changes
        .iter()
        .filter(|c| c["key"].as_str().unwrap().contains("kernel=packet8"))
        .collect();
    assert_eq!(packet8.len(), 8);
    for c in packet8 {
        assert_eq!(c["verdict"], "slower", "{c}");
        assert!(c["change_high"].as_f64().unwrap() < 0.0, "{c}");
    }
    // The text output says so too.
    let text = raypack_in(
        &dir,
        &[&KERNELS[..], &["--baseline", "before"]].concat(),
        &[("RAYPACK_TEST_SLOWDOWN", "packet8:10")],
    );
    assert!(text.status.success(), "{}", stderr(&text));
    let text = String::from_utf8(text.stdout).unwrap();
    assert!(text.contains("against baseline before"), "{text}");
    let line = text
        .lines()
        .find(|l| l.contains("throughput kernel=packet8 primitive=sphere"))
        .unwrap_or_else(|| panic!("{text}"));
    assert!(line.ends_with("slower"), "{line}");
    assert!(text.contains("beyond ±5%"), "{text}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A missing baseline, a name that would leave the directory, a baseline of
/// another bench command and a malformed hook are the user's errors (exit 2),
/// reported before anything is measured.
#[test]
fn bad_baselines_are_the_users_error() {
    let dir = scratch("baseline-errors");
    let tiny = [
        "bench",
        "kernels",
        "--rays",
        "8",
        "--rounds",
        "1",
        "--sample-ms",
        "1",
    ];
    let run = |extra: &[&str], env: &[(&str, &str)]| raypack_in(&dir, &[&tiny[..], extra].concat(), env);
    let out = run(&["--baseline", "nothing"], &[]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("--save-baseline nothing"),
        "{}",
        stderr(&out)
    );
    for bad in ["../up", ".hidden", "a/b", ""] {
        let out = run(&["--save-baseline", bad], &[]);
        assert_eq!(out.status.code(), Some(2), "{bad}");
        assert!(stderr(&out).contains("baseline name"), "{bad}: {}", stderr(&out));
    }
    let out = run(&[], &[("RAYPACK_TEST_SLOWDOWN", "packet8")]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("VARIANT:FACTOR"), "{}", stderr(&out));
    let out = run(&[], &[("RAYPACK_TEST_CLOCK", "wall")]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("RAYPACK_TEST_CLOCK=wall: expected work"),
        "{}",
        stderr(&out)
    );
    let out = run(&["--save-baseline", "k"], &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/spd_balls_small.nff");
    let out = raypack_in(
        &dir,
        &[
            "bench",
            "scene",
            scene,
            "--size",
            "8x8",
            "--runs",
            "1",
            "--baseline",
            "k",
        ],
        &[],
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("`bench kernels`"), "{}", stderr(&out));
    assert!(out.stdout.is_empty());
    std::fs::remove_dir_all(&dir).unwrap();
}
