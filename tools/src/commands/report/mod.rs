//! `cellrt report FILE.mcap --out DIR [--csv] [--settle-band COUNTS]`: one SVG per axis
//! (setpoint vs actual position and velocity, following error, torque, all over time with the
//! events marked and labelled), a wakeup latency histogram, an `index.html` tying them together
//! with a per-move table (travel, peak speed and following error, settling time), and with
//! `--csv` the per-cycle data.

mod moves;
mod plot;

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

use cellrt_runtime::host::record::proto::{AxisCycle, Event};
use cellrt_runtime::rt::histogram::NsHistogram;

use crate::cli::ReportArgs;
use crate::commands::inspect::{event_line, FAULT_KINDS};
use crate::exit::Exit;
use cellrt_recording::{CellInfo, RecFile, Records};

use moves::{move_table, MoveRow};
use plot::{axis_plot, latency_plot, AxisPlot, Mark, MarkKind, PlotErr};

/// The smallest span of the following-error scale, counts: quantisation noise of a few counts
/// stays a thin line instead of filling the panel.
const MIN_ERROR_SPAN_COUNTS: f64 = 40.0;

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
    if !(args.settle_band.is_finite() && args.settle_band >= 0.0) {
        eprintln!(
            "error: --settle-band: must be a count of 0 or more (got {})",
            args.settle_band
        );
        return Exit::BadInput;
    }
    match write_report(&file, &cell, &recs, &args) {
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

/// The counts per unit in an axis' recorded details (`counts_per_unit=…`), 1 where missing.
fn counts_per_unit(cell: &CellInfo, axis: usize) -> f64 {
    cell.axis_field(axis, "counts_per_unit")
        .and_then(|v| v.parse::<f64>().ok())
        .filter(|v| v.is_finite() && *v > 0.0)
        .unwrap_or(1.0)
}

/// An axis' unit in its recorded details (`unit=…`).
fn unit_of(cell: &CellInfo, axis: usize) -> String {
    cell.axis_field(axis, "unit").unwrap_or("unit").to_string()
}

/// The events marked on the plots: alarms and motion starts labelled, overruns as ticks; the
/// others (state changes, commands, FSA steps) are in the event table only.
fn marks(recs: &Records, t: &dyn Fn(u64) -> f64) -> Vec<Mark> {
    recs.events
        .iter()
        .filter_map(|e| {
            let kind = if e.kind == "overrun" {
                MarkKind::Overrun
            } else if is_alarm(e) {
                MarkKind::Alarm
            } else if e.kind == "motion_started" {
                MarkKind::MotionStart
            } else {
                return None;
            };
            let label = match kind {
                MarkKind::Overrun => String::new(),
                MarkKind::MotionStart => format!("motion {}", e.value),
                MarkKind::Alarm if e.axis.is_empty() => e.kind.clone(),
                MarkKind::Alarm => format!("{} [{}]", e.kind, e.axis),
            };
            Some(Mark {
                t: t(e.cycle),
                kind,
                label,
            })
        })
        .collect()
}

/// The per-move table as HTML.
fn move_table_html(rows: &[MoveRow], cell: &CellInfo, band_counts: f64) -> String {
    let period = cell.cycle_time_us.max(1) as f64 / 1e6;
    let mut html = format!(
        "<h2>moves ({})</h2>\n<p>Per motion and axis it moved: settled once |actual − final \
         setpoint| stays within {band_counts} counts (<code>--settle-band</code>) until the \
         next motion; the peak following error is taken until then.</p>\n<table>\n\
         <tr><th>motion</th><th>axis</th><th>start [s]</th><th>duration [s]</th>\
         <th>travel</th><th>peak speed</th><th>peak following error</th>\
         <th>settling [ms]</th></tr>\n",
        rows.len()
    );
    for r in rows {
        let name = cell.axes.get(r.axis).map_or("?", String::as_str);
        let unit = unit_of(cell, r.axis);
        let settling = r.settling_cycles.map_or_else(
            || "<span class=\"alarm\">not settled</span>".to_string(),
            |c| format!("{:.1}", c as f64 * period * 1e3),
        );
        let _ = writeln!(
            html,
            "<tr><td>{}</td><td>{}</td><td>{:.3}</td><td>{:.3}</td><td>{:+.4} {unit}</td>\
             <td>{:.3} {unit}/s</td><td>{:.4} {unit}</td><td>{settling}</td></tr>",
            r.motion,
            esc(name),
            r.start_cycle as f64 * period,
            r.duration_cycles as f64 * period,
            r.travel,
            r.peak_velocity,
            r.peak_following_error,
            unit = esc(&unit)
        );
    }
    html.push_str("</table>\n");
    html
}

fn write_report(
    file: &RecFile,
    cell: &CellInfo,
    recs: &Records,
    args: &ReportArgs,
) -> Result<usize, ReportError> {
    let (out, csv) = (args.out.as_path(), args.csv);
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
    let marks = marks(recs, &t);
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
        "<p>Setpoints are drawn as a wide light-blue band, actual values as a thin dark-red \
         line on it. Events are marked as vertical lines labelled above the plots (orange: \
         faults, stops, underruns, rejections; grey dashed: motion starts); overruns are orange \
         ticks at the top of each panel. Every event is in the table at the end.</p>"
    );
    let on_loop: Vec<&[AxisCycle]> = recs.axes.iter().map(Vec::as_slice).collect();
    let bands: Vec<f64> = (0..cell.axes.len())
        .map(|i| args.settle_band / counts_per_unit(cell, i))
        .collect();
    html.push_str(&move_table_html(
        &move_table(&recs.events, &on_loop, &bands),
        cell,
        args.settle_band,
    ));

    for (i, name) in cell.axes.iter().enumerate() {
        let samples = &recs.axes[i];
        if samples.is_empty() {
            continue;
        }
        let unit = unit_of(cell, i);
        let fname = format!("axis-{}.svg", sanitize(name));
        let path = out.join(&fname);
        let axis = AxisPlot {
            name,
            unit: &unit,
            samples,
            min_error_span: MIN_ERROR_SPAN_COUNTS / counts_per_unit(cell, i),
        };
        axis_plot(&path, &axis, &t, &marks).map_err(plot(&path))?;
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
