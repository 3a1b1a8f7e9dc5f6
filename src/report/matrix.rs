//! The report's table of a `raypack bench matrix` result: a row per scene
//! and thread count, a column per ray kind and the build, each cell
//! raypack ÷ Embree (best path against best path; build times) with its 95%
//! interval, the cells that fail the matrix's rule marked; then the headline.

use std::fmt::Write as _;

use crate::bench::figure::Figure;
use crate::bench::matrix::{BUILD_RATIO, Headline, PASS, PASS_WITHIN_INTERVAL, RATIO, figure_passes};
use crate::bench::rays::RayKind;
use crate::report::Input;
use crate::report::html::escape;

/// The `command` of a matrix result.
pub const COMMAND: &str = "matrix";

/// Whether `input` is a matrix result.
pub fn is_matrix(input: &Input) -> bool {
    input.result.command == COMMAND
}

/// The ray kinds of the matrix's cells, in [`RayKind::ALL`]'s order.
fn kinds(figures: &[Figure]) -> Vec<&'static str> {
    RayKind::ALL
        .iter()
        .map(|k| k.name())
        .filter(|k| figures.iter().any(|f| f.name == RATIO && f.label("rays") == *k))
        .collect()
}

/// The (scene, primitives, threads) rows of the matrix, in order of appearance.
fn rows(figures: &[Figure]) -> Vec<(&str, &str, &str)> {
    let mut rows: Vec<(&str, &str, &str)> = Vec::new();
    for f in figures
        .iter()
        .filter(|f| f.name == RATIO || f.name == BUILD_RATIO)
    {
        let row = (f.label("scene"), f.label("primitives"), f.label("threads"));
        if !rows.contains(&row) {
            rows.push(row);
        }
    }
    rows
}

/// One cell: the figure's median and interval, marked where it fails.
fn cell(out: &mut String, figure: Option<&Figure>) {
    let Some(f) = figure else {
        out.push_str("<td></td>");
        return;
    };
    let s = &f.summary;
    let passes = figure_passes(f);
    // Writing to a String cannot fail.
    let _ = write!(
        out,
        "<td class=\"num{}\">{:.2}× [{:.2}, {:.2}]{}</td>",
        if passes { "" } else { " wrong" },
        s.median,
        s.ci_low,
        s.ci_high,
        if passes { "" } else { " ✗" }
    );
}

/// The matrix of `input` as an HTML table with its headline.
pub fn table(input: &Input) -> String {
    let figures = &input.result.figures;
    let kinds = kinds(figures);
    let env = &input.result.environment;
    let mut out = String::new();
    let _ = write!(
        out,
        "<p>raypack ÷ Embree on {} (kernels {}): per scene and thread count, each ray kind's \
         fastest raypack path (single rays, 8- or 16-ray packets) over Embree's fastest path and \
         setting, in Mrays/s of the same rays, round by round: median [95% interval]; build: \
         raypack's build time over Embree's faster setting's. Marked ✗: a cell below \
         {PASS:.2}× whose interval does not reach {PASS_WITHIN_INTERVAL:.2}×, a build above 1.00×.</p>\n\
         <table class=\"matrix\"><thead><tr><th>scene</th><th>primitives</th><th>threads</th>",
        escape(&env.cpu_model),
        escape(env.isa_label())
    );
    for kind in &kinds {
        let _ = write!(out, "<th>{kind}</th>");
    }
    out.push_str("<th>build</th></tr></thead><tbody>\n");
    for (scene, primitives, threads) in rows(figures) {
        let here = |f: &&Figure| {
            f.label("scene") == scene && f.label("primitives") == primitives && f.label("threads") == threads
        };
        let _ = write!(
            out,
            "<tr><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td>",
            escape(scene),
            escape(primitives),
            escape(threads)
        );
        for kind in &kinds {
            cell(
                &mut out,
                figures
                    .iter()
                    .filter(here)
                    .find(|f| f.name == RATIO && f.label("rays") == *kind),
            );
        }
        cell(
            &mut out,
            figures.iter().filter(here).find(|f| f.name == BUILD_RATIO),
        );
        out.push_str("</tr>\n");
    }
    let _ = writeln!(
        out,
        "</tbody></table>\n<p class=\"headline\">{}</p>",
        escape(&Headline::of(figures).words())
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::figure::Better;
    use crate::statistics::Summary;

    fn figure(name: &str, scene: &str, threads: &str, rays: &str, samples: &[f64]) -> Figure {
        let mut labels = vec![
            ("scene", scene.to_string()),
            ("primitives", "4096".to_string()),
            ("threads", threads.to_string()),
        ];
        if !rays.is_empty() {
            labels.push(("rays", rays.to_string()));
        }
        Figure::new(name, "x", Better::Higher, &labels, Summary::of(samples).unwrap())
    }

    #[test]
    fn a_row_per_scene_and_thread_count_with_failing_cells_marked() {
        let figures = vec![
            figure(RATIO, "gen:tetra", "1", "ao", &[0.9, 0.95, 1.0]),
            figure(RATIO, "gen:tetra", "1", "primary", &[1.4, 1.5, 1.6]),
            figure(BUILD_RATIO, "gen:tetra", "1", "", &[1.2, 1.3, 1.4]),
            figure(RATIO, "gen:tetra", "2", "primary", &[0.9, 1.0, 1.1]),
            figure(RATIO, "gen:tetra", "2", "ao", &[0.8, 0.9, 1.06]),
            figure(BUILD_RATIO, "gen:tetra", "2", "", &[0.5, 0.6, 0.7]),
        ];
        let html = table(&Input::of_figures("matrix.json", COMMAND, figures));
        // Kinds in the bench's order, whatever the figures' order.
        assert!(
            html.contains("<th>primary</th><th>ao</th><th>build</th>"),
            "{html}"
        );
        assert_eq!(html.matches("<tr><td>gen:tetra</td>").count(), 2, "{html}");
        assert!(
            html.contains("<td class=\"num\">1.50× [1.40, 1.60]</td>"),
            "{html}"
        );
        assert!(
            html.contains("<td class=\"num wrong\">0.95× [0.90, 1.00] ✗</td>"),
            "{html}"
        );
        assert!(
            html.contains("<td class=\"num wrong\">1.30× [1.20, 1.40] ✗</td>"),
            "{html}"
        );
        // Below 1 but its interval reaches 1.05: passes.
        assert!(
            html.contains("<td class=\"num\">0.90× [0.80, 1.06]</td>"),
            "{html}"
        );
        assert!(
            html.contains("<td class=\"num\">0.60× [0.50, 0.70]</td>"),
            "{html}"
        );
        assert!(html.contains("1 of 4 ray-kind cells fail"), "{html}");
    }
}
