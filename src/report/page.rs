//! The report page: per result file, its environment, a chart per group of
//! figures (one figure name and unit, one scene), thread scaling where more
//! than one thread count was measured, and the comparison with a baseline
//! when the run made one.

use std::fmt::Write as _;

use crate::bench::change::Comparison;
use crate::bench::figure::Figure;
use crate::bench::result::StoredResult;
use crate::report::ReportError;
use crate::report::chart::{Bar, interval_bars};
use crate::report::html::{escape, svg_image};
use crate::report::scaling::{Line, thread_scaling};

/// A result file to report.
#[derive(Debug, Clone)]
pub struct Input {
    /// Its name on the page (the file name).
    pub name: String,
    /// What it holds.
    pub result: StoredResult,
}

/// The order labels are read in a bar's label; others follow by name.
const LABEL_ORDER: [&str; 6] = ["primitive", "rays", "engine", "kernel", "block", "threads"];

/// The labels that make a chart of their own rather than a bar of one.
const CHART_LABELS: [&str; 1] = ["scene"];

const STYLE: &str = "body{font-family:sans-serif;max-width:1000px;margin:1em auto;color:#222}\
h1{font-size:1.6em}h2{font-size:1.3em;border-bottom:1px solid #ccc;margin-top:2em}\
table{border-collapse:collapse;font-size:0.85em;margin:0.5em 0}\
td,th{border:1px solid #ddd;padding:2px 8px;text-align:left}\
td.num{text-align:right;font-variant-numeric:tabular-nums}\
.slower,.lower{color:#b00}.faster,.higher{color:#070}img{display:block;margin:1em 0;max-width:100%}";

/// The page of `inputs`, made at `date`.
pub fn page(inputs: &[Input], date: &str) -> Result<String, ReportError> {
    if inputs.is_empty() {
        return Err(ReportError::Empty);
    }
    let mut out = String::new();
    // Writing to a String cannot fail.
    let _ = write!(
        out,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <title>raypack benchmark report</title><style>{STYLE}</style></head><body>\n\
         <h1>raypack benchmark report</h1>\n<p>Made {} from {}. Each bar reaches the median of \
         its samples; its whisker spans the median's 95% confidence interval (order statistics). \
         A pale bar marked * is noisy: its interval reaches beyond ±5% of the median. Ratios \
         come from samples paired round by round.</p>\n",
        escape(date),
        inputs
            .iter()
            .map(|i| escape(&i.name))
            .collect::<Vec<_>>()
            .join(", ")
    );
    for input in inputs {
        section(&mut out, input)?;
    }
    out.push_str("</body></html>\n");
    Ok(out)
}

/// One result file's section.
fn section(out: &mut String, input: &Input) -> Result<(), ReportError> {
    let r = &input.result;
    let _ = writeln!(
        out,
        "<section><h2>{}: <code>raypack bench {}</code></h2>",
        escape(&input.name),
        escape(&r.command)
    );
    out.push_str("<table><tbody>");
    for (name, value) in r.environment.rows() {
        let _ = write!(
            out,
            "<tr><th>{}</th><td>{}</td></tr>",
            escape(name),
            escape(&value)
        );
    }
    out.push_str("</tbody></table>\n");
    for group in groups(&r.figures) {
        let first = group[0];
        let scene = first.label("scene");
        let title = if scene.is_empty() {
            first.name.clone()
        } else {
            format!("{}, {scene}", first.name)
        };
        let svg = interval_bars(&title, &first.unit, &bars(&group))?;
        out.push_str(&svg_image(&svg, &title));
        out.push('\n');
    }
    for (scene, lines) in scaling(&r.figures) {
        let title = format!("throughput over threads, {scene}");
        let unit = r
            .figures
            .iter()
            .find(|f| f.name == "throughput")
            .map_or("", |f| &f.unit);
        let svg = thread_scaling(&title, unit, &lines)?;
        out.push_str(&svg_image(&svg, &title));
        out.push('\n');
    }
    if let Some(c) = &r.comparison {
        comparison(out, c);
    }
    out.push_str("</section>\n");
    Ok(())
}

/// The figures grouped by name, unit and scene, in order of appearance.
fn groups(figures: &[Figure]) -> Vec<Vec<&Figure>> {
    fn key(f: &Figure) -> Vec<&str> {
        let mut k = vec![f.name.as_str(), f.unit.as_str()];
        k.extend(CHART_LABELS.iter().map(|l| f.label(l)));
        k
    }
    let mut groups: Vec<Vec<&Figure>> = Vec::new();
    for f in figures {
        match groups.iter_mut().find(|g| key(g[0]) == key(f)) {
            Some(g) => g.push(f),
            None => groups.push(vec![f]),
        }
    }
    groups
}

/// A figure's label on its bar or line: its labels but the chart's and `skip`.
fn bar_label(f: &Figure, skip: &str) -> String {
    let ordered = LABEL_ORDER.iter().copied().chain(
        f.labels
            .keys()
            .map(String::as_str)
            .filter(|k| !LABEL_ORDER.contains(k)),
    );
    ordered
        .filter(|k| !CHART_LABELS.contains(k) && *k != skip)
        .filter_map(|k| {
            let v = f.labels.get(k)?;
            Some(if k == "threads" {
                format!("{v}t")
            } else {
                v.clone()
            })
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// The bars of a group, coloured by kernel.
fn bars(group: &[&Figure]) -> Vec<Bar> {
    let mut kernels: Vec<&str> = Vec::new();
    group
        .iter()
        .map(|f| {
            let kernel = f.label("kernel");
            let colour = kernels.iter().position(|k| *k == kernel).unwrap_or_else(|| {
                kernels.push(kernel);
                kernels.len() - 1
            });
            let mark = if f.summary.noisy { " *" } else { "" };
            Bar {
                label: format!("{}{mark}", bar_label(f, "")),
                summary: f.summary,
                colour,
            }
        })
        .collect()
}

/// Per scene with more than one thread count: a line per variant of the
/// throughput figures over their thread counts.
fn scaling(figures: &[Figure]) -> Vec<(String, Vec<Line>)> {
    let throughput: Vec<&Figure> = figures
        .iter()
        .filter(|f| f.name == "throughput" && !f.label("threads").is_empty())
        .collect();
    let mut scenes: Vec<&str> = Vec::new();
    for f in &throughput {
        if !scenes.contains(&f.label("scene")) {
            scenes.push(f.label("scene"));
        }
    }
    scenes
        .into_iter()
        .filter_map(|scene| {
            let mut lines: Vec<Line> = Vec::new();
            for f in throughput.iter().filter(|f| f.label("scene") == scene) {
                let Ok(threads) = f.label("threads").parse::<f64>() else {
                    continue;
                };
                let label = bar_label(f, "threads");
                match lines.iter_mut().find(|l| l.label == label) {
                    Some(l) => l.points.push((threads, f.summary)),
                    None => lines.push(Line {
                        label,
                        points: vec![(threads, f.summary)],
                    }),
                }
            }
            lines.retain(|l| l.points.len() > 1);
            for l in &mut lines {
                l.points.sort_by(|a, b| a.0.total_cmp(&b.0));
            }
            (!lines.is_empty()).then(|| (scene.to_string(), lines))
        })
        .collect()
}

/// The comparison with a baseline as a table.
fn comparison(out: &mut String, c: &Comparison) {
    let _ = write!(
        out,
        "<h3>Against baseline {} (commit {}, {})</h3><p>A change counts when its whole interval \
         lies beyond ±{}%.</p><table><thead><tr><th>figure</th><th>baseline</th><th>this run</th>\
         <th>change</th><th>interval</th><th>verdict</th></tr></thead><tbody>",
        escape(&c.baseline),
        escape(&c.baseline_commit),
        escape(&c.baseline_date),
        100.0 * c.noise_threshold
    );
    for x in &c.changes {
        let words = x.verdict.words();
        let _ = write!(
            out,
            "<tr><td>{}</td><td class=\"num\">{:.4}</td><td class=\"num\">{:.4}</td>\
             <td class=\"num\">{:+.1}%</td><td class=\"num\">[{:+.1}%, {:+.1}%]</td>\
             <td class=\"{}\">{}</td></tr>",
            escape(&x.key),
            x.baseline,
            x.current,
            100.0 * x.change,
            100.0 * x.change_low,
            100.0 * x.change_high,
            words.replace(' ', "-"),
            escape(words)
        );
    }
    out.push_str("</tbody></table>\n");
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::figure::Better;
    use crate::environment::Environment;
    use crate::statistics::Summary;

    fn figure(name: &str, labels: &[(&str, &str)], median: f64) -> Figure {
        let labels: Vec<(&str, String)> = labels.iter().map(|(k, v)| (*k, v.to_string())).collect();
        let s = Summary::of(&[median * 0.98, median, median * 1.02, median, median, median]).unwrap();
        Figure::new(name, "Mrays/s", Better::Higher, &labels, s)
    }

    fn input(figures: Vec<Figure>) -> Input {
        Input {
            name: "scene <1>.json".into(),
            result: StoredResult {
                command: "scene".into(),
                environment: Environment::collect(),
                rows: Vec::new(),
                figures,
                comparison: None,
            },
        }
    }

    #[test]
    fn groups_by_name_and_scene_and_labels_bars_by_the_rest() {
        let figures = vec![
            figure(
                "throughput",
                &[("scene", "a"), ("kernel", "scalar"), ("threads", "1")],
                1.0,
            ),
            figure(
                "throughput",
                &[("scene", "a"), ("kernel", "packet8"), ("threads", "1")],
                2.0,
            ),
            figure(
                "throughput",
                &[("scene", "b"), ("kernel", "scalar"), ("threads", "1")],
                3.0,
            ),
            figure(
                "ratio",
                &[("scene", "a"), ("kernel", "scalar"), ("threads", "1")],
                1.0,
            ),
        ];
        let g = groups(&figures);
        assert_eq!(g.iter().map(Vec::len).collect::<Vec<_>>(), [2, 1, 1]);
        let b = bars(&g[0]);
        assert_eq!(b[0].label, "scalar 1t");
        assert_eq!((b[0].colour, b[1].colour), (0, 1));
    }

    #[test]
    fn scaling_needs_two_thread_counts() {
        let mut figures = vec![
            figure(
                "throughput",
                &[("scene", "a"), ("kernel", "scalar"), ("threads", "1")],
                1.0,
            ),
            figure(
                "throughput",
                &[("scene", "a"), ("kernel", "scalar"), ("threads", "2")],
                1.9,
            ),
        ];
        let lines = scaling(&figures);
        assert_eq!(lines.len(), 1);
        assert_eq!(lines[0].1[0].label, "scalar");
        assert_eq!(lines[0].1[0].points.len(), 2);
        figures.pop();
        assert!(scaling(&figures).is_empty());
    }

    #[test]
    fn the_page_is_self_contained_and_escaped() {
        let figures = vec![
            figure(
                "throughput",
                &[("scene", "a"), ("kernel", "scalar"), ("threads", "1")],
                1.0,
            ),
            figure(
                "throughput",
                &[("scene", "a"), ("kernel", "scalar"), ("threads", "2")],
                1.9,
            ),
        ];
        let html = page(&[input(figures)], "2026-01-01T00:00:00Z").unwrap();
        assert!(html.starts_with("<!DOCTYPE html>"));
        assert!(html.contains("scene &lt;1&gt;.json"));
        // Two images (the group, the scaling), inlined; nothing fetched.
        assert_eq!(html.matches("<img src=\"data:image/svg+xml;base64,").count(), 2);
        assert!(!html.contains("http"), "nothing to fetch");
        assert!(matches!(page(&[], ""), Err(ReportError::Empty)));
    }
}
