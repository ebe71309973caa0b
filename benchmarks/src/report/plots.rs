//! Robustness plots (SVG, `plotters`): each metric against each swept axis
//! with at least two values, one line per method label with the 95%
//! bootstrap band of its mean. A point pools every row with that axis value
//! (all datasets, views, seeds and values of the other axes), so every
//! method's point stands on the same inputs. Numeric axes are plotted to
//! scale, text axes (a light rig, `on`/`off`) as categories.

use super::axes;
use super::methods::MethodInfo;
use super::stats::{AxisPoints, Metric, Statistics};
use crate::row::AxisValue;
use plotters::prelude::*;
use serde::Serialize;
use sfp_core::{Error, Result, io};
use std::path::Path;

/// Line colours (Tableau 10), one per method label in report order.
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// Size of a plot, pixels.
pub const SIZE: (u32, u32) = (720, 420);

/// Width of the legend column right of the chart, pixels.
const LEGEND_WIDTH: u32 = 150;

/// One written plot.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Plot {
    /// Path relative to the report folder (`plots/…svg`).
    pub file: String,
    pub axis: String,
    pub metric: Metric,
    pub title: String,
}

/// One line: `(x, mean, lo, hi)` per axis value the method has figures at.
type Line = Vec<(f64, f64, f64, f64)>;

fn plot_error(e: impl std::fmt::Display) -> Error {
    Error::invalid(format!("plot: {e}"))
}

/// Writes `dir/plots/<metric>-vs-<axis>.svg` for every swept axis and metric.
pub fn write(dir: &Path, stats: &Statistics, methods: &[MethodInfo]) -> Result<Vec<Plot>> {
    let mut plots = Vec::new();
    for AxisPoints {
        axis,
        values,
        figures,
    } in &stats.axes
    {
        let numeric = values.iter().all(|v| matches!(v, AxisValue::Number(_)));
        let x_of = |i: usize| match (&values[i], numeric) {
            (AxisValue::Number(x), true) => *x,
            _ => i as f64,
        };
        for metric in Metric::ALL {
            let mut lines: Vec<(String, Line)> = Vec::new();
            for (m, per_value) in methods.iter().zip(figures) {
                let line: Line = per_value
                    .iter()
                    .enumerate()
                    .filter_map(|(i, f)| f.get(metric).map(|s| (x_of(i), s.mean, s.lo, s.hi)))
                    .collect();
                if !line.is_empty() {
                    lines.push((m.display(), line));
                }
            }
            if lines.is_empty() {
                continue;
            }
            let title = format!("{} vs {}", metric.name(), axes::describe(axis).0);
            let svg = draw(axis, values, numeric, metric, &title, &lines)?;
            let file = format!("plots/{}-vs-{}.svg", metric.key(), axis);
            io::write_atomic(&dir.join(&file), svg.as_bytes())?;
            plots.push(Plot {
                file,
                axis: axis.clone(),
                metric,
                title,
            });
        }
    }
    Ok(plots)
}

fn draw(
    axis: &str,
    values: &[AxisValue],
    numeric: bool,
    metric: Metric,
    title: &str,
    lines: &[(String, Line)],
) -> Result<String> {
    let (mut x0, mut x1) = if numeric {
        let xs: Vec<f64> = lines
            .iter()
            .flat_map(|(_, l)| l.iter().map(|p| p.0))
            .collect();
        let lo = xs.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = xs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        (lo, hi)
    } else {
        (0.0, values.len() as f64 - 1.0)
    };
    let pad = if numeric {
        0.05 * (x1 - x0).max(1e-9)
    } else {
        0.5
    };
    x0 -= pad;
    x1 += pad;
    let ys = lines
        .iter()
        .flat_map(|(_, l)| l.iter().flat_map(|p| [p.2, p.3]));
    let (ylo, yhi) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), y| {
        (a.min(y), b.max(y))
    });
    let ypad = 0.08 * (yhi - ylo).max(if metric.is_error() { 1.0 } else { 2.0 });
    let (y0, y1) = ((ylo - ypad).max(0.0), yhi + ypad);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(plot_error)?;
        // The legend gets its own column right of the chart, so it never
        // hides a line.
        let (plot_area, legend_area) = root.split_horizontally(SIZE.0 - LEGEND_WIDTH);
        let mut chart = ChartBuilder::on(&plot_area)
            .caption(title, ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(48)
            .y_label_area_size(64)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(plot_error)?;
        let category = |x: &f64| -> String {
            let i = x.round();
            if (x - i).abs() < 1e-6 && i >= 0.0 && (i as usize) < values.len() {
                values[i as usize].to_string()
            } else {
                String::new()
            }
        };
        let number = |x: &f64| format!("{}", (x * 1e6).round() / 1e6);
        let mut mesh = chart.configure_mesh();
        mesh.x_desc(axes::label(axis))
            .y_desc(metric.label())
            .axis_desc_style(("sans-serif", 15))
            .label_style(("sans-serif", 13))
            .light_line_style(TRANSPARENT)
            .bold_line_style(RGBColor(225, 225, 225));
        if numeric {
            mesh.x_label_formatter(&number);
        } else {
            mesh.x_labels(values.len().max(2) * 2 + 1)
                .x_label_formatter(&category);
        }
        mesh.draw().map_err(plot_error)?;
        for (i, (_, line)) in lines.iter().enumerate() {
            let colour = PALETTE[i % PALETTE.len()];
            if line.len() > 1 {
                let band: Vec<(f64, f64)> = line
                    .iter()
                    .map(|p| (p.0, p.3))
                    .chain(line.iter().rev().map(|p| (p.0, p.2)))
                    .collect();
                chart
                    .draw_series(std::iter::once(Polygon::new(band, colour.mix(0.15))))
                    .map_err(plot_error)?;
            }
            // Interval ends as whiskers, so a single point shows its interval too.
            chart
                .draw_series(line.iter().map(|p| {
                    PathElement::new(
                        vec![(p.0, p.2), (p.0, p.3)],
                        colour.mix(0.6).stroke_width(1),
                    )
                }))
                .map_err(plot_error)?;
            chart
                .draw_series(LineSeries::new(
                    line.iter().map(|p| (p.0, p.1)),
                    colour.stroke_width(2),
                ))
                .map_err(plot_error)?;
            chart
                .draw_series(
                    line.iter()
                        .map(|p| Circle::new((p.0, p.1), 3, colour.filled())),
                )
                .map_err(plot_error)?;
        }
        for (i, (name, _)) in lines.iter().enumerate() {
            let colour = PALETTE[i % PALETTE.len()];
            let y = 56 + 22 * i as i32;
            legend_area
                .draw(&PathElement::new(
                    vec![(4, y), (26, y)],
                    colour.stroke_width(2),
                ))
                .map_err(plot_error)?;
            legend_area
                .draw(&Circle::new((15, y), 3, colour.filled()))
                .map_err(plot_error)?;
            legend_area
                .draw(&Text::new(
                    name.clone(),
                    (32, y - 7),
                    ("sans-serif", 13).into_font(),
                ))
                .map_err(plot_error)?;
        }
        root.present().map_err(plot_error)?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::methods::catalog;
    use crate::row::Row;
    use sfp_core::metrics::Metrics;

    fn row(method: &str, light: &str, wobble: f64, seed: u64, mae: f64) -> Row {
        Row {
            key: format!("{method}{light}{wobble}{seed}"),
            dataset: "d".into(),
            view: "v".into(),
            object: "o".into(),
            axes: [
                ("light".to_string(), AxisValue::Text(light.into())),
                ("wobble".to_string(), AxisValue::Number(wobble)),
                ("eta".to_string(), AxisValue::Number(1.5)),
            ]
            .into(),
            method: method.into(),
            config: serde_json::json!({ "method": method }),
            seed,
            metrics: Some(Metrics {
                mae_deg: mae,
                rmse_deg: mae,
                median_deg: mae,
                acc_11_25: 50.0,
                acc_22_5: 60.0,
                acc_30: 70.0,
                pixels: 10,
                missing: 0,
                specular: None,
            }),
            error: None,
            view_dir: String::new(),
            pictures: None,
            estimates: None,
            exit_status: None,
            stderr_tail: None,
        }
    }

    #[test]
    fn text_and_unknown_axes_are_plotted_with_their_names() {
        let mut rows = Vec::new();
        for (light, wobble) in [("ring", 1.0), ("sun", 2.0)] {
            for seed in 0..3 {
                rows.push(row("smith", light, wobble, seed, 10.0 + seed as f64));
                rows.push(row("smsfp", light, wobble, seed, 5.0 + seed as f64));
            }
        }
        let dir = tempfile::tempdir().unwrap();
        let methods = catalog(&rows);
        let stats = Statistics::new(&rows, &methods, None);
        // `eta` has one value: no plot of it.
        let swept: Vec<&str> = stats.axes.iter().map(|a| a.axis.as_str()).collect();
        assert_eq!(swept, ["light", "wobble"]);
        let plots = write(dir.path(), &stats, &methods).unwrap();
        assert_eq!(plots.len(), 2 * Metric::ALL.len());
        let svg = std::fs::read_to_string(dir.path().join("plots/mae_deg-vs-light.svg")).unwrap();
        for text in [
            "ring",
            "sun",
            "light rig",
            "mean angular error (°)",
            "Smith",
            "SMSfP",
        ] {
            assert!(svg.contains(text), "{text} not in the plot");
        }
        let svg = std::fs::read_to_string(dir.path().join("plots/acc_30-vs-wobble.svg")).unwrap();
        // plotters writes each text on a line of its own.
        assert!(
            svg.contains("\nwobble\n"),
            "the raw axis name, without a unit, labels an unknown axis"
        );
        assert!(svg.contains("pixels with error &lt;30° (%)"));
    }
}
