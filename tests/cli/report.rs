//! `raypack report RESULTS.json… -o report.html`: a page made from real bench
//! results loads in headless Chromium with no console message, draws its
//! charts (the screenshot is colourful, not blank), and fetches nothing; bad
//! input is the user's error. The browser part is skipped, saying so, where
//! no Chromium is installed (CI installs Debian's `chromium`).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use crate::support::cli::{SMALL_SCENE, bench_scene_json, raypack, scratch, stderr};

/// Run `raypack` with `args`, writing its stdout to `out`.
fn bench_json(args: &[&str], out: &Path) {
    let o = raypack(args);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    std::fs::write(out, &o.stdout).unwrap();
}

/// Chromium on the PATH, by Debian's name or the upstream one.
fn chromium() -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .flat_map(|dir| ["chromium", "chromium-browser"].map(|name| dir.join(name)))
        .find(|p| p.is_file())
}

/// [`chromium`], or None after saying the browser check is skipped; in CI,
/// which installs the browser (`.ci/run`), its absence is a failure.
fn chromium_or_skip() -> Option<PathBuf> {
    let found = chromium();
    if found.is_none() {
        assert!(
            std::env::var_os("CI").is_none(),
            "no chromium on PATH, and CI must run the browser check (apt-get install chromium)"
        );
        eprintln!("skipped the browser check: no chromium on PATH (apt-get install chromium)");
    }
    found
}

/// Load the page `html` in headless `chromium` with `extra` flags; it must
/// run and log no console message (errors, failed loads, warnings).
fn headless(chromium: &Path, html: &Path, extra: &[&str]) -> Output {
    let o = Command::new(chromium)
        .args(["--headless", "--disable-gpu", "--no-sandbox", "--hide-scrollbars"])
        .args(["--window-size=1200,2000", "--enable-logging=stderr", "--v=0"])
        .args(extra)
        .arg(format!("file://{}", html.display()))
        .output()
        .unwrap();
    assert!(o.status.success(), "chromium: {}", stderr(&o));
    // Every console message is logged as CONSOLE.
    let log = stderr(&o);
    let console: Vec<&str> = log.lines().filter(|l| l.contains(":CONSOLE")).collect();
    assert!(console.is_empty(), "console messages: {console:#?}");
    o
}

#[test]
fn the_report_loads_in_headless_chromium_and_shows_its_charts() {
    let dir = scratch("report");
    let (scene_json, kernels_json) = (dir.join("scene.json"), dir.join("kernels.json"));
    let result = bench_scene_json(&[
        "--size",
        "32x16",
        "--runs",
        "6",
        "--threads",
        "1,2",
        "--rays",
        "primary,shadow",
    ]);
    std::fs::write(&scene_json, result.to_string()).unwrap();
    bench_json(
        &[
            "bench",
            "kernels",
            "--rays",
            "64",
            "--rounds",
            "6",
            "--sample-ms",
            "1",
            "--json",
        ],
        &kernels_json,
    );
    // A timing-annotated render with its heat map, shown on the page.
    let render = dir.join("render.png");
    let o = raypack(&[
        "render",
        SMALL_SCENE,
        "-o",
        render.to_str().unwrap(),
        "--size",
        "96x64",
        "--heatmap",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let html_path = dir.join("report.html");
    let o = raypack(&[
        "report",
        scene_json.to_str().unwrap(),
        kernels_json.to_str().unwrap(),
        "-o",
        html_path.to_str().unwrap(),
        "--image",
        render.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let html = std::fs::read_to_string(&html_path).unwrap();
    // Self-contained: every image inlined, nothing to fetch.
    let images = html.matches("<img ").count();
    let svgs = html.matches("<img src=\"data:image/svg+xml;base64,").count();
    let pngs = html.matches("<img src=\"data:image/png;base64,").count();
    assert_eq!(svgs + pngs, images);
    // scene: throughput, vs first row, vs fewest threads, scaling; kernels: throughput, ratio.
    assert_eq!(svgs, 6, "{html}");
    assert_eq!(pngs, 1, "the render");
    assert!(html.contains("<figcaption>render.png</figcaption>"));
    assert!(
        !html.contains("http:") && !html.contains("https:"),
        "nothing fetched"
    );
    for text in [
        "scene.json",
        "kernels.json",
        "raypack bench scene",
        "cpu",
        "commit",
    ] {
        assert!(html.contains(text), "{text} missing");
    }

    let Some(chromium) = chromium_or_skip() else {
        return;
    };
    let shot = dir.join("shot.png");
    let browse = |extra: &[&str]| headless(&chromium, &html_path, extra);
    let dom = browse(&["--dump-dom"]);
    let dom = String::from_utf8(dom.stdout).unwrap();
    assert!(dom.contains("<title>raypack benchmark report</title>"), "{dom}");
    assert_eq!(dom.matches("<img ").count(), images);

    browse(&[&format!("--screenshot={}", shot.display())]);
    let png = image::open(&shot).expect("a PNG screenshot").to_rgb8();
    assert_eq!(png.dimensions(), (1200, 2000));
    let mut colours = std::collections::HashSet::new();
    let mut colourful = 0usize;
    for p in png.pixels() {
        colours.insert(p.0);
        let (hi, lo) = (p.0.iter().max().unwrap(), p.0.iter().min().unwrap());
        // The text and tables are grey: colour comes from the charts' bars.
        if hi - lo > 60 {
            colourful += 1;
        }
    }
    assert!(colours.len() > 50, "{} colours: blank?", colours.len());
    assert!(
        colourful > 10_000,
        "{colourful} coloured pixels: no charts drawn?"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_results_are_the_users_error_and_nothing_is_written() {
    let dir = scratch("report-errors");
    let out = dir.join("report.html");
    let not_a_result = dir.join("rows.json");
    std::fs::write(&not_a_result, "[{\"median\": 1}]\n").unwrap();
    for (input, says) in [
        (dir.join("missing.json"), "missing.json"),
        (not_a_result.clone(), "rows.json:1: not a bench result"),
    ] {
        let o = raypack(&["report", input.to_str().unwrap(), "-o", out.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(2));
        assert!(stderr(&o).contains(says), "{}", stderr(&o));
        assert!(!out.exists());
    }
    let o = raypack(&["report", "-o", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "results are required");
    // A picture that is not a PNG.
    let result = dir.join("kernels.json");
    let o = raypack(&[
        "bench",
        "kernels",
        "--rays",
        "16",
        "--rounds",
        "6",
        "--sample-ms",
        "1",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    std::fs::write(&result, &o.stdout).unwrap();
    let o = raypack(&[
        "report",
        result.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--image",
        not_a_result.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("rows.json: not a PNG image"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A matrix figure of `name` for `scene` at one thread, its three samples.
fn matrix_figure(name: &str, scene: &str, rays: Option<&str>, samples: [f64; 3]) -> serde_json::Value {
    let mut labels = serde_json::json!({"scene": scene, "primitives": "4096", "threads": "1"});
    if let Some(rays) = rays {
        labels["rays"] = rays.into();
    }
    let [low, median, high] = samples;
    serde_json::json!({
        "name": name, "unit": "x", "better": "higher", "labels": labels,
        "median": median, "ci_low": low, "ci_high": high, "samples": 3, "confidence": 0.75,
        "min": low, "q1": low, "q3": high, "max": high, "noisy": true,
    })
}

/// A `bench matrix` result is one table, raypack ÷ Embree per cell, the
/// failing cells marked, and no chart; the page loads in Chromium.
#[test]
fn a_matrix_result_is_drawn_as_one_table() {
    let dir = scratch("report-matrix");
    let env = raypack(&["env", "--json"]);
    assert!(env.status.success(), "{}", stderr(&env));
    let environment: serde_json::Value = serde_json::from_slice(&env.stdout).unwrap();
    let (cell, build) = ("raypack/embree best path", "raypack/embree build time");
    let result = serde_json::json!({
        "command": "matrix",
        "environment": environment,
        "rows": [],
        "figures": [
            matrix_figure(cell, "gen:tetra", Some("primary"), [1.3, 1.44, 1.5]),
            matrix_figure(cell, "gen:tetra", Some("shadow"), [0.7, 0.8, 0.9]),
            matrix_figure(build, "gen:tetra", None, [0.8, 0.9, 1.0]),
            matrix_figure(cell, "dragon", Some("primary"), [0.9, 0.97, 1.06]),
            matrix_figure(cell, "dragon", Some("shadow"), [1.0, 1.1, 1.2]),
            matrix_figure(build, "dragon", None, [1.1, 1.2, 1.3]),
        ],
    });
    let (json, html_path) = (dir.join("matrix.json"), dir.join("report.html"));
    std::fs::write(&json, result.to_string()).unwrap();
    let o = raypack(&[
        "report",
        json.to_str().unwrap(),
        "-o",
        html_path.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let html = std::fs::read_to_string(&html_path).unwrap();
    assert_eq!(html.matches("<table class=\"matrix\">").count(), 1, "{html}");
    assert!(
        html.contains("<th>primary</th><th>shadow</th><th>build</th>"),
        "{html}"
    );
    for cell in [
        "<td class=\"num\">1.44× [1.30, 1.50]</td>",
        "<td class=\"num wrong\">0.80× [0.70, 0.90] ✗</td>",
        "<td class=\"num\">0.90× [0.80, 1.00]</td>",
        "<td class=\"num\">0.97× [0.90, 1.06]</td>",
        "<td class=\"num wrong\">1.20× [1.10, 1.30] ✗</td>",
    ] {
        assert!(html.contains(cell), "{cell}: {html}");
    }
    assert!(
        html.contains("1 of 4 ray-kind cells fail; 1 of 2 builds slower"),
        "{html}"
    );
    assert!(!html.contains("<img "), "a table, no charts: {html}");
    if let Some(chromium) = chromium_or_skip() {
        let dom = headless(&chromium, &html_path, &["--dump-dom"]);
        let dom = String::from_utf8(dom.stdout).unwrap();
        assert!(dom.contains("<td>dragon</td>"), "{dom}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A real (tiny) `bench matrix` result comes out as its table.
#[cfg(feature = "embree")]
#[test]
fn a_measured_matrix_is_drawn_with_every_cell() {
    let dir = scratch("report-measured-matrix");
    let (json, html_path) = (dir.join("matrix.json"), dir.join("report.html"));
    crate::bench_matrix::tiny_matrix("1", json.to_str().unwrap());
    let o = raypack(&[
        "report",
        json.to_str().unwrap(),
        "-o",
        html_path.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let html = std::fs::read_to_string(&html_path).unwrap();
    assert!(
        html.contains("<th>primary</th><th>ao</th><th>build</th>"),
        "{html}"
    );
    for scene in ["gen:tetra", "mesh:1000"] {
        let row = format!("<tr><td>{scene}</td>");
        let at = html.find(&row).unwrap_or_else(|| panic!("{scene}: {html}"));
        let line = html[at..].lines().next().unwrap();
        // Two ray kinds and the build, each a ratio with its interval.
        assert_eq!(line.matches("× [").count(), 3, "{line}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
