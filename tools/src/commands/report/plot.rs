//! The report's SVG plots: per axis the position, velocity, following error and torque over
//! time with the events marked and labelled, and the wakeup latency histogram.

use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use cellrt_runtime::host::record::proto::AxisCycle;
use cellrt_runtime::rt::histogram::NsHistogram;

/// Most points drawn per series (a min/max envelope keeps the peaks of longer series).
const MAX_POINTS: usize = 4000;

/// Colour of the markers of faults, stops, underruns and rejections.
pub const ALARM: RGBColor = RGBColor(255, 128, 0);
/// The setpoint: a wide, light band the actual is drawn on, so both stay visible where equal.
const SETPOINT: RGBColor = RGBColor(110, 160, 230);
/// The actual value: a thin dark line.
const ACTUAL: RGBColor = RGBColor(170, 0, 30);
/// Motion starts and other events.
const EVENT: RGBColor = RGBColor(90, 90, 90);

/// The plots' width and the height of one panel, pixels.
const WIDTH: u32 = 1200;
const PANEL_HEIGHT: u32 = 210;
/// The title, the event labels above the panels, and the time axis below them, pixels.
const TITLE_HEIGHT: u32 = 30;
const LANE_HEIGHT: u32 = 46;
const TIME_AXIS_HEIGHT: u32 = 36;

/// Why a plot is not drawn.
pub type PlotErr = Box<dyn std::error::Error>;

/// What a vertical mark on the plots stands for.
#[derive(Debug, Clone, PartialEq)]
pub enum MarkKind {
    /// A fault, stop, underrun or rejection: an orange line, labelled.
    Alarm,
    /// A motion's start: a grey dashed line, labelled with the motion.
    MotionStart,
    /// An overrun of the RT loop: a short orange tick at the top of each panel (too frequent
    /// on a loaded machine to label).
    Overrun,
}

/// An event marked on the plots.
#[derive(Debug, Clone, PartialEq)]
pub struct Mark {
    /// Seconds from the recording's first cycle.
    pub t: f64,
    /// What it is.
    pub kind: MarkKind,
    /// Its label (empty for overruns).
    pub label: String,
}

/// One axis' plot: its name, unit and samples, and the smallest span of the following-error
/// scale (so quantisation noise of a few counts is not blown up to the panel's height).
pub struct AxisPlot<'a> {
    /// The axis.
    pub name: &'a str,
    /// Its unit (mm, deg…).
    pub unit: &'a str,
    /// Its samples.
    pub samples: &'a [AxisCycle],
    /// The smallest span of the following-error scale, units.
    pub min_error_span: f64,
}

/// At most [`MAX_POINTS`] points: the min and max of each bucket, in time order.
pub fn decimate(points: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    if points.len() <= MAX_POINTS {
        return points;
    }
    let per = points.len().div_ceil(MAX_POINTS / 2);
    let mut out = Vec::with_capacity(MAX_POINTS + 2);
    for b in points.chunks(per) {
        let lo = b
            .iter()
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .expect("non-empty");
        let hi = b
            .iter()
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .expect("non-empty");
        if lo.0 <= hi.0 {
            out.extend([*lo, *hi]);
        } else {
            out.extend([*hi, *lo]);
        }
    }
    out
}

/// (min, max) of the series' values with 5 % headroom, spanning at least `min_span` (centred
/// on the values) and never empty.
pub fn y_range(series: &[&[(f64, f64)]], min_span: f64) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for s in series {
        for p in *s {
            if p.1.is_finite() {
                lo = lo.min(p.1);
                hi = hi.max(p.1);
            }
        }
    }
    if !lo.is_finite() {
        return (-1.0, 1.0);
    }
    let pad = (hi - lo) * 0.05;
    let (lo, hi) = (lo - pad, hi + pad);
    let span = min_span.max(1e-9);
    if hi - lo < span {
        let mid = (lo + hi) / 2.0;
        return (mid - span / 2.0, mid + span / 2.0);
    }
    (lo, hi)
}

/// Decimals of the y labels of a scale spanning `span`: about three significant digits.
fn label_decimals(span: f64) -> usize {
    if !(span.is_finite() && span > 0.0) {
        return 1;
    }
    (2.0 - span.log10().floor()).clamp(0.0, 6.0) as usize
}

/// A panel: its y label and its lines (legend, points, colour, stroke width).
type Panel = (
    String,
    Vec<(&'static str, Vec<(f64, f64)>, RGBColor, u32)>,
    f64,
);

/// Draws `axis` to `path`: one panel per quantity, sharing the time axis (drawn once, at the
/// bottom), the `marks` as vertical lines labelled above the first panel. The torque panel is
/// left out where the drive reported no torque.
pub fn axis_plot(
    path: &std::path::Path,
    axis: &AxisPlot,
    t: &dyn Fn(u64) -> f64,
    marks: &[Mark],
) -> Result<(), PlotErr> {
    let s = axis.samples;
    let series = |f: &dyn Fn(&AxisCycle) -> f64| -> Vec<(f64, f64)> {
        decimate(s.iter().map(|a| (t(a.cycle), f(a))).collect())
    };
    let t0 = t(s[0].cycle);
    let t1 = t(s[s.len() - 1].cycle).max(t0 + 1e-3);
    let unit = axis.unit;
    let mut panels: Vec<Panel> = vec![
        (
            format!("position [{unit}]"),
            vec![
                ("setpoint", series(&|a| a.setpoint_position), SETPOINT, 5),
                ("actual", series(&|a| a.actual_position), ACTUAL, 1),
            ],
            0.0,
        ),
        (
            format!("velocity [{unit}/s]"),
            vec![
                ("setpoint", series(&|a| a.setpoint_velocity), SETPOINT, 5),
                ("actual", series(&|a| a.actual_velocity), ACTUAL, 1),
            ],
            0.0,
        ),
        (
            format!("following error [{unit}]"),
            vec![("60F4h", series(&|a| a.following_error), ACTUAL, 1)],
            axis.min_error_span,
        ),
    ];
    if s.iter()
        .any(|a| a.setpoint_torque != 0 || a.actual_torque != 0)
    {
        panels.push((
            "torque [0.1 % rated]".into(),
            vec![
                (
                    "setpoint (6071h)",
                    series(&|a| f64::from(a.setpoint_torque)),
                    SETPOINT,
                    5,
                ),
                (
                    "actual (6077h)",
                    series(&|a| f64::from(a.actual_torque)),
                    ACTUAL,
                    1,
                ),
            ],
            0.0,
        ));
    }
    let n = panels.len() as u32;
    let height = TITLE_HEIGHT + LANE_HEIGHT + n * PANEL_HEIGHT + TIME_AXIS_HEIGHT;
    let root = SVGBackend::new(path, (WIDTH, height)).into_drawing_area();
    root.fill(&WHITE)?;
    let overruns = marks.iter().filter(|m| m.kind == MarkKind::Overrun).count();
    let title = if overruns > 0 {
        format!(
            "axis {} — {overruns} overrun(s), ticked in orange at the top of each panel",
            axis.name
        )
    } else {
        format!("axis {}", axis.name)
    };
    let (top, rest) = root.split_vertically(TITLE_HEIGHT);
    top.titled(&title, ("sans-serif", 20))?;
    let (lane, rest) = rest.split_vertically(LANE_HEIGHT);
    let mut heights: Vec<u32> = (1..n).map(|k| k * PANEL_HEIGHT).collect();
    heights.push(n * PANEL_HEIGHT);
    let areas = rest.split_by_breakpoints::<u32, u32, _, _>(Vec::<u32>::new(), heights);
    let mut label_x: Vec<(f64, &Mark)> = Vec::new();
    for (k, (area, (label, lines, min_span))) in areas.iter().zip(panels.iter()).enumerate() {
        let bottom = k + 1 == panels.len();
        let refs: Vec<&[(f64, f64)]> = lines.iter().map(|l| l.1.as_slice()).collect();
        let (lo, hi) = y_range(&refs, *min_span);
        let mut chart = ChartBuilder::on(area)
            .margin_left(8)
            .margin_right(16)
            .margin_top(4)
            .x_label_area_size(if bottom { TIME_AXIS_HEIGHT } else { 0 })
            .y_label_area_size(80)
            .build_cartesian_2d(t0..t1, lo..hi)?;
        let decimals = label_decimals(hi - lo);
        // No "-0.00": a value that rounds to zero is printed as zero.
        let fmt = move |v: &f64| {
            let text = format!("{v:.decimals$}");
            match text.strip_prefix('-') {
                Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_string(),
                _ => text,
            }
        };
        let mut mesh = chart.configure_mesh();
        mesh.y_desc(label.as_str())
            .disable_x_mesh()
            .light_line_style(WHITE.mix(0.0))
            .bold_line_style(BLACK.mix(0.12))
            .y_label_formatter(&fmt);
        if bottom {
            mesh.x_desc("time [s]");
        }
        mesh.draw()?;
        draw_marks(&mut chart, marks, lo, hi)?;
        for (lname, pts, color, width) in lines {
            let c = *color;
            let w = *width;
            chart
                .draw_series(LineSeries::new(pts.iter().copied(), c.stroke_width(w)))?
                .label(*lname)
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 16, y)], c.stroke_width(w)));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.5))
            .position(SeriesLabelPosition::UpperRight)
            .draw()?;
        if k == 0 {
            label_x = marks
                .iter()
                .filter(|m| m.kind != MarkKind::Overrun)
                .map(|m| (f64::from(chart.backend_coord(&(m.t, hi)).0), m))
                .collect();
        }
    }
    draw_labels(&lane, &label_x)?;
    root.present()?;
    Ok(())
}

/// The marks on one panel: full-height lines for alarms and motion starts, short ticks at the
/// top for overruns.
fn draw_marks<DB: DrawingBackend>(
    chart: &mut ChartContext<DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    marks: &[Mark],
    lo: f64,
    hi: f64,
) -> Result<(), PlotErr>
where
    DB::ErrorType: 'static,
{
    let tick = (hi - lo) * 0.06;
    for m in marks {
        let line = [(m.t, lo), (m.t, hi)];
        match m.kind {
            MarkKind::Alarm => {
                chart.draw_series(LineSeries::new(line, ALARM.mix(0.9).stroke_width(1)))?;
            }
            MarkKind::MotionStart => {
                chart.draw_series(DashedLineSeries::new(
                    line,
                    4,
                    4,
                    EVENT.mix(0.6).stroke_width(1),
                ))?;
            }
            MarkKind::Overrun => {
                chart.draw_series(LineSeries::new(
                    [(m.t, hi - tick), (m.t, hi)],
                    ALARM.mix(0.9).stroke_width(2),
                ))?;
            }
        }
    }
    Ok(())
}

/// The labels of the marks in the lane above the first panel, at their lines' x (pixels of
/// the whole plot), left to right in up to three rows; a label that fits in no row is left
/// out (its line stays, and the report's event table lists it).
fn draw_labels<DB: DrawingBackend>(
    lane: &DrawingArea<DB, plotters::coord::Shift>,
    marks: &[(f64, &Mark)],
) -> Result<(), PlotErr>
where
    DB::ErrorType: 'static,
{
    const ROWS: usize = 3;
    const CHAR_PX: f64 = 6.2;
    let mut row_end = [f64::NEG_INFINITY; ROWS];
    let mut order: Vec<&(f64, &Mark)> = marks.iter().collect();
    order.sort_by(|a, b| a.0.total_cmp(&b.0));
    let lane_x0 = f64::from(lane.get_base_pixel().0);
    let lane_width = f64::from(lane.dim_in_pixel().0);
    for (x, m) in order {
        let x = x - lane_x0;
        let w = m.label.chars().count() as f64 * CHAR_PX + 4.0;
        // Left of its line where it would run off the right edge.
        let left = if x + w > lane_width { x - w } else { x };
        let Some(row) = (0..ROWS).find(|&r| row_end[r] < left) else {
            continue;
        };
        row_end[row] = left + w;
        let color = match m.kind {
            MarkKind::Alarm => RGBColor(200, 90, 0),
            _ => EVENT,
        };
        let y = 4 + row as i32 * 14;
        lane.draw(&Text::new(
            m.label.clone(),
            (left as i32 + 2, y),
            ("sans-serif", 11).into_font().color(&color),
        ))?;
        lane.draw(&PathElement::new(
            [(x as i32, y), (x as i32, LANE_HEIGHT as i32)],
            color.mix(0.5),
        ))?;
    }
    Ok(())
}

/// The wakeup latency histogram: 5 µs bins up to the p99.9 (at least 100 µs), the rest in one
/// last bin, on a log scale.
pub fn latency_plot(path: &std::path::Path, h: &NsHistogram) -> Result<(), PlotErr> {
    let buckets = h.buckets();
    let root = SVGBackend::new(path, (900, 450)).into_drawing_area();
    root.fill(&WHITE)?;
    let top_us = (h.quantile_ns(0.999) as f64 / 1e3).max(100.0).ceil();
    let width = 5.0;
    let nbins = (top_us / width).ceil() as usize + 1;
    let mut bins = vec![0u64; nbins];
    for (ns, n) in buckets {
        let us = ns as f64 / 1e3;
        let i = ((us / width) as usize).min(nbins - 1);
        bins[i] += n;
    }
    let ymax = bins.iter().copied().max().unwrap_or(1).max(1) as f64;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!(
                "wakeup latency ({} cycles; last bin: ≥ {:.0} µs)",
                h.len(),
                (nbins - 1) as f64 * width
            ),
            ("sans-serif", 20),
        )
        .margin(10)
        .x_label_area_size(32)
        .y_label_area_size(60)
        .build_cartesian_2d(
            0.0..(nbins as f64 * width),
            (0.5f64..ymax * 2.0).log_scale(),
        )?;
    chart
        .configure_mesh()
        .x_desc("wakeup latency [µs]")
        .y_desc("cycles")
        .draw()?;
    chart.draw_series(
        bins.iter()
            .enumerate()
            .filter(|(_, n)| **n > 0)
            .map(|(i, n)| {
                let x0 = i as f64 * width;
                Rectangle::new([(x0, 0.5), (x0 + width * 0.9, *n as f64)], BLUE.filled())
            }),
    )?;
    root.present()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flat_or_tiny_series_is_drawn_on_at_least_the_minimum_span() {
        let noise = [(0.0, 0.001), (1.0, -0.001)];
        let (lo, hi) = y_range(&[&noise], 0.02);
        assert!((hi - lo - 0.02).abs() < 1e-12 && lo < -0.001 && hi > 0.001);
        let big = [(0.0, -1.0), (1.0, 1.0)];
        let (lo, hi) = y_range(&[&big], 0.02);
        assert!((lo + 1.1).abs() < 1e-12 && (hi - 1.1).abs() < 1e-12);
        assert_eq!(y_range(&[&[]], 0.0), (-1.0, 1.0));
    }

    #[test]
    fn labels_carry_about_three_significant_digits() {
        assert_eq!(label_decimals(1540.0), 0);
        assert_eq!(label_decimals(3.2), 2);
        assert_eq!(label_decimals(0.04), 4);
        assert_eq!(label_decimals(0.0), 1);
    }
}
