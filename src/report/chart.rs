//! A group of figures as horizontal bars, one per figure: the bar reaches the
//! median, a whisker spans the 95% interval, and a noisy figure's bar is
//! pale and its label marked `*`.

use plotters::prelude::*;

use crate::report::ReportError;
use crate::statistics::Summary;

/// One bar.
#[derive(Debug, Clone)]
pub struct Bar {
    /// Its label on the axis.
    pub label: String,
    /// What the bar shows.
    pub summary: Summary,
    /// Bars with the same colour index share a colour (e.g. one per kernel).
    pub colour: usize,
}

/// Pixels per bar, and around the plot.
const BAR_HEIGHT: u32 = 22;
const WIDTH: u32 = 960;

/// The SVG document of `bars` under `title`, values in `unit`.
pub fn interval_bars(title: &str, unit: &str, bars: &[Bar]) -> Result<String, ReportError> {
    let failed = |e: &dyn std::fmt::Display| ReportError::Chart {
        title: title.to_string(),
        reason: e.to_string(),
    };
    if bars.is_empty() {
        return Err(failed(&"no figures"));
    }
    let n = bars.len();
    let label_chars = bars.iter().map(|b| b.label.chars().count()).max().unwrap_or(0);
    let height = 90 + BAR_HEIGHT * n as u32;
    // Ratios read best from zero too: the eye compares bar lengths.
    let max = bars.iter().map(|b| b.summary.ci_high).fold(0.0, f64::max) * 1.08;
    let max = if max > 0.0 { max } else { 1.0 };
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, height)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| failed(&e))?;
        // Bar 0 at the top: plotters counts segments from the bottom.
        let row = |i: usize| n - 1 - i;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(40 + 7 * label_chars as u32)
            .build_cartesian_2d(0.0..max, (0..n as i32 - 1).into_segmented())
            .map_err(|e| failed(&e))?;
        chart
            .configure_mesh()
            .disable_y_mesh()
            .light_line_style(TRANSPARENT)
            .y_labels(n)
            .y_label_formatter(&|v| match v {
                SegmentValue::CenterOf(i) => bars
                    .get(row(*i as usize))
                    .map_or(String::new(), |b| b.label.clone()),
                _ => String::new(),
            })
            .x_label_formatter(&|v| compact(*v))
            .x_desc(unit)
            .label_style(("sans-serif", 13))
            .draw()
            .map_err(|e| failed(&e))?;
        chart
            .draw_series(bars.iter().enumerate().map(|(i, b)| {
                let colour = Palette99::pick(b.colour);
                let fill = if b.summary.noisy {
                    colour.mix(0.35)
                } else {
                    colour.mix(0.85)
                };
                let y = row(i) as i32;
                let mut bar = Rectangle::new(
                    [
                        (0.0, SegmentValue::Exact(y)),
                        (b.summary.median, SegmentValue::Exact(y + 1)),
                    ],
                    fill.filled(),
                );
                bar.set_margin(3, 3, 0, 0);
                bar
            }))
            .map_err(|e| failed(&e))?;
        chart
            .draw_series(bars.iter().enumerate().map(|(i, b)| {
                let s = &b.summary;
                let y = SegmentValue::CenterOf(row(i) as i32);
                ErrorBar::new_horizontal(y, s.ci_low, s.median, s.ci_high, BLACK.stroke_width(1), 8)
            }))
            .map_err(|e| failed(&e))?;
        root.present().map_err(|e| failed(&e))?;
    }
    Ok(svg)
}

/// An axis value in few characters: `2.5G`, `340M`, `12k`, `0.75`.
pub fn compact(v: f64) -> String {
    let a = v.abs();
    let (scaled, suffix) = if a >= 1e9 {
        (v / 1e9, "G")
    } else if a >= 1e6 {
        (v / 1e6, "M")
    } else if a >= 1e3 {
        (v / 1e3, "k")
    } else {
        (v, "")
    };
    // Up to three significant digits, without trailing zeros.
    let digits = if scaled.abs() >= 100.0 {
        0
    } else if scaled.abs() >= 10.0 {
        1
    } else {
        2
    };
    let text = format!("{scaled:.digits$}");
    let text = if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.')
    } else {
        &text
    };
    format!("{text}{suffix}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn compact_axis_values() {
        let cases = [
            (0.0, "0"),
            (0.75, "0.75"),
            (1.5, "1.5"),
            (12.0, "12"),
            (2500.0, "2.5k"),
            (12_000.0, "12k"),
            (340e6, "340M"),
            (2.5e9, "2.5G"),
        ];
        for (v, text) in cases {
            assert_eq!(compact(v), text, "{v}");
        }
    }

    #[test]
    fn draws_a_bar_and_a_whisker_per_figure() {
        let bars: Vec<Bar> = [(10.0, false), (20.0, true)]
            .iter()
            .enumerate()
            .map(|(i, &(m, noisy))| {
                let mut summary = Summary::of(&[m - 1.0, m, m + 1.0, m, m, m]).unwrap();
                summary.noisy = noisy;
                Bar {
                    label: format!("bar {i}"),
                    summary,
                    colour: i,
                }
            })
            .collect();
        let svg = interval_bars("two bars", "Mrays/s", &bars).unwrap();
        assert!(svg.starts_with("<svg"), "{svg}");
        for text in ["two bars", "Mrays/s", "bar 0", "bar 1"] {
            assert!(svg.contains(text), "{text} missing");
        }
        assert!(interval_bars("none", "x", &[]).is_err());
    }
}
