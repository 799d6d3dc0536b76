//! `cellrt report FILE.mcap --out DIR [--csv]`: one SVG per axis (setpoint vs actual position
//! and velocity, following error, torque, all over time with the events marked), a wakeup
//! latency histogram, an `index.html` tying them together, and with `--csv` the per-cycle data.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

use cellrt_runtime::host::record::proto::{AxisCycle, Event};
use cellrt_runtime::rt::histogram::NsHistogram;
use plotters::prelude::*;

use crate::cli::ReportArgs;
use crate::commands::inspect::{event_line, FAULT_KINDS};
use crate::exit::Exit;
use cellrt_recording::{CellInfo, RecFile, Records};

/// Most points drawn per series (a min/max envelope keeps the peaks of longer series).
const MAX_POINTS: usize = 4000;

/// Colour of the markers of faults, stops, underruns and rejections (orange: the series use
/// blue and red).
pub const ALARM: RGBColor = RGBColor(255, 128, 0);

/// Events not marked on the plots (too frequent to read).
const UNMARKED: [&str; 2] = ["fsa_state", "planner_connected"];

/// Runs `cellrt report`.
pub fn run(args: ReportArgs) -> Exit {
    let file = match RecFile::open(&args.file) {
        Ok(f) => f,
        Err(e) => {
            eprintln!("error: {e}");
            return Exit::BadInput;
        }
    };
    let loaded = file
        .cell()
        .and_then(|cell| file.decode(&cell, true).map(|r| (cell, r)));
    let (cell, recs) = match loaded {
        Ok(v) => v,
        Err(e) => {
            eprintln!("error: {e}");
            return Exit::BadInput;
        }
    };
    if recs.cycles.is_empty() {
        eprintln!("error: {}: no cycles recorded", args.file.display());
        return Exit::BadInput;
    }
    match write_report(&file, &cell, &recs, &args.out, args.csv) {
        Ok(n) => {
            println!(
                "report of {} written to {} ({n} files): open {}",
                args.file.display(),
                args.out.display(),
                args.out.join("index.html").display()
            );
            Exit::Ok
        }
        Err(e) => {
            eprintln!("error: {e}");
            Exit::Failed
        }
    }
}

/// Why a report's file is not written.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// The directory or a CSV or HTML file cannot be written.
    #[error("{}: {source}", .path.display())]
    Write {
        /// The file or directory.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A plot cannot be drawn or written.
    #[error("{}: {source}", .path.display())]
    Plot {
        /// The SVG file.
        path: PathBuf,
        /// Why.
        source: PlotErr,
    },
}

fn write_report(
    file: &RecFile,
    cell: &CellInfo,
    recs: &Records,
    out: &Path,
    csv: bool,
) -> Result<usize, ReportError> {
    let io = |p: &Path| {
        let path = p.to_path_buf();
        move |source| ReportError::Write { path, source }
    };
    let plot = |p: &Path| {
        let path = p.to_path_buf();
        move |source| ReportError::Plot { path, source }
    };
    std::fs::create_dir_all(out).map_err(io(out))?;
    let period = cell.cycle_time_us.max(1) as f64 / 1e6;
    let first = recs.cycles[0].cycle;
    let t = |cycle: u64| (cycle as f64 - first as f64) * period;
    let marks: Vec<(f64, bool)> = recs
        .events
        .iter()
        .filter(|e| !UNMARKED.contains(&e.kind.as_str()))
        .map(|e| (t(e.cycle), is_alarm(e)))
        .collect();
    let mut files = 0;
    let mut html = String::new();
    let _ = write!(
        html,
        "<!doctype html><html><head><meta charset=\"utf-8\"><title>cellrt report: {}</title>\
         <style>body{{font-family:sans-serif;margin:2em}}td,th{{padding:0 .8em;text-align:left}}\
         .alarm{{color:#b00}}</style></head><body>\n<h1>cellrt report: cell {}</h1>\n\
         <p>{} — {} µs cycle, {} cycles ({:.3} s), {} axes, written by {}</p>\n",
        esc(&cell.name),
        esc(&cell.name),
        esc(&file.path.display().to_string()),
        cell.cycle_time_us,
        recs.cycles.len(),
        t(recs.cycles.last().map(|c| c.cycle).unwrap_or(first)) + period,
        cell.axes.len(),
        esc(&cell.software)
    );
    let last = recs.cycles.last().expect("checked non-empty");
    let mut wake = NsHistogram::new();
    for c in &recs.cycles {
        wake.record(u64::from(c.wakeup_latency_ns));
    }
    let w = wake.percentiles();
    let _ = writeln!(
        html,
        "<p>overruns {} · dropped records {} · wakeup latency p50 {:.1} µs, p99 {:.1} µs, \
         p99.9 {:.1} µs, max {:.1} µs</p>",
        last.overruns, last.dropped_records, w.p50_us, w.p99_us, w.p999_us, w.max_us
    );
    let _ = writeln!(
        html,
        "<p>Plots mark events as vertical lines (orange: faults, stops, underruns, \
         rejections, overruns; grey: other events except FSA changes).</p>"
    );

    for (i, name) in cell.axes.iter().enumerate() {
        let samples = &recs.axes[i];
        if samples.is_empty() {
            continue;
        }
        let unit = cell
            .axis_details
            .get(i)
            .and_then(|d| d.split_whitespace().find_map(|kv| kv.strip_prefix("unit=")))
            .unwrap_or("unit")
            .to_string();
        let fname = format!("axis-{}.svg", sanitize(name));
        let path = out.join(&fname);
        axis_plot(&path, name, &unit, samples, &t, &marks).map_err(plot(&path))?;
        files += 1;
        let _ = writeln!(
            html,
            "<h2>axis {}</h2>\n<img src=\"{}\" alt=\"axis {}\" width=\"1200\">",
            esc(name),
            fname,
            esc(name)
        );
        if csv {
            let p = out.join(format!("axis-{}.csv", sanitize(name)));
            axis_csv(&p, samples, &t).map_err(io(&p))?;
            files += 1;
        }
    }
    let path = out.join("latency.svg");
    latency_plot(&path, &wake).map_err(plot(&path))?;
    files += 1;
    let _ = writeln!(
        html,
        "<h2>wakeup latency</h2>\n<img src=\"latency.svg\" alt=\"latency histogram\" width=\"900\">"
    );
    if csv {
        let p = out.join("cycles.csv");
        cycles_csv(&p, recs, &t).map_err(io(&p))?;
        files += 1;
        let _ = writeln!(
            html,
            "<p>CSV: <a href=\"cycles.csv\">cycles.csv</a> and one <code>axis-NAME.csv</code> \
             per axis.</p>"
        );
    }
    let _ = writeln!(html, "<h2>events ({})</h2>\n<table>", recs.events.len());
    for e in &recs.events {
        let _ = writeln!(
            html,
            "<tr{}><td>{}</td></tr>",
            if is_alarm(e) { " class=\"alarm\"" } else { "" },
            esc(&event_line(e, first, cell.cycle_time_us))
        );
    }
    let _ = writeln!(html, "</table>\n</body></html>");
    let p = out.join("index.html");
    std::fs::write(&p, html).map_err(io(&p))?;
    Ok(files + 1)
}

/// Events drawn in red.
fn is_alarm(e: &Event) -> bool {
    FAULT_KINDS.contains(&e.kind.as_str())
        || matches!(
            e.kind.as_str(),
            "underrun"
                | "setpoint_rejected"
                | "stop_started"
                | "overrun"
                | "records_dropped"
                | "fault_injected"
                | "fault_left_to_segment"
                | "al_status"
                | "emergency"
                | "mailbox_discarded"
                | "bring_up_warning"
                | "planner_lost"
        )
}

fn sanitize(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// At most [`MAX_POINTS`] points: the min and max of each bucket, in time order.
fn decimate(points: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
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

/// (min, max) of the series' values, widened when flat.
fn y_range(series: &[&[(f64, f64)]]) -> (f64, f64) {
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
    let pad = ((hi - lo) * 0.05).max(1e-9);
    if hi - lo < 1e-9 {
        return (lo - 1.0, hi + 1.0);
    }
    (lo - pad, hi + pad)
}

type PlotErr = Box<dyn std::error::Error>;

/// A plot panel: y label and its lines (legend, points, colour).
type Panel = (String, Vec<(String, Vec<(f64, f64)>, RGBColor)>);

fn axis_plot(
    path: &Path,
    name: &str,
    unit: &str,
    s: &[AxisCycle],
    t: &dyn Fn(u64) -> f64,
    marks: &[(f64, bool)],
) -> Result<(), PlotErr> {
    let series = |f: &dyn Fn(&AxisCycle) -> f64| -> Vec<(f64, f64)> {
        decimate(s.iter().map(|a| (t(a.cycle), f(a))).collect())
    };
    let t0 = t(s[0].cycle);
    let t1 = t(s[s.len() - 1].cycle).max(t0 + 1e-3);
    let panels: [Panel; 4] = [
        (
            format!("position [{unit}]"),
            vec![
                ("setpoint".into(), series(&|a| a.setpoint_position), BLUE),
                ("actual".into(), series(&|a| a.actual_position), RED),
            ],
        ),
        (
            format!("velocity [{unit}/s]"),
            vec![
                ("setpoint".into(), series(&|a| a.setpoint_velocity), BLUE),
                ("actual".into(), series(&|a| a.actual_velocity), RED),
            ],
        ),
        (
            format!("following error [{unit}]"),
            vec![("60F4h".into(), series(&|a| a.following_error), MAGENTA)],
        ),
        (
            "torque [0.1 % rated]".into(),
            vec![
                (
                    "setpoint (6071h)".into(),
                    series(&|a| f64::from(a.setpoint_torque)),
                    BLUE,
                ),
                (
                    "actual (6077h)".into(),
                    series(&|a| f64::from(a.actual_torque)),
                    RED,
                ),
            ],
        ),
    ];
    let root = SVGBackend::new(path, (1200, 1000)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(&format!("axis {name}"), ("sans-serif", 22))?;
    let areas = root.split_evenly((4, 1));
    for (area, (label, lines)) in areas.iter().zip(panels.iter()) {
        let refs: Vec<&[(f64, f64)]> = lines.iter().map(|l| l.1.as_slice()).collect();
        let (lo, hi) = y_range(&refs);
        let mut chart = ChartBuilder::on(area)
            .margin(8)
            .x_label_area_size(28)
            .y_label_area_size(70)
            .build_cartesian_2d(t0..t1, lo..hi)?;
        chart
            .configure_mesh()
            .x_desc("time [s]")
            .y_desc(label.as_str())
            .light_line_style(WHITE.mix(0.0))
            .draw()?;
        for (t, alarm) in marks {
            let color = if *alarm {
                ALARM.mix(0.9)
            } else {
                BLACK.mix(0.25)
            };
            chart.draw_series(LineSeries::new([(*t, lo), (*t, hi)], color))?;
        }
        for (lname, pts, color) in lines {
            let c = *color;
            chart
                .draw_series(LineSeries::new(pts.iter().copied(), c))?
                .label(lname.as_str())
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 16, y)], c));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()?;
    }
    root.present()?;
    Ok(())
}

fn latency_plot(path: &Path, h: &NsHistogram) -> Result<(), PlotErr> {
    let buckets = h.buckets();
    let root = SVGBackend::new(path, (900, 450)).into_drawing_area();
    root.fill(&WHITE)?;
    // Bins of 5 µs up to the p99.9 (at least 100 µs), the rest in one last bin.
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

fn axis_csv(path: &Path, s: &[AxisCycle], t: &dyn Fn(u64) -> f64) -> std::io::Result<()> {
    let mut w = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(
        w,
        "cycle,time_s,setpoint_position,actual_position,following_error,setpoint_velocity,\
         actual_velocity,setpoint_counts,actual_position_counts,actual_velocity_counts,\
         following_error_counts,setpoint_torque,actual_torque,controlword,statusword,fsa_state,\
         mode_display,error_code,counter_sent,counter_received"
    )?;
    for a in s {
        writeln!(
            w,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            a.cycle,
            t(a.cycle),
            a.setpoint_position,
            a.actual_position,
            a.following_error,
            a.setpoint_velocity,
            a.actual_velocity,
            a.setpoint_counts,
            a.actual_position_counts,
            a.actual_velocity_counts,
            a.following_error_counts,
            a.setpoint_torque,
            a.actual_torque,
            a.controlword,
            a.statusword,
            a.fsa_state,
            a.mode_display,
            a.error_code,
            a.counter_sent,
            a.counter_received
        )?;
    }
    w.flush()
}

fn cycles_csv(path: &Path, recs: &Records, t: &dyn Fn(u64) -> f64) -> std::io::Result<()> {
    let mut w = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(
        w,
        "cycle,time_s,deadline_ns,wakeup_latency_ns,loop_time_ns,overruns,cell_state,dropped_records"
    )?;
    for c in &recs.cycles {
        writeln!(
            w,
            "{},{},{},{},{},{},{},{}",
            c.cycle,
            t(c.cycle),
            c.deadline_ns,
            c.wakeup_latency_ns,
            c.loop_time_ns,
            c.overruns,
            c.cell_state,
            c.dropped_records
        )?;
    }
    w.flush()
}
