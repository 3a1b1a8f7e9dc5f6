//! The report's table of raypack against Embree: per result file, scene and
//! thread count, each ray kind's best raypack path (single rays or packets)
//! against Embree's best path and setting, the same rays in one run, and the
//! build times. Best against best is the comparison issue 17 asks for: a
//! reader who picks the faster of each engine's ways to trace gets these.

use std::fmt::Write as _;

use crate::bench::figure::Figure;
use crate::report::Input;
use crate::report::html::escape;

/// The ray kinds in the order `bench traversal` names them; others follow.
const KIND_ORDER: [&str; 5] = ["primary", "shadow", "ao", "diffuse", "random"];

/// The engine label of raypack's figures; any other engine is a rival.
const RAYPACK: &str = "raypack";

/// One row: where it comes from, and per column (ray kinds, then the build)
/// raypack's figure against the rivals' best (None where one is missing).
struct Row<'a> {
    input: &'a str,
    scene: &'a str,
    threads: &'a str,
    cells: Vec<Option<Cell>>,
}

/// raypack's best median against the rivals' best, and whether higher is better.
#[derive(Clone, Copy)]
struct Cell {
    raypack: f64,
    rival: f64,
    higher_is_better: bool,
}

impl Cell {
    /// raypack's figure over the rival's: above 1 is faster for throughput,
    /// below 1 for build times.
    fn ratio(&self) -> f64 {
        self.raypack / self.rival
    }

    /// True where raypack is at least as fast.
    fn ahead(&self) -> bool {
        if self.higher_is_better {
            self.ratio() >= 1.0
        } else {
            self.ratio() <= 1.0
        }
    }
}

/// The best of `values`: the highest, or the lowest where lower is better.
fn best_value(values: impl Iterator<Item = f64>, higher_is_better: bool) -> Option<f64> {
    values.reduce(|a, b| if (a < b) == higher_is_better { b } else { a })
}

/// The best median among `figures` for raypack (`ours`) or for the rivals.
fn best<'a>(figures: impl Iterator<Item = &'a Figure>, ours: bool, higher_is_better: bool) -> Option<f64> {
    let medians = figures
        .filter(|f| (f.label("engine") == RAYPACK) == ours)
        .map(|f| f.summary.median);
    best_value(medians, higher_is_better)
}

/// The (scene, threads) pairs of the throughput figures of `figures`, once
/// each, in order of appearance.
fn scenes_and_threads(figures: &[Figure]) -> Vec<(&str, &str)> {
    let mut keys: Vec<(&str, &str)> = Vec::new();
    for f in figures.iter().filter(|f| f.name == "throughput") {
        let key = (f.label("scene"), f.label("threads"));
        if !keys.contains(&key) {
            keys.push(key);
        }
    }
    keys
}

/// The cell of `figures` (one scene, thread count and kind or build), if
/// both raypack and a rival were measured.
fn cell<'a>(figures: impl Iterator<Item = &'a Figure> + Clone, higher_is_better: bool) -> Option<Cell> {
    Some(Cell {
        raypack: best(figures.clone(), true, higher_is_better)?,
        rival: best(figures, false, higher_is_better)?,
        higher_is_better,
    })
}

/// The rows of one result file: a row per scene and thread count with both
/// engines' throughput, in order of appearance; columns `kinds` then `build`.
fn rows<'a>(input: &'a Input, kinds: &[&str]) -> Vec<Row<'a>> {
    let figures = &input.result.figures;
    scenes_and_threads(figures)
        .into_iter()
        .filter_map(|(scene, threads)| {
            let here = figures
                .iter()
                .filter(move |f| f.label("scene") == scene && f.label("threads") == threads);
            let mut cells: Vec<Option<Cell>> = kinds
                .iter()
                .map(|&kind| {
                    let of_kind = here
                        .clone()
                        .filter(move |f| f.name == "throughput" && f.label("rays") == kind);
                    cell(of_kind, true)
                })
                .collect();
            cells.push(cell(here.clone().filter(|f| f.name == "build"), false));
            cells.iter().any(Option::is_some).then_some(Row {
                input: &input.name,
                scene,
                threads,
                cells,
            })
        })
        .collect()
}

/// The ray kinds among the throughput figures of `inputs`, in
/// [`KIND_ORDER`] and then in order of appearance.
fn kinds(inputs: &[Input]) -> Vec<&str> {
    let mut seen: Vec<&str> = Vec::new();
    for f in inputs
        .iter()
        .flat_map(|i| &i.result.figures)
        .filter(|f| f.name == "throughput")
    {
        let kind = f.label("rays");
        if !kind.is_empty() && !seen.contains(&kind) {
            seen.push(kind);
        }
    }
    let rank = |k: &str| {
        KIND_ORDER
            .iter()
            .position(|o| *o == k)
            .unwrap_or(KIND_ORDER.len())
    };
    // A stable sort keeps the unknown kinds in order of appearance.
    seen.sort_by_key(|k| rank(k));
    seen
}

/// `v` to three significant digits (two decimals below 10, none from 100).
fn significant(v: f64) -> String {
    let decimals = match v.abs() {
        a if a >= 100.0 => 0,
        a if a >= 10.0 => 1,
        a if a >= 1.0 => 2,
        _ => 3,
    };
    format!("{v:.decimals$}")
}

/// The table as HTML, or None where no result file measured raypack and
/// another engine on the same ray kinds.
pub fn table(inputs: &[Input]) -> Option<String> {
    let kinds = kinds(inputs);
    let rows: Vec<Row> = inputs
        .iter()
        .filter(|i| i.result.command.starts_with("traversal"))
        .flat_map(|i| rows(i, &kinds))
        .collect();
    if rows.is_empty() {
        return None;
    }
    let mut out = String::from(
        "<section><h2>raypack against Embree, by ray kind</h2>\n<p>Per scene and thread count: \
         raypack's best path (single rays, 8- or 16-ray packets, as its results measured them) / \
         Embree's best (<code>rtcIntersect1</code> / <code>rtcOccluded1</code>, 8- or 16-wide \
         packets, at <code>isa=avx2</code> or its default; \
         packets whose rays point one way carry its coherent-ray flag), medians in Mrays/s of the \
         same rays in one run, and their ratio; build: milliseconds, raypack's against Embree's \
         faster setting (below 1× is faster). Each file's command and machine are in its section \
         below.</p>\n<table><thead><tr><th>results</th><th>scene</th>\
         <th>threads</th>",
    );
    for kind in &kinds {
        let _ = write!(out, "<th>{}</th>", escape(kind));
    }
    out.push_str("<th>build</th></tr></thead><tbody>\n");
    for row in &rows {
        let _ = write!(
            out,
            "<tr><td>{}</td><td>{}</td><td class=\"num\">{}</td>",
            escape(row.input),
            escape(row.scene),
            escape(row.threads)
        );
        for c in &row.cells {
            match c {
                Some(c) => {
                    let _ = write!(
                        out,
                        "<td class=\"num {}\">{} / {} ({:.2}×)</td>",
                        if c.ahead() { "faster" } else { "slower" },
                        significant(c.raypack),
                        significant(c.rival),
                        c.ratio()
                    );
                }
                None => out.push_str("<td></td>"),
            }
        }
        out.push_str("</tr>\n");
    }
    out.push_str("</tbody></table></section>\n");
    Some(out)
}

/// An engine's family: its label without a setting (`embree(avx2)` → `embree`).
fn family(engine: &str) -> &str {
    engine.split('(').next().unwrap_or(engine)
}

/// The table of every engine side by side, from the traversal results that
/// measured three engine families or more (None where none did): per result file, scene, thread count
/// and ray kind (and build), each family's best median over its paths and
/// settings, and its ratio to the best of the others (above 1× for
/// throughput, below 1× for builds, is ahead of every peer).
pub fn every_engine_table(inputs: &[Input]) -> Option<String> {
    let kinds = kinds(inputs);
    // The engine families of one result file, in order of appearance.
    let families_of = |input: &'_ Input| -> Vec<String> {
        let mut families: Vec<String> = Vec::new();
        for f in input.result.figures.iter().filter(|f| f.name == "throughput") {
            let engine = family(f.label("engine"));
            if !families.iter().any(|e| e == engine) {
                families.push(engine.to_string());
            }
        }
        families
    };
    // Two families are the table of raypack against Embree already.
    let traversal: Vec<&Input> = inputs
        .iter()
        .filter(|i| i.result.command.starts_with("traversal") && families_of(i).len() >= 3)
        .collect();
    let mut families: Vec<String> = Vec::new();
    for engine in traversal.iter().flat_map(|i| families_of(i)) {
        if !families.contains(&engine) {
            families.push(engine);
        }
    }
    if families.is_empty() {
        return None;
    }
    let mut out = String::from(
        "<section><h2>Every engine, by ray kind</h2>\n<p>Per scene, thread count and ray kind: each \
         engine's best median (over its paths and settings; Mrays/s, build in ms) on the same rays \
         in one run, and its ratio to the best of the others; n/a where an engine does not trace \
         the scene or the ray kind (the peers without an any-hit query: shadow and ao).</p>\n<table><thead><tr><th>results</th><th>scene</th><th>threads</th><th>rays</th>",
    );
    for engine in &families {
        let _ = write!(out, "<th>{}</th>", escape(engine));
    }
    out.push_str("</tr></thead><tbody>\n");
    for input in traversal {
        let figures = &input.result.figures;
        for (scene, threads) in scenes_and_threads(figures) {
            let here = |f: &&Figure| f.label("scene") == scene && f.label("threads") == threads;
            let columns = kinds
                .iter()
                .map(|&k| (k, "throughput", true))
                .chain([("build", "build", false)]);
            for (kind, name, higher_is_better) in columns {
                let of_kind = |f: &&Figure| f.name == name && (name == "build" || f.label("rays") == kind);
                let best_of = |engine: &str| {
                    let medians = figures
                        .iter()
                        .filter(here)
                        .filter(of_kind)
                        .filter(|f| family(f.label("engine")) == engine)
                        .map(|f| f.summary.median);
                    best_value(medians, higher_is_better)
                };
                let medians: Vec<Option<f64>> = families.iter().map(|e| best_of(e)).collect();
                if medians.iter().flatten().count() < 2 {
                    continue;
                }
                let _ = write!(
                    out,
                    "<tr><td>{}</td><td>{}</td><td class=\"num\">{}</td><td>{}</td>",
                    escape(&input.name),
                    escape(scene),
                    escape(threads),
                    escape(kind)
                );
                for (e, median) in medians.iter().enumerate() {
                    let Some(m) = median else {
                        out.push_str("<td>n/a</td>");
                        continue;
                    };
                    let others = medians
                        .iter()
                        .enumerate()
                        .filter(|&(o, _)| o != e)
                        .filter_map(|(_, v)| *v);
                    // Another engine is always there: rows have two medians or more.
                    let cell = Cell {
                        raypack: *m,
                        rival: best_value(others, higher_is_better).unwrap_or(*m),
                        higher_is_better,
                    };
                    let _ = write!(
                        out,
                        "<td class=\"num {}\">{} ({:.2}×)</td>",
                        if cell.ahead() { "faster" } else { "slower" },
                        significant(*m),
                        cell.ratio()
                    );
                }
                out.push_str("</tr>\n");
            }
        }
    }
    out.push_str("</tbody></table></section>\n");
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::figure::Better;
    use crate::statistics::Summary;

    fn figure(name: &str, labels: &[(&str, &str)], median: f64) -> Figure {
        let labels: Vec<(&str, String)> = labels.iter().map(|(k, v)| (*k, v.to_string())).collect();
        let s = Summary::of(&[median, median, median]).unwrap();
        let (unit, better) = if name == "build" {
            ("ms", Better::Lower)
        } else {
            ("Mrays/s", Better::Higher)
        };
        Figure::new(name, unit, better, &labels, s)
    }

    fn throughput(engine: &str, kernel: &str, rays: &str, median: f64) -> Figure {
        figure(
            "throughput",
            &[
                ("scene", "dragon"),
                ("threads", "1"),
                ("engine", engine),
                ("kernel", kernel),
                ("rays", rays),
            ],
            median,
        )
    }

    fn input(command: &str, figures: Vec<Figure>) -> Input {
        Input::of_figures("traversal-dragon.json", command, figures)
    }

    /// Each cell is the best raypack path against the best rival path and
    /// setting; kinds come in the bench's order; builds compare the faster.
    #[test]
    fn best_against_best_per_kind_and_build() {
        let build = |engine: &str, ms: f64| {
            figure(
                "build",
                &[("scene", "dragon"), ("threads", "1"), ("engine", engine)],
                ms,
            )
        };
        let figures = vec![
            throughput("raypack", "single", "diffuse", 3.9),
            throughput("raypack", "packet8", "diffuse", 3.5),
            throughput("embree(avx2)", "packet8", "diffuse", 4.2),
            throughput("embree(default)", "single", "diffuse", 4.0),
            throughput("raypack", "packet8", "primary", 28.0),
            throughput("embree(avx2)", "packet8", "primary", 16.0),
            build("raypack", 300.0),
            build("embree(avx2)", 420.0),
            build("embree(default)", 400.0),
        ];
        let html = table(&[input("traversal assets/dragon.ply", figures)]).expect("a table");
        let primary = html.find("<th>primary</th>").unwrap();
        let diffuse = html.find("<th>diffuse</th>").unwrap();
        assert!(primary < diffuse, "{html}");
        assert!(html.contains("28.0 / 16.0 (1.75×)"), "{html}");
        assert!(html.contains("\"num slower\">3.90 / 4.20 (0.93×)"), "{html}");
        assert!(html.contains("\"num faster\">300 / 400 (0.75×)"), "{html}");
        assert_eq!(significant(0.4581), "0.458");
    }

    /// No table without a rival engine, nor from other commands.
    #[test]
    fn needs_two_engines_in_a_traversal_result() {
        let ours = vec![throughput("raypack", "single", "ao", 5.0)];
        assert!(table(&[input("traversal assets/dragon.ply", ours)]).is_none());
        let both = vec![
            throughput("raypack", "single", "ao", 5.0),
            throughput("embree(avx2)", "single", "ao", 5.0),
        ];
        assert!(table(&[input("scene scenes/spd_balls.nff", both.clone())]).is_none());
        assert!(table(&[input("traversal x", both)]).is_some());
    }

    /// One column per engine family, each cell its best against the best of the
    /// others; an engine that did not trace a kind is n/a.
    #[test]
    fn every_engine_against_the_best_of_the_others() {
        let figures = vec![
            throughput("raypack", "single", "ao", 6.0),
            throughput("raypack", "packet8", "ao", 5.0),
            throughput("embree(avx2)", "single", "ao", 4.0),
            throughput("embree(default)", "single", "ao", 5.0),
            throughput("obvhs", "single", "ao", 2.0),
            throughput("raypack", "single", "primary", 9.0),
            throughput("embree(avx2)", "packet8", "primary", 12.0),
        ];
        let html = every_engine_table(&[input("traversal assets/dragon.ply", figures)]).expect("a table");
        assert!(
            html.contains("<th>raypack</th><th>embree</th><th>obvhs</th>"),
            "{html}"
        );
        assert!(html.contains("\"num faster\">6.00 (1.20×)"), "{html}");
        assert!(html.contains("\"num slower\">5.00 (0.83×)"), "{html}");
        assert!(html.contains("\"num slower\">2.00 (0.33×)"), "{html}");
        assert!(
            html.contains("<td>n/a</td>"),
            "obvhs traced no primary rays: {html}"
        );
        let two = vec![
            throughput("raypack", "single", "ao", 6.0),
            throughput("embree(avx2)", "single", "ao", 4.0),
        ];
        assert!(every_engine_table(&[input("traversal x", two)]).is_none());
    }
}
