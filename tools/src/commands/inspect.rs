//! `cellrt inspect FILE.mcap`: what a recording holds, from its summary and indexes where it
//! has them: cell, axes, channels and counts, timing percentiles, events and faults.

use std::fmt::Write as _;
use std::time::Instant;

use cellrt_runtime::rt::histogram::{NsHistogram, Percentiles};
use serde::Serialize;

use crate::cli::InspectArgs;
use crate::exit::Exit;
use cellrt_recording::{CellInfo, RecFile, Records};

/// Event kinds counted as faults.
pub const FAULT_KINDS: [&str; 3] = ["drive_fault", "master_timeout", "bus_error"];

/// Runs `cellrt inspect`.
pub fn run(args: InspectArgs) -> Exit {
    let started = Instant::now();
    let file = match RecFile::open(&args.file) {
        Ok(f) => f,
        Err(e) => {
            eprintln!("error: {e}");
            return Exit::BadInput;
        }
    };
    let cell = match file.cell() {
        Ok(c) => c,
        Err(e) => {
            eprintln!("error: {e}");
            return Exit::BadInput;
        }
    };
    let recs = match file.decode(&cell, false) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e}");
            return Exit::BadInput;
        }
    };
    let report = inspect(&file, &cell, &recs);
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&report).expect("the inspection serialises")
        );
    } else {
        print!("{}", render(&report));
    }
    if args.timing {
        eprintln!("inspect took {:.3} s", started.elapsed().as_secs_f64());
    }
    Exit::Ok
}

/// Seconds from the first recorded cycle to `cycle`.
fn t_of(cycle: u64, first: u64, period_us: u64) -> f64 {
    (cycle as f64 - first as f64) * period_us as f64 / 1e6
}

/// What `inspect` reports, printed as text or (`--json`) as one JSON document.
#[derive(Debug, Serialize)]
pub struct Inspection {
    /// The file.
    pub file: std::path::PathBuf,
    /// Its size, bytes.
    pub bytes: u64,
    /// True if the file has its summary and indexes.
    pub indexed: bool,
    /// Why it was read linearly (a damaged or truncated end), if it was.
    pub truncated: Option<String>,
    /// Cell name.
    pub cell: String,
    /// Cycle time, µs.
    pub cycle_time_us: u64,
    /// Every axis of the cell with its description, in configuration order.
    pub axes: Vec<InspectedAxis>,
    /// Axes on the RT loop.
    pub loop_axes: usize,
    /// Software that wrote it.
    pub software: String,
    /// First and last recorded cycle, `None` without cycles.
    pub cycles: Option<(u64, u64)>,
    /// Cycle records in the file.
    pub cycles_recorded: u64,
    /// Cycles between the first and the last without a record.
    pub cycles_skipped: u64,
    /// Seconds from the first recorded cycle to the last.
    pub duration_s: f64,
    /// Messages per channel.
    pub channels: Vec<InspectedChannel>,
    /// Overruns at the last cycle.
    pub overruns: u64,
    /// Records dropped on the way to the file, at the last cycle.
    pub dropped_records: u64,
    /// `records_dropped` events.
    pub records_dropped_events: usize,
    /// Wakeup latency.
    pub wakeup: Percentiles,
    /// Loop time.
    pub loop_time: Percentiles,
    /// Every event.
    pub events: Vec<InspectedEvent>,
    /// The events that are faults ([`FAULT_KINDS`]).
    pub faults: usize,
}

/// One axis of [`Inspection`].
#[derive(Debug, Serialize)]
pub struct InspectedAxis {
    /// Axis name.
    pub name: String,
    /// Its `axis.<name>` description.
    pub description: String,
}

/// One channel of [`Inspection`].
#[derive(Debug, Serialize)]
pub struct InspectedChannel {
    /// Topic.
    pub topic: String,
    /// Schema name.
    pub schema: String,
    /// Messages.
    pub messages: u64,
}

/// One event of [`Inspection`], with its fields apart.
#[derive(Debug, Serialize)]
pub struct InspectedEvent {
    /// Cycle.
    pub cycle: u64,
    /// Seconds from the first recorded cycle.
    pub t_s: f64,
    /// Event kind, e.g. `drive_fault`.
    pub kind: String,
    /// Axis, if the event names one.
    pub axis: Option<String>,
    /// Detail text.
    pub detail: String,
    /// True for a fault ([`FAULT_KINDS`]).
    pub fault: bool,
}

/// The inspection of `file` (its `cell` and decoded `recs`).
fn inspect(file: &RecFile, cell: &CellInfo, recs: &Records) -> Inspection {
    let period = cell.cycle_time_us.max(1);
    let cycles = match (recs.cycles.first(), recs.cycles.last()) {
        (Some(f), Some(l)) => Some((f.cycle, l.cycle)),
        _ => None,
    };
    let first = cycles.map_or(0, |c| c.0);
    let span = cycles.map_or(0, |(f, l)| l - f + 1);
    let mut wake = NsHistogram::new();
    let mut looptime = NsHistogram::new();
    for c in &recs.cycles {
        wake.record(u64::from(c.wakeup_latency_ns));
        looptime.record(u64::from(c.loop_time_ns));
    }
    let lastc = recs.cycles.last();
    let events: Vec<InspectedEvent> = recs
        .events
        .iter()
        .map(|e| InspectedEvent {
            cycle: e.cycle,
            t_s: t_of(e.cycle, first, period),
            kind: e.kind.clone(),
            axis: (!e.axis.is_empty()).then(|| e.axis.clone()),
            detail: e.detail.clone(),
            fault: FAULT_KINDS.contains(&e.kind.as_str()),
        })
        .collect();
    Inspection {
        file: file.path.clone(),
        bytes: file.bytes.len() as u64,
        indexed: file.indexed(),
        truncated: recs.truncated.as_ref().map(|t| t.to_string()),
        cell: cell.name.clone(),
        cycle_time_us: cell.cycle_time_us,
        axes: cell
            .cell_axes
            .iter()
            .map(|(name, description)| InspectedAxis {
                name: name.clone(),
                description: description.clone(),
            })
            .collect(),
        loop_axes: cell.axes.len(),
        software: cell.software.clone(),
        cycles,
        cycles_recorded: recs.cycles.len() as u64,
        cycles_skipped: span.saturating_sub(recs.cycles.len() as u64),
        duration_s: span as f64 * period as f64 / 1e6,
        channels: file
            .channel_counts()
            .into_iter()
            .map(|c| InspectedChannel {
                topic: c.topic,
                schema: c.schema,
                messages: c.count,
            })
            .collect(),
        overruns: lastc.map_or(0, |c| c.overruns),
        dropped_records: lastc.map_or(0, |c| c.dropped_records),
        records_dropped_events: recs
            .events
            .iter()
            .filter(|e| e.kind == "records_dropped")
            .count(),
        wakeup: wake.percentiles(),
        loop_time: looptime.percentiles(),
        faults: events.iter().filter(|e| e.fault).count(),
        events,
    }
}

fn render(r: &Inspection) -> String {
    let mut o = String::new();
    let mib = r.bytes as f64 / (1024.0 * 1024.0);
    let _ = writeln!(
        o,
        "file        {} ({mib:.1} MiB, {})",
        r.file.display(),
        match (&r.truncated, r.indexed) {
            (None, true) => "indexed".to_string(),
            (Some(why), _) => format!(
                "NOT indexed ({why}): read to the last complete chunk; `cellrt recover` rewrites it"
            ),
            (None, false) => "not indexed".to_string(),
        }
    );
    let _ = writeln!(
        o,
        "cell        {} — {} µs cycle, {} axes ({} on the RT loop), written by {}",
        r.cell,
        r.cycle_time_us,
        r.axes.len(),
        r.loop_axes,
        r.software
    );
    let _ = writeln!(o, "axes");
    for a in &r.axes {
        let _ = writeln!(o, "  {:<8} {}", a.name, a.description);
    }
    match r.cycles {
        None => {
            let _ = writeln!(o, "duration    no cycles recorded");
        }
        Some((first, last)) => {
            let _ = writeln!(
                o,
                "duration    {:.3} s: cycles {first}..={last}, {} recorded, {} skipped",
                r.duration_s, r.cycles_recorded, r.cycles_skipped
            );
        }
    }
    let _ = writeln!(
        o,
        "channels    topic                schema               messages"
    );
    for c in &r.channels {
        let _ = writeln!(o, "  {:<26} {:<20} {:>9}", c.topic, c.schema, c.messages);
    }
    let _ = writeln!(
        o,
        "overruns    {}   dropped records {} ({} records_dropped events)",
        r.overruns, r.dropped_records, r.records_dropped_events
    );
    let (w, l) = (&r.wakeup, &r.loop_time);
    let _ = writeln!(
        o,
        "wakeup      p50 {:.1} µs   p99 {:.1} µs   p99.9 {:.1} µs   max {:.1} µs",
        w.p50_us, w.p99_us, w.p999_us, w.max_us
    );
    let _ = writeln!(
        o,
        "loop time   p50 {:.1} µs   p99 {:.1} µs   p99.9 {:.1} µs   max {:.1} µs",
        l.p50_us, l.p99_us, l.p999_us, l.max_us
    );
    let _ = writeln!(o, "events      {}", r.events.len());
    for e in &r.events {
        let _ = writeln!(o, "  {}", inspected_line(e));
    }
    if r.faults == 0 {
        let _ = writeln!(o, "faults      none");
    } else {
        let _ = writeln!(o, "faults      {}", r.faults);
        for e in r.events.iter().filter(|e| e.fault) {
            let _ = writeln!(o, "  {}", inspected_line(e));
        }
    }
    o
}

/// An event of [`Inspection`] as [`event_line`] writes it.
fn inspected_line(e: &InspectedEvent) -> String {
    line_of(
        e.cycle,
        e.t_s,
        &e.kind,
        e.axis.as_deref().unwrap_or(""),
        &e.detail,
    )
}

/// `cycle N (t s): kind [axis]: detail`.
pub fn event_line(
    e: &cellrt_runtime::host::record::proto::Event,
    first_cycle: u64,
    period_us: u64,
) -> String {
    let t_s = t_of(e.cycle, first_cycle, period_us);
    line_of(e.cycle, t_s, &e.kind, &e.axis, &e.detail)
}

fn line_of(cycle: u64, t_s: f64, kind: &str, axis: &str, detail: &str) -> String {
    let mut s = format!("cycle {cycle:>8} ({t_s:>9.3} s): {kind}");
    if !axis.is_empty() {
        let _ = write!(s, " [{axis}]");
    }
    if !detail.is_empty() {
        let _ = write!(s, ": {detail}");
    }
    s
}
