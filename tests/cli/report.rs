//! `raypack report RESULTS.json… -o report.html`: a page made from real bench
//! results loads in headless Chromium with no console message, draws its
//! charts (the screenshot is colourful, not blank), and fetches nothing; bad
//! input is the user's error. The browser part is skipped, saying so, where
//! no Chromium is installed (CI installs Debian's `chromium`).

use std::path::{Path, PathBuf};
use std::process::Command;

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

    let Some(chromium) = chromium() else {
        // CI installs the browser (`.ci/run`): there its absence is a failure.
        assert!(
            std::env::var_os("CI").is_none(),
            "no chromium on PATH, and CI must run the browser check (apt-get install chromium)"
        );
        eprintln!("skipped the browser check: no chromium on PATH (apt-get install chromium)");
        return;
    };
    let url = format!("file://{}", html_path.display());
    let shot = dir.join("shot.png");
    let browse = |extra: &[&str]| {
        let o = Command::new(&chromium)
            .args(["--headless", "--disable-gpu", "--no-sandbox", "--hide-scrollbars"])
            .args(["--window-size=1200,2000", "--enable-logging=stderr", "--v=0"])
            .args(extra)
            .arg(&url)
            .output()
            .unwrap();
        assert!(o.status.success(), "chromium: {}", stderr(&o));
        // Every console message (errors, failed loads, warnings) is logged as CONSOLE.
        let log = stderr(&o);
        let console: Vec<&str> = log.lines().filter(|l| l.contains(":CONSOLE")).collect();
        assert!(console.is_empty(), "console messages: {console:#?}");
        o
    };
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
