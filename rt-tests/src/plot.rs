//! `--plot FILE.svg`: the latency histograms of cellrt and cyclictest overlaid, log-scale
//! latency (µs) against log-scale count.

use std::path::Path;

use plotters::prelude::*;

use crate::error::BenchError;
use crate::hist::UsHistogram;

/// Draws the named histograms into an SVG file.
pub fn histograms_svg(
    path: &Path,
    title: &str,
    series: &[(&str, &UsHistogram)],
) -> Result<(), BenchError> {
    draw(path, title, series)
        .map_err(|e| BenchError::failed(format!("cannot draw {}: {e}", path.display())))
}

fn draw(
    path: &Path,
    title: &str,
    series: &[(&str, &UsHistogram)],
) -> Result<(), Box<dyn std::error::Error>> {
    // Bucket b holds [b, b+1) µs: plot it at its middle so bucket 0 fits a log axis.
    let x_max = series
        .iter()
        .filter_map(|(_, h)| h.buckets.keys().next_back())
        .copied()
        .max()
        .unwrap_or(1) as f64
        + 1.0;
    let y_max = series
        .iter()
        .flat_map(|(_, h)| h.buckets.values())
        .copied()
        .max()
        .unwrap_or(1) as f64;
    let root = SVGBackend::new(path, (1000, 600)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 20))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(65)
        .build_cartesian_2d(
            (0.5f64..x_max * 1.2).log_scale(),
            (0.8f64..y_max * 2.0).log_scale(),
        )?;
    chart
        .configure_mesh()
        .x_desc("wakeup latency, µs (1 µs buckets)")
        .y_desc("samples")
        .draw()?;
    let colors = [RED, BLUE, GREEN, MAGENTA];
    for (i, (name, h)) in series.iter().enumerate() {
        let color = colors[i % colors.len()];
        let points: Vec<(f64, f64)> = h
            .buckets
            .iter()
            .map(|(&us, &n)| (us as f64 + 0.5, n as f64))
            .collect();
        chart
            .draw_series(LineSeries::new(points, color.stroke_width(2)))?
            .label(format!("{name} ({} samples)", h.count()))
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
            });
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperRight)
        .draw()?;
    root.present()?;
    Ok(())
}
