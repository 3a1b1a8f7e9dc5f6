//! The JSON result of `raypack robustness --json`: the command and the
//! environment it ran on (as a bench result carries them), the oracle's rows
//! and their totals, and the queries' rows; what `raypack report` reads back
//! beside bench results.

use serde::{Deserialize, Serialize};

use crate::compare::robustness::{QueryRow, Row, totals};
use crate::environment::Environment;
use crate::geometry::triangle::TriangleTest;
use crate::scene::generate::closed_mesh::ClosedShape;

/// The `command` of every robustness result.
pub const COMMAND: &str = "raypack robustness";

/// A run of the robustness oracle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RobustnessResult {
    /// [`COMMAND`]: what tells this result from a bench result.
    pub command: String,
    /// raypack's arguments as given, for a reader to run it again.
    #[serde(default)]
    pub arguments: Vec<String>,
    /// The machine and build it ran on.
    pub environment: Environment,
    /// The triangle test raypack uses unless told otherwise.
    pub default_triangle_test: TriangleTest,
    /// The meshes aimed at.
    pub shapes: Vec<ClosedShape>,
    /// The rows summed per category and engine.
    pub totals: Vec<Row>,
    /// One row per category, mesh, placement and engine.
    pub rows: Vec<Row>,
    /// The all-hits and inside/outside queries per mesh and triangle test.
    pub queries: Vec<QueryRow>,
}

impl RobustnessResult {
    /// The result of a run on `shapes` that gave `rows` and `queries`.
    pub fn new(
        arguments: Vec<String>,
        environment: Environment,
        shapes: Vec<ClosedShape>,
        rows: Vec<Row>,
        queries: Vec<QueryRow>,
    ) -> Self {
        Self {
            command: COMMAND.to_string(),
            arguments,
            environment,
            default_triangle_test: TriangleTest::default(),
            shapes,
            totals: totals(&rows),
            rows,
            queries,
        }
    }

    /// Whether the JSON text `json` says it is a robustness result (an
    /// object whose `command` is [`COMMAND`]), whatever else it holds.
    pub fn claims(json: &str) -> bool {
        #[derive(Deserialize)]
        struct Command {
            command: String,
        }
        serde_json::from_str::<Command>(json).is_ok_and(|c| c.command == COMMAND)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compare::agreement::Quantiles;
    use crate::compare::robustness::Category;

    #[test]
    fn a_result_reads_back_what_it_wrote_and_says_what_it_is() {
        let row = Row {
            category: Category::Grazing,
            shape: ClosedShape::Torus,
            placement: "origin".into(),
            engine: "raypack watertight scalar".into(),
            rays: 10,
            leaks: 1,
            false_hits: 0,
            self_hits: 0,
            t_ulps: Quantiles {
                p50: 0.5,
                p99: 2.0,
                max: f64::NAN,
            },
        };
        let result = RobustnessResult::new(
            vec!["robustness".into()],
            Environment::collect(),
            vec![ClosedShape::Torus],
            vec![row],
            Vec::new(),
        );
        let json = serde_json::to_string(&result).unwrap();
        assert!(RobustnessResult::claims(&json));
        let back: RobustnessResult = serde_json::from_str(&json).unwrap();
        // NaN went out as null and came back as NaN (which equals nothing).
        assert!(back.rows[0].t_ulps.max.is_nan());
        let mut expected = result.clone();
        for row in expected.rows.iter_mut().chain(&mut expected.totals) {
            row.t_ulps.max = 0.0;
        }
        let mut back = back;
        for row in back.rows.iter_mut().chain(&mut back.totals) {
            row.t_ulps.max = 0.0;
        }
        assert_eq!(back, expected);
        assert_eq!(back.totals[0].placement, "all");
        for other in ["{\"command\": \"scene\"}", "[1, 2]", "not json", "{}"] {
            assert!(!RobustnessResult::claims(other), "{other}");
        }
    }
}
