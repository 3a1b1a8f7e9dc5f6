//! The report's section of a robustness result (`raypack robustness
//! --json`, [`crate::compare::robustness`]): the command and its environment,
//! a table per category of the oracle (each engine's totals, and below them,
//! folded, each mesh and placement), and the queries' table. Every count of
//! wrong answers (leaks, false hits, self-hits, wrong queries) is marked where
//! it is not zero.

use std::fmt::Write as _;

use crate::compare::robustness::{Category, Row};
use crate::report::RobustnessInput;
use crate::report::html::{escape, pairs_table};

/// The class of a count of wrong answers that is not zero (the page's style draws it red).
const WRONG: &str = "wrong";

/// The columns of a category's tables.
const COLUMNS: [&str; 10] = [
    "engine",
    "mesh",
    "placement",
    "rays",
    "leaks",
    "false hits",
    "self-hits",
    "t error p50 (ulps)",
    "p99",
    "max",
];

/// The section of `input`.
pub fn section(out: &mut String, input: &RobustnessInput) {
    let r = &input.result;
    let command = if r.arguments.is_empty() {
        "robustness".to_string()
    } else {
        r.arguments.join(" ")
    };
    // Writing to a String cannot fail.
    let _ = writeln!(
        out,
        "<section><h2>Robustness oracle: {}</h2>\n<p><code>raypack {}</code> on {}; raypack's \
         default triangle test: {}. A leak is a ray that crossed a closed surface without a hit \
         there; a false hit, a hit where the f64 reference clearly misses; a self-hit, a \
         secondary ray hitting the surface it leaves. t error in f32 ulps against the f64 \
         reference.</p>",
        escape(&input.name),
        escape(&command),
        escape(&r.shapes.iter().map(|s| s.name()).collect::<Vec<_>>().join(", ")),
        r.default_triangle_test.name()
    );
    out.push_str(&pairs_table(&r.environment.rows()));
    for category in Category::ALL {
        let of =
            |rows: &[Row]| -> Vec<Row> { rows.iter().filter(|x| x.category == category).cloned().collect() };
        let (totals, rows) = (of(&r.totals), of(&r.rows));
        if totals.is_empty() && rows.is_empty() {
            continue;
        }
        let _ = writeln!(out, "<h3>{}</h3>", category.name());
        table(out, &totals);
        let _ = writeln!(
            out,
            "<details><summary>per mesh and placement ({} rows)</summary>",
            rows.len()
        );
        table(out, &rows);
        out.push_str("</details>\n");
    }
    queries(out, input);
    out.push_str("</section>\n");
}

/// A category's rows as a table.
fn table(out: &mut String, rows: &[Row]) {
    out.push_str("<table><thead><tr>");
    for c in COLUMNS {
        let _ = write!(out, "<th>{c}</th>");
    }
    out.push_str("</tr></thead><tbody>\n");
    for row in rows {
        // Totals name no mesh: their placement is `all`.
        let shape = if row.placement == "all" {
            "all"
        } else {
            row.shape.name()
        };
        let _ = writeln!(
            out,
            "<tr><td>{}</td><td>{shape}</td><td>{}</td><td class=\"num\">{}</td>{}{}{}\
             <td class=\"num\">{:.1}</td><td class=\"num\">{:.1}</td><td class=\"num\">{:.1}</td></tr>",
            escape(&row.engine),
            escape(&row.placement),
            row.rays,
            count(row.leaks),
            count(row.false_hits),
            count(row.self_hits),
            row.t_ulps.p50,
            row.t_ulps.p99,
            row.t_ulps.max
        );
    }
    out.push_str("</tbody></table>\n");
}

/// The all-hits and inside/outside queries as a table.
fn queries(out: &mut String, input: &RobustnessInput) {
    let queries = &input.result.queries;
    if queries.is_empty() {
        return;
    }
    out.push_str(
        "<h3>queries</h3>\n<p>Points just inside and outside faces, edges and vertices, \
         classified inside or outside, and rays from them and along the edge rays, their \
         crossings counted (all hits).</p>\n<table><thead><tr><th>mesh</th><th>triangle \
         test</th><th>points</th><th>wrong inside</th><th>rays</th><th>wrong crossings</th>\
         </tr></thead><tbody>\n",
    );
    for q in queries {
        let _ = writeln!(
            out,
            "<tr><td>{}</td><td>{}</td><td class=\"num\">{}</td>{}<td class=\"num\">{}</td>{}</tr>",
            q.shape.name(),
            q.test.name(),
            q.points,
            count(q.wrong_inside),
            q.rays,
            count(q.wrong_crossings)
        );
    }
    out.push_str("</tbody></table>\n");
}

/// The cell of a count of wrong answers: marked [`WRONG`] unless zero.
fn count(n: usize) -> String {
    if n == 0 {
        "<td class=\"num\">0</td>".into()
    } else {
        format!("<td class=\"num {WRONG}\">{n}</td>")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compare::agreement::Quantiles;
    use crate::compare::robustness::QueryRow;
    use crate::compare::robustness_result::RobustnessResult;
    use crate::environment::Environment;
    use crate::geometry::triangle::TriangleTest;
    use crate::scene::generate::closed_mesh::ClosedShape;

    fn row(category: Category, placement: &str, engine: &str, leaks: usize) -> Row {
        Row {
            category,
            shape: ClosedShape::Tetrahedron,
            placement: placement.into(),
            engine: engine.into(),
            rays: 32,
            leaks,
            false_hits: 0,
            self_hits: 0,
            t_ulps: Quantiles {
                p50: 0.5,
                p99: 1.5,
                max: 2.0,
            },
        }
    }

    #[test]
    fn a_table_per_category_with_wrong_counts_marked() {
        let rows = vec![
            row(Category::EdgesVertices, "origin", "raypack <w>", 0),
            row(Category::EdgesVertices, "origin", "leaky", 3),
            row(Category::FarSmall, "1e7", "leaky", 5),
        ];
        let queries = vec![QueryRow {
            shape: ClosedShape::Tetrahedron,
            test: TriangleTest::Barycentric,
            points: 100,
            wrong_inside: 0,
            rays: 132,
            wrong_crossings: 7,
        }];
        let result = RobustnessResult::new(
            Vec::new(),
            Environment::collect(),
            vec![ClosedShape::Tetrahedron],
            rows,
            queries,
        );
        let mut html = String::new();
        section(
            &mut html,
            &RobustnessInput {
                name: "r.json".into(),
                result,
            },
        );
        assert!(html.contains("<h2>Robustness oracle: r.json</h2>"));
        // Two categories of the five, each with its totals and its rows folded.
        assert_eq!(html.matches("<h3>").count(), 3, "{html}");
        assert!(html.contains("<h3>edges-vertices</h3>") && html.contains("<h3>far-small</h3>"));
        assert!(!html.contains("<h3>grazing</h3>"));
        assert_eq!(html.matches("<details>").count(), 2);
        // The totals, then the row of the mesh.
        let total = "<tr><td>leaky</td><td>all</td><td>all</td><td class=\"num\">32</td>\
                     <td class=\"num wrong\">3</td><td class=\"num\">0</td><td class=\"num\">0</td>\
                     <td class=\"num\">0.5</td><td class=\"num\">1.5</td><td class=\"num\">2.0</td></tr>";
        assert!(html.contains(total), "{html}");
        assert!(html.contains("<tr><td>leaky</td><td>tetrahedron</td><td>1e7</td>"));
        assert!(html.contains("<tr><td>raypack &lt;w&gt;</td>"), "escaped");
        // Marked: the two leaking rows of edges (row, total), the two of far-small, one query.
        assert_eq!(html.matches("class=\"num wrong\"").count(), 5, "{html}");
        assert!(html.contains("<td>barycentric</td><td class=\"num\">100</td><td class=\"num\">0</td>"));
        assert!(html.contains("<td class=\"num wrong\">7</td></tr>"));
    }
}
