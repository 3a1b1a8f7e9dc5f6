//! The triangle-scene matrix: per scene, thread count and ray kind, raypack's
//! fastest path against Embree's fastest path and setting on the same rays
//! ([`BestVsEmbree`]), and raypack's build time against Embree's; the rule a
//! cell passes by and the headline figure, the geometric mean of the
//! incoherent cells. `raypack bench matrix` measures it, `raypack report`
//! draws it from the figures alone ([`RATIO`], [`BUILD_RATIO`]).

use serde::Serialize;

use crate::bench::figure::{Better, Figure};
use crate::bench::rays::RayKind;
use crate::bench::traversal::{BestVsEmbree, TraversalRow};
use crate::statistics::Summary;

/// The figure of a ray-kind cell: raypack's Mrays/s over Embree's, best
/// path against best path, round by round.
pub const RATIO: &str = "raypack/embree best path";

/// The figure of a build cell: raypack's build time over Embree's faster
/// setting's, round by round.
pub const BUILD_RATIO: &str = "raypack/embree build time";

/// A ray-kind cell passes when its median reaches this ratio…
pub const PASS: f64 = 1.0;

/// …or, below it, when its 95% interval reaches this one.
pub const PASS_WITHIN_INTERVAL: f64 = 1.05;

/// The headline's target: the geometric mean of the incoherent cells.
pub const TARGET_GEOMETRIC_MEAN: f64 = 1.15;

/// The incoherent kinds, whose cells make the headline.
pub const INCOHERENT: [RayKind; 4] = [RayKind::Shadow, RayKind::Ao, RayKind::Diffuse, RayKind::Random];

/// Whether a ray-kind cell of `ratio` passes: median at least [`PASS`], or
/// an interval reaching [`PASS_WITHIN_INTERVAL`].
pub fn cell_passes(ratio: &Summary) -> bool {
    ratio.median >= PASS || ratio.ci_high >= PASS_WITHIN_INTERVAL
}

/// Whether a build cell of `ratio` passes: raypack's median build time no
/// longer than Embree's.
pub fn build_passes(ratio: &Summary) -> bool {
    ratio.median <= 1.0
}

/// Whether a figure of the matrix ([`RATIO`] or [`BUILD_RATIO`]) passes.
pub fn figure_passes(figure: &Figure) -> bool {
    if figure.name == BUILD_RATIO {
        build_passes(&figure.summary)
    } else {
        cell_passes(&figure.summary)
    }
}

/// One row of the matrix: a scene at a thread count.
#[derive(Clone, Debug, Serialize)]
pub struct MatrixRow {
    /// The scene as `--scenes` named it.
    pub scene: String,
    /// Primitives in the scene.
    pub primitives: usize,
    /// Threads of the rayon pool (and of both builds).
    pub threads: usize,
    /// One cell per ray kind measured, in the order measured.
    pub cells: Vec<MatrixCell>,
    /// The build times.
    pub build: BuildCell,
}

/// A ray-kind cell: raypack's fastest path against Embree's.
#[derive(Clone, Debug, Serialize)]
pub struct MatrixCell {
    /// The ray kind.
    pub kind: RayKind,
    /// Which paths were fastest, and the ratio with its interval.
    #[serde(flatten)]
    pub best: BestVsEmbree,
    /// Whether the cell passes ([`cell_passes`]).
    pub passes: bool,
    /// raypack's fastest path, median Mrays/s.
    pub raypack_mrays: f64,
    /// Embree's fastest path and setting, median Mrays/s.
    pub embree_mrays: f64,
}

/// A build cell: raypack's build time against Embree's faster setting's.
#[derive(Clone, Debug, Serialize)]
pub struct BuildCell {
    /// raypack's time over Embree's, round by round.
    pub ratio: Summary,
    /// Whether the cell passes ([`build_passes`]).
    pub passes: bool,
    /// raypack's median build time, ms.
    pub raypack_ms: f64,
    /// The median build time of Embree's faster setting, ms.
    pub embree_ms: f64,
}

impl MatrixRow {
    /// The row of raypack's traversal row `ours` on `scene`, against the
    /// rows `embree` of Embree's settings on the same rays and thread count;
    /// None where Embree was not measured alongside.
    pub fn of(scene: &str, ours: &TraversalRow, embree: &[&TraversalRow]) -> Option<Self> {
        let cells = ours
            .kinds
            .iter()
            .map(|k| {
                let best = k.best_vs_embree.clone()?;
                let embree_mrays = embree
                    .iter()
                    .filter_map(|r| r.kinds.iter().find(|e| e.kind == k.kind))
                    .map(|e| e.best().0)
                    .reduce(f64::max)?;
                Some(MatrixCell {
                    kind: k.kind,
                    passes: cell_passes(&best.ratio),
                    best,
                    raypack_mrays: k.best().0,
                    embree_mrays,
                })
            })
            .collect::<Option<Vec<_>>>()?;
        let ratio = ours.build_vs_embree?;
        Some(Self {
            scene: scene.to_string(),
            primitives: ours.primitives,
            threads: ours.threads,
            cells,
            build: BuildCell {
                ratio,
                passes: build_passes(&ratio),
                raypack_ms: ours.build_ms.median,
                embree_ms: embree.iter().map(|r| r.build_ms.median).reduce(f64::min)?,
            },
        })
    }

    /// The row's figures: a [`RATIO`] per ray kind, then the [`BUILD_RATIO`].
    pub fn figures(&self) -> Vec<Figure> {
        let labels = |kind: Option<RayKind>| {
            let mut l = vec![
                ("scene", self.scene.clone()),
                ("primitives", self.primitives.to_string()),
                ("threads", self.threads.to_string()),
            ];
            l.extend(kind.map(|k| ("rays", k.name().to_string())));
            l
        };
        self.cells
            .iter()
            .map(|c| Figure::new(RATIO, "x", Better::Higher, &labels(Some(c.kind)), c.best.ratio))
            .chain([Figure::new(
                BUILD_RATIO,
                "x",
                Better::Lower,
                &labels(None),
                self.build.ratio,
            )])
            .collect()
    }
}

/// What the matrix comes to: the geometric mean of its incoherent cells'
/// medians, and how many cells of each sort fail.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Headline {
    /// The geometric mean of the incoherent cells' medians (None without any).
    pub incoherent_mean: Option<f64>,
    /// Incoherent cells.
    pub incoherent: usize,
    /// Ray-kind cells.
    pub cells: usize,
    /// Ray-kind cells that fail ([`cell_passes`]).
    pub failing: usize,
    /// Build cells.
    pub builds: usize,
    /// Build cells that fail ([`build_passes`]).
    pub slower_builds: usize,
}

impl Headline {
    /// The headline of the matrix figures among `figures`.
    pub fn of(figures: &[Figure]) -> Self {
        let cells: Vec<&Figure> = figures.iter().filter(|f| f.name == RATIO).collect();
        let builds: Vec<&Figure> = figures.iter().filter(|f| f.name == BUILD_RATIO).collect();
        let incoherent: Vec<f64> = cells
            .iter()
            .filter(|f| INCOHERENT.iter().any(|k| k.name() == f.label("rays")))
            .map(|f| f.summary.median)
            .collect();
        let failing = |of: &[&Figure]| of.iter().filter(|f| !figure_passes(f)).count();
        Self {
            incoherent_mean: geometric_mean(&incoherent),
            incoherent: incoherent.len(),
            cells: cells.len(),
            failing: failing(&cells),
            builds: builds.len(),
            slower_builds: failing(&builds),
        }
    }

    /// The headline in words, for the table's reader.
    pub fn words(&self) -> String {
        let kinds: Vec<&str> = INCOHERENT.iter().map(|k| k.name()).collect();
        let mean = match self.incoherent_mean {
            Some(m) => format!(
                "geometric mean of the {} incoherent cells ({}): {m:.2}x (target {TARGET_GEOMETRIC_MEAN:.2}x: {})",
                self.incoherent,
                kinds.join(", "),
                if m >= TARGET_GEOMETRIC_MEAN {
                    "met"
                } else {
                    "not met"
                }
            ),
            None => format!("no incoherent cells ({})", kinds.join(", ")),
        };
        format!(
            "{mean}; {} of {} ray-kind cells fail; {} of {} builds slower than Embree's",
            self.failing, self.cells, self.slower_builds, self.builds
        )
    }
}

/// The geometric mean of positive `values` (None for none).
fn geometric_mean(values: &[f64]) -> Option<f64> {
    (!values.is_empty()).then(|| (values.iter().map(|v| v.ln()).sum::<f64>() / values.len() as f64).exp())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A summary of median `median` whose interval reaches `high`.
    fn ratio(median: f64, high: f64) -> Summary {
        Summary::of(&[median * 0.9, median, median, median, median, high, high]).unwrap()
    }

    fn figure(name: &str, rays: &str, s: Summary) -> Figure {
        let mut labels = vec![("scene", "gen:tetra".to_string()), ("threads", "1".to_string())];
        if !rays.is_empty() {
            labels.push(("rays", rays.to_string()));
        }
        Figure::new(name, "x", Better::Higher, &labels, s)
    }

    #[test]
    fn a_cell_below_one_passes_only_where_its_interval_reaches_1_05() {
        assert!(cell_passes(&ratio(1.0, 1.01)));
        assert!(cell_passes(&ratio(0.97, 1.06)));
        assert!(!cell_passes(&ratio(0.97, 1.04)));
        let s = ratio(0.97, 1.06);
        assert!(s.ci_high >= PASS_WITHIN_INTERVAL, "{s:?}");
        assert!(build_passes(&ratio(0.9, 1.2)) && !build_passes(&ratio(1.1, 1.2)));
    }

    #[test]
    fn the_headline_is_the_geometric_mean_of_the_incoherent_cells() {
        let figures = [
            figure(RATIO, "primary", ratio(3.0, 3.0)),
            figure(RATIO, "shadow", ratio(2.0, 2.0)),
            figure(RATIO, "random", ratio(0.5, 0.5)),
            figure(BUILD_RATIO, "", ratio(1.2, 1.3)),
        ];
        let h = Headline::of(&figures);
        assert!((h.incoherent_mean.unwrap() - 1.0).abs() < 1e-12, "{h:?}");
        assert_eq!((h.incoherent, h.cells, h.failing), (2, 3, 1));
        assert_eq!((h.builds, h.slower_builds), (1, 1));
        let words = h.words();
        assert!(words.contains("1.00x (target 1.15x: not met)"), "{words}");
        assert!(words.contains("1 of 3 ray-kind cells fail"), "{words}");
        assert_eq!(Headline::of(&[]).incoherent_mean, None);
    }
}
