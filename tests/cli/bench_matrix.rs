//! `raypack bench matrix`: a tiny matrix has a cell per scene, thread count
//! and ray kind, in its JSON and its printed table; a bad `--scenes` entry is
//! the user's error (exit 2); without Embree the command says the ratios need it.

use crate::support::cli::{raypack, stderr};

/// A matrix small enough for a test, but for `--json` and `--threads`.
const TINY_MATRIX: [&str; 14] = [
    "bench",
    "matrix",
    "--scenes",
    "gen:tetra,mesh:1000",
    "--rays",
    "primary,ao",
    "--size",
    "32x32",
    "--random",
    "512",
    "--rounds",
    "2",
    "--embree-isa",
    "avx2",
];

/// `bench matrix` on [`TINY_MATRIX`] at `threads`, its JSON into `json`
/// (`-`: stdout): the result and what was printed on stdout and stderr.
#[cfg(feature = "embree")]
pub fn tiny_matrix(threads: &str, json: &str) -> (serde_json::Value, String, String) {
    let o = raypack(&[&TINY_MATRIX[..], &["--threads", threads, "--json", json]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    let (err, out) = (stderr(&o), String::from_utf8(o.stdout).unwrap());
    let text = if json == "-" {
        out.clone()
    } else {
        std::fs::read_to_string(json).unwrap()
    };
    (serde_json::from_str(&text).expect("a JSON result"), out, err)
}

#[cfg(feature = "embree")]
#[test]
fn a_tiny_matrix_has_a_cell_per_scene_thread_count_and_ray_kind() {
    let dir = crate::support::cli::scratch("bench-matrix");
    let file = dir.join("matrix.json");
    let (result, table, _) = tiny_matrix("1,2", file.to_str().unwrap());
    assert_eq!(result["command"], "matrix");
    // The machine it ran on, as every bench result carries it.
    let env = &result["environment"];
    assert!(!env["cpu_model"].as_str().unwrap().is_empty(), "{env}");
    assert!(env["embree"].is_object(), "{env}");
    let rows = result["rows"].as_array().unwrap();
    let layout: Vec<(&str, u64)> = rows
        .iter()
        .map(|r| (r["scene"].as_str().unwrap(), r["threads"].as_u64().unwrap()))
        .collect();
    assert_eq!(
        layout,
        [
            ("gen:tetra", 1),
            ("gen:tetra", 2),
            ("mesh:1000", 1),
            ("mesh:1000", 2)
        ]
    );
    for row in rows {
        let kinds: Vec<&str> = row["cells"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c["kind"].as_str().unwrap())
            .collect();
        assert_eq!(kinds, ["primary", "ao"], "{row}");
        for cell in row["cells"].as_array().unwrap() {
            assert!(cell["ratio"]["median"].as_f64().unwrap() > 0.0, "{cell}");
            assert_eq!(cell["ratio"]["samples"], 2, "{cell}");
            let path = cell["raypack"].as_str().unwrap();
            assert!(["single", "packet8", "packet16"].contains(&path), "{cell}");
            assert!(
                cell["embree"].as_str().unwrap().starts_with("embree(avx2) "),
                "{cell}"
            );
            assert!(cell["passes"].is_boolean());
        }
        assert!(row["build"]["ratio"]["median"].as_f64().unwrap() > 0.0, "{row}");
    }
    // A figure per cell: two ray kinds and the build, per row.
    let figures = result["figures"].as_array().unwrap();
    assert_eq!(figures.len(), rows.len() * 3);
    // The table printed while it ran: a line per row, then the headline.
    for (scene, threads) in &layout {
        let line = table
            .lines()
            .find(|l| l.starts_with(scene) && l.contains(&format!(" {threads}t ")));
        assert!(line.is_some(), "{scene} {threads}t: {table}");
    }
    assert!(
        table.contains("geometric mean of the 4 incoherent cells"),
        "{table}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// With `--json` and no file, the result goes to stdout and the table to stderr.
#[cfg(feature = "embree")]
#[test]
fn json_without_a_file_goes_to_stdout_and_the_table_to_stderr() {
    let (result, _, table) = tiny_matrix("1", "-");
    assert_eq!(result["rows"].as_array().unwrap().len(), 2);
    assert!(table.contains("mesh:1000"), "{table}");
}

#[test]
fn a_bad_scene_is_the_users_error() {
    for (scene, says) in [
        ("gen:tetra,mesh:ten", "mesh:ten: expected mesh:N"),
        ("no-such-scene.ply", "no-such-scene.ply: no such scene file"),
    ] {
        let o = raypack(&["bench", "matrix", "--scenes", scene]);
        assert_eq!(o.status.code(), Some(2), "{scene}: {}", stderr(&o));
        assert!(stderr(&o).contains(says), "{scene}: {}", stderr(&o));
        assert!(o.stdout.is_empty());
    }
}

/// A generated scene spelled wrong is found before anything is measured.
#[cfg(feature = "embree")]
#[test]
fn an_unknown_generated_scene_fails_before_measuring() {
    let o = raypack(&[&TINY_MATRIX[..], &["--scenes", "mesh:1000,gen:nosuch"]].concat());
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("unknown generated scene `nosuch`"),
        "{}",
        stderr(&o)
    );
    assert!(o.stdout.is_empty(), "nothing measured");
}

/// Without the `embree` feature there is no ratio to take: the command says
/// so, before loading any scene.
#[cfg(not(feature = "embree"))]
#[test]
fn without_embree_the_matrix_says_it_needs_the_feature() {
    let o = raypack(&TINY_MATRIX);
    assert_eq!(o.status.code(), Some(2));
    let err = stderr(&o);
    assert!(err.contains("bench matrix sets raypack against Embree"), "{err}");
    assert!(err.contains("without the `embree` feature"), "{err}");
    assert!(o.stdout.is_empty());
}

/// The dragon and the bunny are assets that may not be fetched: where the
/// working directory has none, each is left out with a note, and nothing
/// left to measure is the user's error.
#[cfg(feature = "embree")]
#[test]
fn missing_assets_are_left_out_with_a_note() {
    let dir = crate::support::cli::scratch("bench-matrix-assets");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_raypack"))
        .args(["bench", "matrix", "--scenes", "dragon,bunny", "--threads", "1"])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = stderr(&o);
    for asset in ["dragon", "bunny"] {
        let note =
            format!("note: assets/{asset}.ply is missing: no {asset} rows (run scripts/fetch-assets.sh");
        assert!(err.contains(&note), "{err}");
    }
    assert!(err.contains("no scene to measure"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}
