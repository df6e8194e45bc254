//! Line plots as SVG, written atomically beside the CSV they draw (probe time series,
//! spectra). One panel per call, several named series, automatic ranges.

use crate::output::{write_atomic, OutputError};
use plotters::prelude::*;
use std::path::Path;

/// One named curve.
pub struct Series<'a> {
    /// Legend label.
    pub label: &'a str,
    /// (x, y) points.
    pub points: &'a [(f64, f64)],
}

/// A vertical line at `x` with a label (a natural frequency on a spectrum).
pub struct Mark<'a> {
    /// Where (x-axis units).
    pub x: f64,
    /// What it is, written beside the line.
    pub label: &'a str,
    /// A reference given by hand (a paper's peak), drawn in red; else a computed mode, grey.
    pub reference: bool,
}

/// Axis titles and the plot title.
pub struct Labels<'a> {
    /// Title above the panel.
    pub title: &'a str,
    /// x-axis title.
    pub x: &'a str,
    /// y-axis title.
    pub y: &'a str,
}

const COLOURS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];

/// Most points drawn per curve: longer series are thinned by a stride (the CSV keeps all).
const MAX_POINTS: usize = 4000;

/// Range of the finite values, widened when empty or flat.
fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if lo > hi {
        return (0.0, 1.0);
    }
    let pad = if hi > lo {
        0.05 * (hi - lo)
    } else {
        lo.abs().max(1e-30)
    };
    (lo - pad, hi + pad)
}

/// Tick label: plain for magnitudes between 10⁻² and 10⁵, scientific otherwise.
fn tick(v: &f64) -> String {
    let a = v.abs();
    if a == 0.0 || (1e-2..1e5).contains(&a) {
        format!("{v:.3}")
            .trim_end_matches('0')
            .trim_end_matches('.')
            .to_string()
    } else {
        format!("{v:.2e}")
    }
}

/// Draws `series` into an SVG file at `path` (written atomically).
pub fn line_plot_svg(
    path: &Path,
    labels: &Labels<'_>,
    series: &[Series<'_>],
) -> Result<(), OutputError> {
    marked_plot_svg(path, labels, series, &[])
}

/// [`line_plot_svg`] with `marks` drawn as dashed vertical lines over the curves, each
/// labelled at the top of the panel (those outside the curves' x range are left out).
pub fn marked_plot_svg(
    path: &Path,
    labels: &Labels<'_>,
    series: &[Series<'_>],
    marks: &[Mark<'_>],
) -> Result<(), OutputError> {
    let (x0, x1) = range(series.iter().flat_map(|s| s.points.iter().map(|p| p.0)));
    let (y0, y1) = range(series.iter().flat_map(|s| s.points.iter().map(|p| p.1)));
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 500)).into_drawing_area();
        let draw = || -> Result<(), Box<dyn std::error::Error + '_>> {
            root.fill(&WHITE)?;
            let mut chart = ChartBuilder::on(&root)
                .caption(labels.title, ("sans-serif", 20))
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(80)
                .build_cartesian_2d(x0..x1, y0..y1)?;
            chart
                .configure_mesh()
                .x_desc(labels.x)
                .y_desc(labels.y)
                .y_label_formatter(&tick)
                .draw()?;
            for (i, s) in series.iter().enumerate() {
                let colour = COLOURS[i % COLOURS.len()];
                let stride = s.points.len().div_ceil(MAX_POINTS).max(1);
                let points = s.points.iter().step_by(stride).copied();
                chart
                    .draw_series(LineSeries::new(points, colour.stroke_width(1)))?
                    .label(s.label)
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
            }
            for (i, mark) in marks
                .iter()
                .filter(|m| (x0..=x1).contains(&m.x))
                .enumerate()
            {
                let colour = if mark.reference {
                    RGBColor(190, 30, 30)
                } else {
                    RGBColor(110, 110, 110)
                };
                chart.draw_series(DashedLineSeries::new(
                    [(mark.x, y0), (mark.x, y1)],
                    4,
                    3,
                    colour.stroke_width(1),
                ))?;
                // Labels step down the panel so that neighbouring marks stay readable;
                // references from the bottom, modes from the top.
                let step = (y1 - y0) * (0.03 + 0.05 * (i % 6) as f64);
                let at = if mark.reference {
                    y0 + step + (y1 - y0) * 0.03
                } else {
                    y1 - step
                };
                chart.draw_series(std::iter::once(Text::new(
                    mark.label.to_string(),
                    (mark.x, at),
                    ("sans-serif", 11).into_font().color(&colour),
                )))?;
            }
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .draw()?;
            root.present()?;
            Ok(())
        };
        draw().map_err(|e| OutputError::Plot {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
    }
    write_atomic(path, |w| w.write_all(svg.as_bytes()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn marks_inside_the_range_are_drawn_with_their_labels() {
        let dir = std::env::temp_dir().join(format!("qdem-plot-marks-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("marked.svg");
        let points: Vec<(f64, f64)> = (0..100).map(|i| (i as f64, (i as f64).sin())).collect();
        let labels = Labels {
            title: "t",
            x: "f",
            y: "a",
        };
        let series = [Series {
            label: "curve",
            points: &points,
        }];
        let marks = [
            Mark {
                x: 42.6,
                label: "mode 44",
                reference: false,
            },
            Mark {
                x: 60.0,
                label: "paper 60 Hz",
                reference: true,
            },
            Mark {
                x: 500.0,
                label: "beyond",
                reference: false,
            },
        ];
        marked_plot_svg(&path, &labels, &series, &marks).unwrap();
        let svg = std::fs::read_to_string(&path).unwrap();
        assert!(svg.contains("mode 44"));
        assert!(svg.contains("paper 60 Hz"));
        assert!(
            svg.contains("#BE1E1E"),
            "a reference is drawn in red, apart from the modes"
        );
        assert!(
            !svg.contains("beyond"),
            "a mark outside the x range is left out"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn tick_labels_are_plain_for_moderate_values_and_scientific_otherwise() {
        assert_eq!(tick(&60.0), "60");
        assert_eq!(tick(&100.0), "100");
        assert_eq!(tick(&0.125), "0.125");
        assert_eq!(tick(&0.0), "0");
        assert_eq!(tick(&-6.4e-5), "-6.40e-5");
        assert_eq!(tick(&2.5e7), "2.50e7");
    }
}
