//! Figures over a numeric label (throughput over thread counts, over scene
//! sizes): one line per variant through its medians, a whisker at each point
//! for the 95% interval.

use plotters::prelude::*;

use crate::report::ReportError;
use crate::report::chart::compact;
use crate::statistics::Summary;

/// One variant's figures over the x values.
#[derive(Debug, Clone)]
pub struct Line {
    /// The variant, in the legend.
    pub label: String,
    /// `(x, figure)`, by increasing x.
    pub points: Vec<(f64, Summary)>,
}

/// The x axis: what it is, and whether its values span decades.
#[derive(Debug, Clone, Copy)]
pub struct XAxis<'a> {
    /// Its description (`threads`, `primitives`).
    pub name: &'a str,
    /// Drawn as the logarithm of the values (scene sizes from 10³ to 10⁶).
    pub log: bool,
}

/// The SVG document of `lines` over `x` under `title`, values in `unit`.
pub fn over(title: &str, x: XAxis<'_>, unit: &str, lines: &[Line]) -> Result<String, ReportError> {
    let failed = |e: &dyn std::fmt::Display| ReportError::Chart {
        title: title.to_string(),
        reason: e.to_string(),
    };
    // A logarithmic axis is drawn linear in log10 of the values, labelled with the values.
    let to_x = |v: f64| if x.log { v.log10() } else { v };
    let points = || lines.iter().flat_map(|l| &l.points);
    let top = points().map(|(_, s)| s.ci_high).fold(0.0, f64::max) * 1.1;
    let (lo, hi) = points().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), (v, _)| {
        (lo.min(to_x(*v)), hi.max(to_x(*v)))
    });
    if lines.is_empty() || !(top > 0.0) || !(lo <= hi) {
        return Err(failed(&"no figures"));
    }
    // Room at either end; half a unit when every point has one x.
    let pad = if hi > lo { 0.08 * (hi - lo) } else { 0.5 };
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (960, 420)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| failed(&e))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(lo - pad..hi + pad, 0.0..top)
            .map_err(|e| failed(&e))?;
        chart
            .configure_mesh()
            .x_labels(((hi - lo).round() as usize + 2).clamp(3, 12))
            .x_label_formatter(&|t| {
                // Only whole counts (whole decades on a log axis) get a label.
                if t.fract() != 0.0 {
                    String::new()
                } else if x.log {
                    compact(10f64.powf(*t))
                } else {
                    compact(*t)
                }
            })
            .light_line_style(TRANSPARENT)
            .x_desc(x.name)
            .y_label_formatter(&|v| compact(*v))
            .y_desc(unit)
            .label_style(("sans-serif", 13))
            .draw()
            .map_err(|e| failed(&e))?;
        for (k, line) in lines.iter().enumerate() {
            let colour = Palette99::pick(k).to_rgba();
            chart
                .draw_series(LineSeries::new(
                    line.points.iter().map(|(v, s)| (to_x(*v), s.median)),
                    colour.stroke_width(2),
                ))
                .map_err(|e| failed(&e))?
                .label(line.label.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2)));
            chart
                .draw_series(line.points.iter().map(|(t, s)| {
                    ErrorBar::new_vertical(to_x(*t), s.ci_low, s.median, s.ci_high, colour.stroke_width(1), 8)
                }))
                .map_err(|e| failed(&e))?;
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 13))
            .draw()
            .map_err(|e| failed(&e))?;
        root.present().map_err(|e| failed(&e))?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_a_line_per_variant_on_linear_and_log_axes() {
        let s = |m: f64| Summary::of(&[m * 0.9, m, m * 1.1, m, m, m]).unwrap();
        let lines = [
            Line {
                label: "packet8".into(),
                points: vec![(1.0, s(10.0)), (2.0, s(19.0))],
            },
            Line {
                label: "scalar".into(),
                points: vec![(1.0, s(4.0)), (2.0, s(7.5))],
            },
        ];
        let threads = XAxis {
            name: "threads",
            log: false,
        };
        let svg = over("scaling", threads, "Mrays/s", &lines).unwrap();
        for text in ["scaling", "threads", "packet8", "scalar", "<polyline"] {
            assert!(svg.contains(text), "{text} missing");
        }
        assert!(over("none", threads, "x", &[]).is_err());
        // Decades: 1k, 10k, 100k label the log axis.
        let sizes = [Line {
            label: "single".into(),
            points: vec![(1e3, s(5.0)), (1e4, s(4.0)), (1e5, s(3.0))],
        }];
        let log = XAxis {
            name: "primitives",
            log: true,
        };
        let svg = over("growth", log, "Mrays/s", &sizes).unwrap();
        for text in ["\n1k\n", "\n10k\n", "\n100k\n", "primitives"] {
            assert!(svg.contains(text), "{text} missing: {svg}");
        }
    }
}
