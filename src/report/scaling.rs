//! Throughput over thread counts: one line per variant through its medians,
//! a whisker at each point for the 95% interval.

use plotters::prelude::*;

use crate::report::ReportError;
use crate::report::chart::compact;
use crate::statistics::Summary;

/// One variant's figures over thread counts.
#[derive(Debug, Clone)]
pub struct Line {
    /// The variant, in the legend.
    pub label: String,
    /// `(threads, figure)`, by increasing threads.
    pub points: Vec<(f64, Summary)>,
}

/// The SVG document of `lines` under `title`, values in `unit`.
pub fn thread_scaling(title: &str, unit: &str, lines: &[Line]) -> Result<String, ReportError> {
    let failed = |e: &dyn std::fmt::Display| ReportError::Chart {
        title: title.to_string(),
        reason: e.to_string(),
    };
    let points = || lines.iter().flat_map(|l| &l.points);
    let top = points().map(|(_, s)| s.ci_high).fold(0.0, f64::max) * 1.1;
    let most = points().map(|(t, _)| *t).fold(1.0, f64::max);
    if lines.is_empty() || !(top > 0.0) {
        return Err(failed(&"no figures"));
    }
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (960, 420)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| failed(&e))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(0.5..most + 0.5, 0.0..top)
            .map_err(|e| failed(&e))?;
        chart
            .configure_mesh()
            .x_labels(most as usize + 1)
            .x_label_formatter(&|t| {
                // Only whole thread counts get a label.
                if t.fract() == 0.0 {
                    format!("{t}")
                } else {
                    String::new()
                }
            })
            .light_line_style(TRANSPARENT)
            .x_desc("threads")
            .y_label_formatter(&|v| compact(*v))
            .y_desc(unit)
            .label_style(("sans-serif", 13))
            .draw()
            .map_err(|e| failed(&e))?;
        for (k, line) in lines.iter().enumerate() {
            let colour = Palette99::pick(k).to_rgba();
            chart
                .draw_series(LineSeries::new(
                    line.points.iter().map(|(t, s)| (*t, s.median)),
                    colour.stroke_width(2),
                ))
                .map_err(|e| failed(&e))?
                .label(line.label.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2)));
            chart
                .draw_series(line.points.iter().map(|(t, s)| {
                    ErrorBar::new_vertical(*t, s.ci_low, s.median, s.ci_high, colour.stroke_width(1), 8)
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
    fn draws_a_line_per_variant() {
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
        let svg = thread_scaling("scaling", "Mrays/s", &lines).unwrap();
        for text in ["scaling", "threads", "packet8", "scalar", "<polyline"] {
            assert!(svg.contains(text), "{text} missing");
        }
        assert!(thread_scaling("none", "x", &[]).is_err());
    }
}
