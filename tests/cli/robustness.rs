//! `raypack robustness` through the binary, on the tetrahedron (small enough
//! for a test): its JSON read back by `raypack report`, which tables the
//! same numbers; its crack pictures, one valid PNG per engine; and the
//! user's errors (an unusable picture directory, a broken result file).

use raypack::compare::crack_image::SIZE;
use serde_json::Value;

use crate::support::cli::{raypack, scratch, stderr};

/// The oracle on the tetrahedron with few sampled rays, then `extra`.
fn tetrahedron(extra: &[&str]) -> std::process::Output {
    let args = [
        "robustness",
        "--shape",
        "tetrahedron",
        "--spawn-points",
        "20",
        "--random-rays",
        "50",
        "--query-points",
        "100",
    ];
    raypack(&[&args[..], extra].concat())
}

/// A count's cell as the report writes it: marked unless zero.
fn count(v: &Value) -> String {
    match v.as_u64().unwrap() {
        0 => "<td class=\"num\">0</td>".into(),
        n => format!("<td class=\"num wrong\">{n}</td>"),
    }
}

#[test]
fn the_report_tables_a_robustness_result_with_its_numbers() {
    let dir = scratch("robustness-report");
    let o = tetrahedron(&["--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let json: Value = serde_json::from_slice(&o.stdout).expect("JSON on stdout");
    assert_eq!(json["command"], "raypack robustness");
    assert!(json["environment"]["cpu_model"].is_string() && json["environment"]["isa"].is_string());
    let result = dir.join("oracle.json");
    std::fs::write(&result, &o.stdout).unwrap();
    let page = dir.join("report.html");
    let o = raypack(&["report", result.to_str().unwrap(), "-o", page.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let html = std::fs::read_to_string(&page).unwrap();
    assert!(html.contains("<title>raypack robustness report</title>"));
    assert!(!html.contains("benchmark"), "only robustness results");
    assert!(html.contains("<h2>Robustness oracle: oracle.json</h2>"));
    let totals = json["totals"].as_array().unwrap();
    assert!(totals.len() >= 6 * 5, "six raypack engines, five categories");
    for t in totals {
        let row = format!(
            "<tr><td>{}</td><td>all</td><td>all</td><td class=\"num\">{}</td>{}{}{}\
             <td class=\"num\">{:.1}</td><td class=\"num\">{:.1}</td><td class=\"num\">{:.1}</td></tr>",
            t["engine"].as_str().unwrap(),
            t["rays"],
            count(&t["leaks"]),
            count(&t["false_hits"]),
            count(&t["self_hits"]),
            t["t_ulps"]["p50"].as_f64().unwrap(),
            t["t_ulps"]["p99"].as_f64().unwrap(),
            t["t_ulps"]["max"].as_f64().unwrap(),
        );
        assert!(html.contains(&row), "{row} missing");
    }
    for q in json["queries"].as_array().unwrap() {
        let row = format!(
            "<tr><td>tetrahedron</td><td>{}</td><td class=\"num\">{}</td>{}<td class=\"num\">{}</td>{}</tr>",
            q["test"].as_str().unwrap(),
            q["points"],
            count(&q["wrong_inside"]),
            q["rays"],
            count(&q["wrong_crossings"]),
        );
        assert!(html.contains(&row), "{row} missing");
    }
    // Every row of a category sits in it: five tables of totals, five of rows.
    for category in ["edges-vertices", "grazing", "spawned", "far-small", "against-f64"] {
        assert!(html.contains(&format!("<h3>{category}</h3>")), "{category}");
    }
    let rows = json["rows"].as_array().unwrap().len();
    assert_eq!(
        html.matches("<tr><td>").count(),
        totals.len() + rows + json["queries"].as_array().unwrap().len()
    );

    // A result that says it is one but is not: the user's error, naming the file.
    let broken = dir.join("broken.json");
    std::fs::write(&broken, "{\"command\": \"raypack robustness\", \"rows\": 3}\n").unwrap();
    std::fs::remove_file(&page).unwrap();
    let o = raypack(&["report", broken.to_str().unwrap(), "-o", page.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("broken.json:1: not a robustness result"),
        "{}",
        stderr(&o)
    );
    assert!(!page.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn crack_pictures_are_one_png_per_mesh_and_engine() {
    let dir = scratch("robustness-cracks");
    // Made if missing.
    let cracks = dir.join("cracks");
    let o = tetrahedron(&["--json", "--crack-images", cracks.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let json: Value = serde_json::from_slice(&o.stdout).unwrap();
    let mut engines: Vec<&str> = json["totals"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["engine"].as_str().unwrap())
        .collect();
    engines.sort_unstable();
    engines.dedup();
    let mut written: Vec<String> = std::fs::read_dir(&cracks)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    written.sort();
    let mut expected: Vec<String> = engines
        .iter()
        .map(|e| format!("tetrahedron-{}.png", e.replace(' ', "-")))
        .collect();
    expected.sort();
    assert_eq!(written, expected, "one per engine, nothing else left");
    assert!(written.contains(&"tetrahedron-raypack-watertight-packet8.png".to_string()));
    for name in &written {
        let img = image::open(cracks.join(name)).expect("a PNG").to_rgb8();
        assert_eq!(img.width(), SIZE, "{name}");
        assert!(img.height() > SIZE, "{name}: a caption below the picture");
    }

    // A directory that cannot be made: the user's error, before any work.
    let file = dir.join("a-file");
    std::fs::write(&file, "").unwrap();
    let o = tetrahedron(&["--crack-images", file.join("cracks").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("a-file/cracks"), "{}", stderr(&o));
    assert!(o.stdout.is_empty(), "no table: nothing ran");
    std::fs::remove_dir_all(&dir).unwrap();
}
