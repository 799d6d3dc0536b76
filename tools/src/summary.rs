//! The human-readable run summary.

use std::fmt::Write;

use cellrt_runtime::host::controller::{FailedStep, Outcome, Summary};

/// Renders the summary printed at exit.
pub fn render(s: &Summary) -> String {
    let mut o = String::new();
    let outcome = match s.outcome {
        Outcome::ProgramCompleted => "program completed",
        Outcome::ProgramFailed => "program FAILED",
        Outcome::DurationElapsed => "duration elapsed",
        Outcome::Interrupted => "interrupted (clean shutdown)",
    };
    let _ = writeln!(o, "\n== cellrt summary: cell '{}' — {outcome}", s.cell);
    if let Some(f) = &s.failed_step {
        failure(&mut o, f);
    }
    if let Some(e) = &s.program_error {
        let _ = writeln!(o, "   error: {e}");
    }
    let _ = writeln!(
        o,
        "cycles      {} at {} µs ({:.1} s), final state {}",
        s.counters.cycles,
        s.cycle_time_us,
        s.counters.cycles as f64 * f64::from(s.cycle_time_us) / 1e6,
        s.final_state
    );
    let _ = writeln!(
        o,
        "rt          {}{}",
        s.rt.describe(),
        if s.rt.refused.is_empty() {
            ""
        } else {
            " (best effort: see warnings)"
        }
    );
    let _ = writeln!(o, "privileges  {}", s.privileges.describe());
    let _ = writeln!(
        o,
        "overruns    {}   underruns {}   rejected setpoints {}   faults {}   dropped records {}",
        s.counters.overruns,
        s.counters.underruns,
        s.counters.rejected_setpoints,
        s.counters.faults,
        s.counters.dropped_records
    );
    let shown = s.failed_step.as_ref().map_or(0, |f| f.faults.len());
    if shown == 0 {
        for d in &s.drive_faults {
            let _ = writeln!(o, "drive fault {d}");
        }
    }
    let l = &s.wakeup_latency;
    let _ = writeln!(
        o,
        "wakeup      p50 {:.1} µs   p99 {:.1} µs   p99.9 {:.1} µs   max {:.1} µs",
        l.p50_us, l.p99_us, l.p999_us, l.max_us
    );
    let t = &s.loop_time;
    let _ = writeln!(
        o,
        "loop time   p50 {:.1} µs   p99 {:.1} µs   max {:.1} µs",
        t.p50_us, t.p99_us, t.max_us
    );
    let x = &s.exchange_time;
    let _ = writeln!(
        o,
        "exchange    p50 {:.1} µs   p99 {:.1} µs   max {:.1} µs",
        x.p50_us, x.p99_us, x.max_us
    );
    if let Some(f) = &s.frames {
        let _ = writeln!(
            o,
            "frames      {} sent   {} lost   {} working-counter errors",
            f.frames, f.lost, f.wkc_errors
        );
    }
    if let Some(d) = &s.dc_phase_error {
        let _ = writeln!(
            o,
            "dc phase    |error| p50 {:.1} µs   p99 {:.1} µs   max {:.1} µs (frame vs its place in the SYNC0 cycle)",
            d.p50_us, d.p99_us, d.max_us
        );
    }
    axes(&mut o, s);
    recording(&mut o, s);
    if let Some(l) = &s.live {
        let _ = writeln!(
            o,
            "live view   ws://{}: {} messages sent, {} dropped before the server",
            l.address, l.messages_sent, l.messages_dropped
        );
        if let Some(page) = &l.page {
            let _ = writeln!(o, "live page   {page}");
        }
    }
    o
}

/// The step a failed program stopped at and, where drive faults stopped it, each faulted axis
/// with the alarm's manual number, name, cause and remedy.
fn failure(o: &mut String, f: &FailedStep) {
    let at = format!("step {} ({})", f.step, f.what);
    match f.faults.as_slice() {
        [] => {
            let _ = writeln!(o, "   failed at {at}");
        }
        faults => {
            let _ = writeln!(o, "   failed at {at}: drive fault");
            for d in faults {
                let _ = writeln!(o, "     {d}");
                if let Some(c) = d.cause {
                    let _ = writeln!(o, "       cause:  {c}");
                }
                if let Some(r) = d.remedy {
                    let _ = writeln!(o, "       remedy: {r}");
                }
            }
        }
    }
}

/// Each axis' final position against its target (only the positions where a drive fault
/// stopped the program: its final targets were never run to); for an axis driven over an
/// MR-JE-C link, the link's figures below it.
fn axes(o: &mut String, s: &Summary) {
    let stopped_at = s
        .failed_step
        .as_ref()
        .filter(|f| !f.faults.is_empty())
        .map(|f| format!("step {} ({})", f.step, f.what));
    match &stopped_at {
        None => {
            let _ = writeln!(o, "axes        final position vs target");
        }
        Some(at) => {
            let _ = writeln!(
                o,
                "axes        final position (a drive fault stopped the program at {at}: its final targets were not run to)"
            );
        }
    }
    for a in &s.axes {
        let target = match (a.target, a.error, &stopped_at) {
            (_, _, Some(_)) => String::new(),
            (Some(t), Some(e), None) => format!("target {t:>12.4}   error {e:+.4}"),
            _ => "(no target)".to_string(),
        };
        let line = format!(
            "  {:<8} {:>12.4} {:<4} {target}",
            a.name, a.final_position, a.unit
        );
        let _ = writeln!(o, "{}", line.trim_end());
        if let Some(l) = &a.link {
            let _ = writeln!(
                o,
                "           {} over {}: {} exchanges, {} missed, {} refused, round trip max {:.0} µs{}{}",
                a.backend,
                l.transport,
                l.exchanges,
                l.missed,
                l.refused,
                l.max_round_trip_us,
                l.stopped
                    .as_ref()
                    .map(|r| format!(", stopped: {r}"))
                    .unwrap_or_default(),
                l.drive_alarm
                    .as_ref()
                    .map(|r| format!(", drive alarm {r}"))
                    .unwrap_or_default()
            );
        }
    }
}

/// Where the recording went, its size and what happened to it.
fn recording(o: &mut String, s: &Summary) {
    match &s.recording.path {
        Some(p) => {
            let _ = writeln!(
                o,
                "recording   {} ({:.1} MiB, {} cycle and {} axis messages, {}{} events)",
                p.display(),
                s.recording.bytes as f64 / (1024.0 * 1024.0),
                s.recording.cycle_messages,
                s.recording.axis_messages,
                if s.recording.je_c_messages > 0 {
                    format!("{} MR-JE-C exchange messages, ", s.recording.je_c_messages)
                } else {
                    String::new()
                },
                s.recording.events
            );
            if s.recording.files.len() > 1 {
                let _ = writeln!(
                    o,
                    "            rotated into {} files: {} … {}",
                    s.recording.files.len(),
                    s.recording.files[0].display(),
                    s.recording.files[s.recording.files.len() - 1].display()
                );
            }
            if let Some(why) = &s.recording.stopped {
                let _ = writeln!(
                    o,
                    "            STOPPED {why}; the cell went on without it (the file holds the \
                     records up to its last closed chunk: `cellrt recover` completes it)"
                );
            }
        }
        None => {
            let _ = writeln!(o, "recording   off ({} events seen)", s.recording.events);
        }
    }
}
