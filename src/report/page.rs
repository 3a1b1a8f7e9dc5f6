//! The report page: raypack against Embree by ray kind ([`engines`]), then
//! per bench result file, the command that made it, its environment, a chart per group of
//! figures (one figure name and unit, one scene; a `bench matrix` result is
//! one table instead, [`matrix`]), thread scaling where more
//! than one thread count was measured, growth over scene sizes where scenes
//! of several sizes were, and the comparison with a baseline when the run
//! made one; then per robustness result file its tables ([`robustness`]).

use std::fmt::Write as _;

use crate::bench::change::Comparison;
use crate::bench::figure::Figure;
use crate::report::chart::{Bar, interval_bars};
use crate::report::engines;
use crate::report::html::{escape, pairs_table, png_image, svg_image};
use crate::report::lines::{Line, XAxis, over};
use crate::report::matrix;
use crate::report::robustness;
use crate::report::{Input, ReportError, RobustnessInput};

/// A picture shown with the figures: an annotated render, a heat map.
#[derive(Clone, Debug)]
pub struct Picture {
    /// Its caption (the file name).
    pub name: String,
    /// The PNG file's bytes.
    pub png: Vec<u8>,
}

/// The order labels are read in a bar's label; others follow by name.
const LABEL_ORDER: [&str; 6] = ["primitive", "rays", "engine", "kernel", "block", "threads"];

/// The labels that make a chart of their own rather than a bar of one (a
/// scene's size goes with the scene).
const CHART_LABELS: [&str; 2] = ["scene", "primitives"];

/// Throughput over thread counts, a chart per scene.
const SCALING: Curves = Curves {
    x: XAxis {
        name: "threads",
        log: false,
    },
    per: &["scene"],
};

/// Throughput over scene sizes, a chart per ray kind and thread count.
const GROWTH: Curves = Curves {
    x: XAxis {
        name: "primitives",
        log: true,
    },
    per: &["rays", "threads"],
};

const STYLE: &str = "body{font-family:sans-serif;max-width:1000px;margin:1em auto;color:#222}\
h1{font-size:1.6em}h2{font-size:1.3em;border-bottom:1px solid #ccc;margin-top:2em}\
table{border-collapse:collapse;font-size:0.85em;margin:0.5em 0}\
td,th{border:1px solid #ddd;padding:2px 8px;text-align:left}\
td.num{text-align:right;font-variant-numeric:tabular-nums}\
.slower,.lower{color:#b00}.faster,.higher{color:#070}img{display:block;margin:1em 0;max-width:100%}\
td.wrong{color:#b00;font-weight:bold;background:#fdd}summary{cursor:pointer;font-size:0.85em}";

/// The page of bench results `inputs`, robustness results `robustness` and
/// `pictures`, made at `date`.
pub fn page(
    inputs: &[Input],
    robustness: &[RobustnessInput],
    pictures: &[Picture],
    date: &str,
) -> Result<String, ReportError> {
    let title = match (inputs.is_empty(), robustness.is_empty()) {
        (true, true) => return Err(ReportError::Empty),
        (false, true) => "raypack benchmark report",
        (true, false) => "raypack robustness report",
        (false, false) => "raypack benchmark and robustness report",
    };
    let names: Vec<String> = inputs
        .iter()
        .map(|i| escape(&i.name))
        .chain(robustness.iter().map(|i| escape(&i.name)))
        .collect();
    let mut out = String::new();
    // Writing to a String cannot fail.
    let _ = write!(
        out,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <title>{title}</title><style>{STYLE}</style></head><body>\n\
         <h1>{title}</h1>\n<p>Made {} from {}.",
        escape(date),
        names.join(", ")
    );
    if !inputs.is_empty() {
        out.push_str(
            " Each bar reaches the median of its samples; its whisker spans the median's 95% \
             confidence interval (order statistics). A pale bar marked * is noisy: its interval \
             reaches beyond ±5% of the median. Ratios come from samples paired round by round.",
        );
    }
    out.push_str("</p>\n");
    if let Some(table) = engines::table(inputs) {
        out.push_str(&table);
    }
    if let Some(table) = engines::every_engine_table(inputs) {
        out.push_str(&table);
    }
    for input in inputs {
        section(&mut out, input)?;
    }
    for input in robustness {
        robustness::section(&mut out, input);
    }
    if !pictures.is_empty() {
        out.push_str("<section><h2>Pictures</h2>\n");
        for p in pictures {
            let _ = writeln!(
                out,
                "<figure>{}<figcaption>{}</figcaption></figure>",
                png_image(&p.png, &p.name),
                escape(&p.name)
            );
        }
        out.push_str("</section>\n");
    }
    out.push_str("</body></html>\n");
    Ok(out)
}

/// One result file's section.
fn section(out: &mut String, input: &Input) -> Result<(), ReportError> {
    let r = &input.result;
    let command = if r.arguments.is_empty() {
        format!("bench {}", r.command)
    } else {
        r.arguments.join(" ")
    };
    let _ = writeln!(
        out,
        "<section><h2>{}: <code>raypack {}</code></h2>",
        escape(&input.name),
        escape(&command)
    );
    out.push_str(&pairs_table(&r.environment.rows()));
    // A matrix is one table: its cells are ratios, and a chart per scene would repeat it.
    let charts = if matrix::is_matrix(input) {
        out.push_str(&matrix::table(input));
        Vec::new()
    } else {
        groups(&r.figures)
    };
    for group in charts {
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
    let unit = r
        .figures
        .iter()
        .find(|f| f.name == "throughput")
        .map_or("", |f| &f.unit);
    for curves in [SCALING, GROWTH] {
        for (chart, lines) in curves.lines(&r.figures) {
            let title = format!("throughput over {}, {chart}", curves.x.name);
            let svg = over(&title, curves.x, unit, &lines)?;
            out.push_str(&svg_image(&svg, &title));
            out.push('\n');
        }
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
fn bar_label(f: &Figure, skip: &[&str]) -> String {
    let ordered = LABEL_ORDER.iter().copied().chain(
        f.labels
            .keys()
            .map(String::as_str)
            .filter(|k| !LABEL_ORDER.contains(k)),
    );
    ordered
        .filter(|k| !CHART_LABELS.contains(k) && !skip.contains(k))
        .map(|k| bar_label_of(f, k))
        .filter(|v| !v.is_empty())
        .collect::<Vec<_>>()
        .join(" ")
}

/// The label `name` of `f` as a bar shows it (`2t` for two threads), or "".
fn bar_label_of(f: &Figure, name: &str) -> String {
    match f.labels.get(name) {
        Some(v) if name == "threads" => format!("{v}t"),
        Some(v) => v.clone(),
        None => String::new(),
    }
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
                label: format!("{}{mark}", bar_label(f, &[])),
                summary: f.summary,
                colour,
            }
        })
        .collect()
}

/// Throughput figures as lines over a numeric label: a chart per value of
/// the `per` labels, a line per variant (the other labels but the scene).
#[derive(Clone, Copy)]
struct Curves {
    x: XAxis<'static>,
    per: &'static [&'static str],
}

impl Curves {
    /// The charts, each named by its `per` labels, with their lines of two
    /// points or more (a chart only where some line has them).
    fn lines(&self, figures: &[Figure]) -> Vec<(String, Vec<Line>)> {
        let x = self.x.name;
        let mut charts: Vec<(String, Vec<Line>)> = Vec::new();
        for f in figures.iter().filter(|f| f.name == "throughput") {
            let Ok(value) = f.label(x).parse::<f64>() else {
                continue;
            };
            let chart = self
                .per
                .iter()
                .map(|l| bar_label_of(f, l))
                .collect::<Vec<_>>()
                .join(", ");
            let line = bar_label(f, &[&[x], self.per].concat());
            let at = match charts.iter().position(|(c, _)| *c == chart) {
                Some(at) => at,
                None => {
                    charts.push((chart, Vec::new()));
                    charts.len() - 1
                }
            };
            let lines = &mut charts[at].1;
            match lines.iter_mut().find(|l| l.label == line) {
                Some(l) => l.points.push((value, f.summary)),
                None => lines.push(Line {
                    label: line,
                    points: vec![(value, f.summary)],
                }),
            }
        }
        for (_, lines) in &mut charts {
            lines.retain(|l| l.points.len() > 1);
            for l in lines.iter_mut() {
                l.points.sort_by(|a, b| a.0.total_cmp(&b.0));
            }
        }
        charts.retain(|(_, lines)| !lines.is_empty());
        charts
    }
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
    use crate::statistics::Summary;

    fn figure(name: &str, labels: &[(&str, &str)], median: f64) -> Figure {
        let labels: Vec<(&str, String)> = labels.iter().map(|(k, v)| (*k, v.to_string())).collect();
        let s = Summary::of(&[median * 0.98, median, median * 1.02, median, median, median]).unwrap();
        Figure::new(name, "Mrays/s", Better::Higher, &labels, s)
    }

    /// A figure of `bench scene`'s labels: scene, kernel, threads.
    fn kernel_figure(name: &str, scene: &str, kernel: &str, threads: &str, median: f64) -> Figure {
        figure(
            name,
            &[("scene", scene), ("kernel", kernel), ("threads", threads)],
            median,
        )
    }

    fn input(figures: Vec<Figure>) -> Input {
        Input::of_figures("scene <1>.json", "scene", figures)
    }

    #[test]
    fn groups_by_name_and_scene_and_labels_bars_by_the_rest() {
        let figures = vec![
            kernel_figure("throughput", "a", "scalar", "1", 1.0),
            kernel_figure("throughput", "a", "packet8", "1", 2.0),
            kernel_figure("throughput", "b", "scalar", "1", 3.0),
            kernel_figure("ratio", "a", "scalar", "1", 1.0),
        ];
        let g = groups(&figures);
        assert_eq!(g.iter().map(Vec::len).collect::<Vec<_>>(), [2, 1, 1]);
        let b = bars(&g[0]);
        assert_eq!(b[0].label, "scalar 1t");
        assert_eq!((b[0].colour, b[1].colour), (0, 1));
    }

    #[test]
    fn scaling_needs_two_thread_counts() {
        let at = |threads: &str, m: f64| {
            figure(
                "throughput",
                &[("scene", "a"), ("kernel", "scalar"), ("threads", threads)],
                m,
            )
        };
        let mut figures = vec![at("1", 1.0), at("2", 1.9)];
        let charts = SCALING.lines(&figures);
        assert_eq!(charts.len(), 1);
        assert_eq!(charts[0].0, "a");
        assert_eq!(charts[0].1[0].label, "scalar");
        assert_eq!(charts[0].1[0].points.len(), 2);
        figures.pop();
        assert!(SCALING.lines(&figures).is_empty());
    }

    #[test]
    fn growth_runs_across_scenes_by_size() {
        let of = |scene: &str, n: &str, kernel: &str, m: f64| {
            let labels = [
                ("scene", scene),
                ("primitives", n),
                ("rays", "primary"),
                ("kernel", kernel),
                ("threads", "1"),
            ];
            figure("throughput", &labels, m)
        };
        let figures = [
            of("mesh-10000", "9800", "single", 4.0),
            of("mesh-1000", "980", "single", 5.0),
            of("mesh-1000", "980", "packet8", 6.0),
        ];
        let charts = GROWTH.lines(&figures);
        assert_eq!(charts.len(), 1);
        let (chart, lines) = &charts[0];
        assert_eq!(chart, "primary, 1t");
        // packet8 has one size only: no line.
        assert_eq!(lines.len(), 1);
        assert_eq!(lines[0].label, "single");
        let sizes: Vec<f64> = lines[0].points.iter().map(|p| p.0).collect();
        assert_eq!(sizes, [980.0, 9800.0]);
        // The size goes with the scene: bars do not repeat it.
        assert_eq!(bar_label(&figures[0], &[]), "primary single 1t");
    }

    #[test]
    fn the_page_is_self_contained_and_escaped() {
        let figures = vec![
            kernel_figure("throughput", "a", "scalar", "1", 1.0),
            kernel_figure("throughput", "a", "scalar", "2", 1.9),
        ];
        let picture = Picture {
            name: "render <a>.png".into(),
            png: b"\x89PNG\r\n\x1a\n".to_vec(),
        };
        let html = page(&[input(figures)], &[], &[picture], "2026-01-01T00:00:00Z").unwrap();
        assert!(html.starts_with("<!DOCTYPE html>"));
        assert!(html.contains("scene &lt;1&gt;.json"));
        // Two charts (the group, the scaling) and the picture, inlined; nothing fetched.
        assert_eq!(html.matches("<img src=\"data:image/svg+xml;base64,").count(), 2);
        assert_eq!(html.matches("<img src=\"data:image/png;base64,").count(), 1);
        assert!(html.contains("<figcaption>render &lt;a&gt;.png</figcaption>"));
        assert!(!html.contains("http"), "nothing to fetch");
        assert!(matches!(page(&[], &[], &[], ""), Err(ReportError::Empty)));
    }

    #[test]
    fn a_page_of_robustness_results_alone_is_no_benchmark_report() {
        use crate::compare::robustness_result::RobustnessResult;
        let result = RobustnessResult::new(
            Vec::new(),
            crate::environment::Environment::collect(),
            Vec::new(),
            Vec::new(),
            Vec::new(),
        );
        let robustness = [RobustnessInput {
            name: "oracle.json".into(),
            result,
        }];
        let html = page(&[], &robustness, &[], "2026-01-01T00:00:00Z").unwrap();
        assert!(html.contains("<title>raypack robustness report</title>"));
        assert!(html.contains("<h2>Robustness oracle: oracle.json</h2>"));
        assert!(!html.to_lowercase().contains("benchmark") && !html.contains("whisker"));
        let both = page(&[input(Vec::new())], &robustness, &[], "").unwrap();
        assert!(both.contains("<title>raypack benchmark and robustness report</title>"));
    }
}
