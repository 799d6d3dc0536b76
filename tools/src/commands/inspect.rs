//! `cellrt inspect FILE.mcap`: what a recording holds, from its summary and indexes where it
//! has them: cell, axes, channels and counts, timing percentiles, events and faults.

use std::fmt::Write as _;
use std::time::Instant;

use cellrt_runtime::rt::histogram::NsHistogram;

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
    print!("{}", render(&file, &cell, &recs));
    if args.timing {
        eprintln!("inspect took {:.3} s", started.elapsed().as_secs_f64());
    }
    Exit::Ok
}

/// Seconds from the first recorded cycle to `cycle`.
fn t_of(cycle: u64, first: u64, period_us: u64) -> f64 {
    (cycle as f64 - first as f64) * period_us as f64 / 1e6
}

fn render(file: &RecFile, cell: &CellInfo, recs: &Records) -> String {
    let mut o = String::new();
    let mib = file.bytes.len() as f64 / (1024.0 * 1024.0);
    let _ = writeln!(
        o,
        "file        {} ({mib:.1} MiB, {})",
        file.path.display(),
        match (&recs.truncated, file.indexed()) {
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
        cell.name,
        cell.cycle_time_us,
        cell.cell_axes.len(),
        cell.axes.len(),
        cell.software
    );
    let _ = writeln!(o, "axes");
    for (a, d) in &cell.cell_axes {
        let _ = writeln!(o, "  {a:<8} {d}");
    }
    let period = cell.cycle_time_us.max(1);
    let (first, last) = match (recs.cycles.first(), recs.cycles.last()) {
        (Some(f), Some(l)) => (f.cycle, l.cycle),
        _ => (0, 0),
    };
    if recs.cycles.is_empty() {
        let _ = writeln!(o, "duration    no cycles recorded");
    } else {
        let span = last - first + 1;
        let _ = writeln!(
            o,
            "duration    {:.3} s: cycles {first}..={last}, {} recorded, {} skipped",
            span as f64 * period as f64 / 1e6,
            recs.cycles.len(),
            span.saturating_sub(recs.cycles.len() as u64)
        );
    }
    let _ = writeln!(
        o,
        "channels    topic                schema               messages"
    );
    for c in file.channel_counts() {
        let _ = writeln!(o, "  {:<26} {:<20} {:>9}", c.topic, c.schema, c.count);
    }
    let lastc = recs.cycles.last();
    let dropped_events = recs
        .events
        .iter()
        .filter(|e| e.kind == "records_dropped")
        .count();
    let _ = writeln!(
        o,
        "overruns    {}   dropped records {} ({} records_dropped events)",
        lastc.map(|c| c.overruns).unwrap_or(0),
        lastc.map(|c| c.dropped_records).unwrap_or(0),
        dropped_events
    );
    let mut wake = NsHistogram::new();
    let mut looptime = NsHistogram::new();
    for c in &recs.cycles {
        wake.record(u64::from(c.wakeup_latency_ns));
        looptime.record(u64::from(c.loop_time_ns));
    }
    let w = wake.percentiles();
    let l = looptime.percentiles();
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
    let _ = writeln!(o, "events      {}", recs.events.len());
    for e in &recs.events {
        let _ = writeln!(o, "  {}", event_line(e, first, period));
    }
    let faults: Vec<_> = recs
        .events
        .iter()
        .filter(|e| FAULT_KINDS.contains(&e.kind.as_str()))
        .collect();
    if faults.is_empty() {
        let _ = writeln!(o, "faults      none");
    } else {
        let _ = writeln!(o, "faults      {}", faults.len());
        for e in faults {
            let _ = writeln!(o, "  {}", event_line(e, first, period));
        }
    }
    o
}

/// `cycle N (t s): kind [axis]: detail`.
pub fn event_line(
    e: &cellrt_runtime::host::record::proto::Event,
    first_cycle: u64,
    period_us: u64,
) -> String {
    let mut s = format!(
        "cycle {:>8} ({:>9.3} s): {}",
        e.cycle,
        t_of(e.cycle, first_cycle, period_us),
        e.kind
    );
    if !e.axis.is_empty() {
        let _ = write!(s, " [{}]", e.axis);
    }
    if !e.detail.is_empty() {
        let _ = write!(s, ": {}", e.detail);
    }
    s
}
