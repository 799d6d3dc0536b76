//! The recorder thread: drains cycle, axis and event records from the hand-off queues and writes
//! them to a chunked, compressed, indexed MCAP file. It never runs on the RT thread.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

use mcap::records::MessageHeader;
use prost::Message;
use serde::Serialize;

use super::capture::Capturer;
pub use super::describe::describe_event;
use super::proto;
pub use super::sink::{channel_ids, channel_specs, ChannelSpec, RecorderError};
use super::sink::{open, template_channels, Channels, Sink};
use crate::handoff::{AxisRecord, CycleRecord, EventKind, EventRecord, HostEnd, NO_AXIS};
use crate::host::faults::{DriveFault, MAX_DRIVE_FAULTS};
use crate::host::je_c::{stopped_text, JecAxes};
use crate::host::live::LiveFeed;
use crate::rt::clock::realtime_offset_ns;
use crate::rt::executive::fsa_index;
use cellrt_config::capture::Quantity;
use cellrt_config::CellConfig;

/// Chunks one file holds at most before the recording rotates to its next part: the MCAP
/// writer keeps an index entry of every chunk (about 50 bytes per channel) in memory for the
/// file's summary, so an endless file would grow the recorder without bound. At the default
/// `flush_ms` of 200 a file spans about 7 minutes; with 16 axes its index holds about 2 MiB.
pub const MAX_CHUNKS_PER_FILE: u64 = 2048;

/// Event lines the run's summary keeps (the first ones, about 1 MiB): `events` counts every
/// event and the recording holds them all.
pub const EVENT_LOG_LINES: usize = 10_000;

/// What was recorded.
#[derive(Debug, Clone, Default, Serialize)]
pub struct RecordingInfo {
    /// The (first) MCAP file, if recording was on.
    pub path: Option<PathBuf>,
    /// Every file written, in order (more than one when the recording rotated).
    pub files: Vec<PathBuf>,
    /// Size of all files, bytes.
    pub bytes: u64,
    /// Cycle messages written.
    pub cycle_messages: u64,
    /// Axis messages written.
    pub axis_messages: u64,
    /// MR-JE-C exchange messages written (topics `/je_c/<name>`).
    pub je_c_messages: u64,
    /// Events seen (recorded or not).
    pub events: u64,
    /// The first [`EVENT_LOG_LINES`] events, as text lines `cycle N: kind [axis]: detail`.
    pub event_log: Vec<String>,
    /// Why and where the recording stopped before the run ended (a full disk, an I/O error):
    /// the cell went on without it; the file holds the records up to its last closed chunk.
    pub stopped: Option<String>,
    /// The RT loop's drive faults in words (the first [`MAX_DRIVE_FAULTS`]; the summary
    /// carries them).
    #[serde(skip)]
    pub drive_faults: Vec<DriveFault>,
    /// The index in `drive_faults` of the first fault after the last `reset` command: the
    /// faults from there on are the ones the cell still stands faulted by.
    #[serde(skip)]
    pub unreset_from: usize,
}

/// Handle of the running recorder thread.
pub struct Recorder {
    stop: Arc<AtomicBool>,
    handle: JoinHandle<Result<RecordingInfo, RecorderError>>,
    je_c: Arc<std::sync::OnceLock<JecAxes>>,
}

/// Path of part `n` of a rotating recording: `run.mcap`, `run.1.mcap`, `run.2.mcap`, …
pub fn part_path(first: &Path, n: u32) -> PathBuf {
    if n == 0 {
        return first.to_path_buf();
    }
    let stem = first
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "recording".into());
    let ext = first
        .extension()
        .map(|e| e.to_string_lossy().into_owned())
        .unwrap_or_else(|| "mcap".into());
    first.with_file_name(format!("{stem}.{n}.{ext}"))
}

impl Recorder {
    /// Opens `path` (if any) and starts draining `handoff`. Without a path the thread still
    /// drains events (for the summary and the log) and whatever per-cycle records come.
    pub fn start(
        cell: &CellConfig,
        path: Option<&Path>,
        handoff: Arc<HostEnd>,
    ) -> Result<Recorder, RecorderError> {
        Recorder::start_with_live(cell, path, handoff, None)
    }

    /// [`Recorder::start`], also offering every encoded record to the live view `live` —
    /// whether a file is written, rotated, between triggers or off (the hand-off must then be
    /// built with [`crate::handoff::PerCycleRecords::Taken`], see `PerCycleRecords::for_run`).
    pub fn start_with_live(
        cell: &CellConfig,
        path: Option<&Path>,
        handoff: Arc<HostEnd>,
        live: Option<LiveFeed>,
    ) -> Result<Recorder, RecorderError> {
        let live = match live {
            Some(feed) => {
                let channels = template_channels(cell).map_err(|source| RecorderError::Mcap {
                    path: PathBuf::new(),
                    source,
                })?;
                Some((feed, channels))
            }
            None => None,
        };
        let (sink, capture) = match (path, &cell.recording.capture) {
            (Some(p), Some(c)) => {
                let channels = template_channels(cell).map_err(|source| RecorderError::Mcap {
                    path: p.to_path_buf(),
                    source,
                })?;
                handoff.arm_capture();
                (None, Some(Capturer::new(cell, c.clone(), p, channels)))
            }
            (Some(p), None) => (Some(open(cell, p)?), None),
            (None, _) => (None, None),
        };
        let stop = Arc::new(AtomicBool::new(false));
        let stop2 = stop.clone();
        let cell = cell.clone();
        let je_c = Arc::new(std::sync::OnceLock::new());
        let je_c2 = je_c.clone();
        let handle = std::thread::Builder::new()
            .name("cellrt-recorder".into())
            .spawn(move || {
                let sources = Sources {
                    handoff: &handoff,
                    je_c: &je_c2,
                };
                drain_loop(&cell, sink, capture, live, sources, &stop2)
            })
            .map_err(|e| RecorderError::Create {
                path: path.map(Path::to_path_buf).unwrap_or_default(),
                source: e,
            })?;
        Ok(Recorder { stop, handle, je_c })
    }

    /// Records the exchanges of the cell's MR-JE-C axes from now on (topics `/je_c/<name>`).
    pub fn attach_je_c(&self, axes: JecAxes) {
        let _ = self.je_c.set(axes);
    }

    /// Drains what is left, finishes the file (summary, indexes) and returns what was written.
    pub fn finish(self) -> Result<RecordingInfo, RecorderError> {
        self.stop.store(true, Ordering::Release);
        self.handle.join().map_err(|_| RecorderError::Thread)?
    }
}

struct Drain<'a> {
    cell: &'a CellConfig,
    sink: Option<Sink>,
    /// Triggered capture instead of `sink`.
    capture: Option<Capturer>,
    /// The live view's feed and the channel ids it knows the records by.
    live: Option<(LiveFeed, Channels)>,
    /// Part number of the open file (rotation).
    part: u32,
    /// Records popped ahead of their cycle record.
    pending_axis: Option<AxisRecord>,
    pending_event: Option<EventRecord>,
    offset: i128,
    seq: u32,
    buf: Vec<u8>,
    info: RecordingInfo,
    /// Monotonic deadline of each recent cycle, to time-stamp axis records and events.
    last_deadline: u64,
    last_cycle: u64,
}

/// Where the recorder's records come from: the RT thread's hand-off, and the MR-JE-C axes'
/// threads once attached.
struct Sources<'a> {
    handoff: &'a HostEnd,
    je_c: &'a std::sync::OnceLock<JecAxes>,
}

fn drain_loop(
    cell: &CellConfig,
    sink: Option<Sink>,
    capture: Option<Capturer>,
    live: Option<(LiveFeed, Channels)>,
    sources: Sources<'_>,
    stop: &AtomicBool,
) -> Result<RecordingInfo, RecorderError> {
    let handoff = sources.handoff;
    let mut d = Drain {
        cell,
        sink,
        capture,
        live,
        part: 0,
        pending_axis: None,
        pending_event: None,
        offset: realtime_offset_ns(),
        seq: 0,
        buf: Vec::with_capacity(512),
        info: RecordingInfo::default(),
        last_deadline: 0,
        last_cycle: 0,
    };
    let period = cell.cycle_time.as_nanos();
    let flush_every = Duration::from_millis(cell.recording.flush_ms);
    loop {
        let finishing = stop.load(Ordering::Acquire);
        let mut n = 0usize;
        if handoff.take_capture_request() {
            if let Some(c) = d.capture.as_mut() {
                c.fire(format!("cycle {}: operator request", d.last_cycle));
            }
        }
        // Cycle by cycle: the cycle record (it carries the deadline that time-stamps the rest),
        // then that cycle's axis records (pushed before it) and events, so a file rotates at a
        // cycle boundary and messages are in time order.
        while let Some(c) = handoff.pop_cycle() {
            d.rotate_if_due(&c)?;
            d.cycle(&c, period)?;
            n += 1;
            while let Some(a) = d.pending_axis.take().or_else(|| handoff.pop_axis()) {
                if a.cycle > c.cycle {
                    d.pending_axis = Some(a);
                    break;
                }
                d.axis(&a, period)?;
                n += 1;
            }
            while let Some(e) = d.pending_event.take().or_else(|| handoff.pop_event()) {
                if e.cycle > c.cycle {
                    d.pending_event = Some(e);
                    break;
                }
                handoff.remember_event(&d.event(&e, period)?);
                n += 1;
            }
            d.flush_if_due(flush_every)?;
        }
        if let Some(je_c) = sources.je_c.get() {
            n += d.je_c_exchanges(je_c)?;
        }
        // Without a file (or at the end) nothing waits for its cycle record.
        if (d.sink.is_none() && d.capture.is_none() && d.live.is_none()) || finishing {
            while let Some(a) = d.pending_axis.take().or_else(|| handoff.pop_axis()) {
                d.axis(&a, period)?;
                n += 1;
            }
            while let Some(e) = d.pending_event.take().or_else(|| handoff.pop_event()) {
                handoff.remember_event(&d.event(&e, period)?);
                n += 1;
            }
        }
        if finishing && n == 0 {
            break;
        }
        d.flush_if_due(flush_every)?;
        if n == 0 {
            std::thread::sleep(Duration::from_millis(2));
        }
    }
    if let Some(sink) = d.sink.take() {
        d.close(sink)?;
    }
    d.finish_capture();
    Ok(d.info)
}

impl Drain<'_> {
    /// Finishes `sink` and adds it to the files written.
    fn close(&mut self, sink: Sink) -> Result<(), RecorderError> {
        let (path, bytes) = sink.finish()?;
        self.info.bytes += bytes;
        if self.info.path.is_none() {
            self.info.path = Some(path.clone());
        }
        self.info.files.push(path);
        Ok(())
    }

    fn flush_if_due(&mut self, every: Duration) -> Result<(), RecorderError> {
        let flushed = match self.sink.as_mut() {
            Some(sink) if sink.last_flush.elapsed() >= every => sink.flush(),
            _ => Ok(()),
        };
        if let Err(e) = flushed {
            self.stop_recording(e);
        }
        Ok(())
    }

    /// Starts the next file before cycle `c` when the open one is over its size, its duration
    /// or [`MAX_CHUNKS_PER_FILE`].
    fn rotate_if_due(&mut self, c: &CycleRecord) -> Result<(), RecorderError> {
        let rec = &self.cell.recording;
        let Some(sink) = self.sink.as_mut() else {
            return Ok(());
        };
        let first = *sink.first_deadline.get_or_insert(c.deadline_ns);
        let by_size = rec.rotate_bytes.is_some_and(|b| sink.writer_len() >= b);
        let by_time = rec
            .rotate_seconds
            .is_some_and(|s| c.deadline_ns.saturating_sub(first) as f64 >= s * 1e9);
        let by_chunks = sink.chunks >= MAX_CHUNKS_PER_FILE;
        if !(by_size || by_time || by_chunks) {
            return Ok(());
        }
        let first_path = self.info.path.clone().unwrap_or_else(|| sink.path.clone());
        let old = self.sink.take().expect("checked above");
        self.part += 1;
        let next = self
            .close(old)
            .and_then(|()| open(self.cell, &part_path(&first_path, self.part)));
        match next {
            Ok(mut next) => {
                next.first_deadline = Some(c.deadline_ns);
                self.sink = Some(next);
            }
            Err(e) => self.stop_recording(e),
        }
        Ok(())
    }

    fn time_of(&self, cycle: u64, period: u64) -> u64 {
        // Deadline of `cycle`, extrapolated from the latest cycle record.
        let mono =
            self.last_deadline as i128 + (cycle as i128 - self.last_cycle as i128) * period as i128;
        (mono + self.offset).max(0) as u64
    }

    /// The channel ids messages are encoded for: the open file's, or the capture's.
    fn channels(&self) -> Option<&Channels> {
        self.sink
            .as_ref()
            .map(|s| &s.channels)
            .or(self.capture.as_ref().map(|c| &c.channels))
            .or(self.live.as_ref().map(|(_, c)| c))
    }

    /// The open capture's end and the captures written, into the run's recording info.
    fn finish_capture(&mut self) {
        let Some(mut c) = self.capture.take() else {
            return;
        };
        if let Err(e) = c.finish(self.cell, self.last_cycle) {
            self.info.stopped = Some(format!("capture at cycle {}: {e}", self.last_cycle));
        }
        for f in c.files {
            self.info.bytes += std::fs::metadata(&f).map_or(0, |m| m.len());
            self.info.path.get_or_insert_with(|| f.clone());
            self.info.files.push(f);
        }
    }

    fn write(&mut self, channel: u16, log_time: u64) -> Result<(), RecorderError> {
        if let Some((feed, _)) = &self.live {
            feed.offer(channel, log_time, &self.buf);
        }
        if let Some(c) = self.capture.as_mut() {
            if let Err(e) = c.record(channel, log_time, self.last_cycle, &self.buf) {
                // A capture that cannot be written ends the captures, not the cell.
                tracing::error!("capture stopped at cycle {}: {e}", self.last_cycle);
                self.finish_capture();
                self.info.stopped = Some(format!("capture at cycle {}: {e}", self.last_cycle));
            }
            return Ok(());
        }
        let Some(sink) = self.sink.as_mut() else {
            return Ok(());
        };
        self.seq = self.seq.wrapping_add(1);
        sink.count_message(self.buf.len());
        let written = sink
            .writer
            .write_to_known_channel(
                &MessageHeader {
                    channel_id: channel,
                    sequence: self.seq,
                    log_time,
                    publish_time: log_time,
                },
                &self.buf,
            )
            .map_err(|source| RecorderError::Mcap {
                path: sink.path.clone(),
                source,
            });
        if let Err(e) = written {
            self.stop_recording(e);
        }
        Ok(())
    }

    /// Stops recording after `e` (a full disk, an I/O error): the file is finished if it still
    /// can be, the loss goes into the summary, and the cell goes on without a recording.
    fn stop_recording(&mut self, e: RecorderError) {
        let mut why = e.to_string();
        let mut source = std::error::Error::source(&e);
        while let Some(s) = source {
            let text = s.to_string();
            if !why.contains(&text) {
                why = format!("{why}: {text}");
            }
            source = s.source();
        }
        let at = format!("at cycle {}: {why}", self.last_cycle);
        tracing::error!("recording stopped {at}; the cell goes on without it");
        self.info.stopped = Some(at);
        let Some(sink) = self.sink.take() else {
            return;
        };
        let path = sink.path.clone();
        if self.close(sink).is_err() {
            self.info.bytes += std::fs::metadata(&path).map_or(0, |m| m.len());
            self.info.path.get_or_insert_with(|| path.clone());
            self.info.files.push(path);
        }
    }

    fn cycle(&mut self, c: &CycleRecord, period: u64) -> Result<(), RecorderError> {
        self.last_deadline = c.deadline_ns;
        self.last_cycle = c.cycle;
        if let Some(capture) = self.capture.as_mut() {
            if let Err(e) = capture.cycle(self.cell, c.cycle) {
                tracing::error!("capture stopped at cycle {}: {e}", c.cycle);
                self.finish_capture();
                self.info.stopped = Some(format!("capture at cycle {}: {e}", c.cycle));
            }
        }
        let Some(channel) = self.channels().map(|ch| ch.cycle) else {
            return Ok(());
        };
        let msg = proto::CycleStats {
            cycle: c.cycle,
            deadline_ns: c.deadline_ns,
            wakeup_latency_ns: c.wakeup_latency_ns,
            loop_time_ns: c.loop_time_ns,
            overruns: c.overruns,
            cell_state: c.cell_state as i32,
            dropped_records: c.dropped_records,
            dc_phase_error_ns: c.dc_phase_error_ns,
        };
        self.buf.clear();
        msg.encode(&mut self.buf).expect("Vec grows");
        let t = self.time_of(c.cycle, period);
        self.write(channel, t)?;
        self.info.cycle_messages += 1;
        Ok(())
    }

    fn axis(&mut self, a: &AxisRecord, period: u64) -> Result<(), RecorderError> {
        let Some(channel) = self
            .channels()
            .and_then(|ch| ch.axes.get(a.axis as usize).copied())
        else {
            return Ok(());
        };
        let axis = &self.cell.axes.on_loop()[a.axis as usize];
        let s = axis.scaling;
        let msg = proto::AxisCycle {
            cycle: a.cycle,
            setpoint_position: s.to_units(a.setpoint),
            setpoint_velocity: s.to_units(a.setpoint_velocity),
            actual_position: s.to_units(f64::from(a.position_actual)),
            actual_velocity: s.to_units(axis.drive_units.velocity_from_drive(a.velocity_actual)),
            following_error: s.to_units(f64::from(a.following_error)),
            setpoint_counts: a.target_position,
            actual_position_counts: a.position_actual,
            actual_velocity_counts: a.velocity_actual,
            following_error_counts: a.following_error,
            controlword: u32::from(a.controlword),
            statusword: u32::from(a.statusword),
            fsa_state: a.fsa_state.map(fsa_index).unwrap_or(0) as i32,
            mode_display: i32::from(a.mode_display),
            error_code: u32::from(a.error_code),
            setpoint_torque: i32::from(a.target_torque),
            actual_torque: i32::from(a.torque_actual),
            // The drive profiles map no incremental counter yet.
            counter_sent: u32::from(a.counter_sent),
            counter_received: u32::from(a.counter_received),
            mode: i32::from(a.mode),
            setpoint_velocity_counts: a.target_velocity,
            status_do_1: u32::from(a.status_do[0]),
            status_do_2: u32::from(a.status_do[1]),
            status_do_3: u32::from(a.status_do[2]),
            controlword2: u32::from(a.controlword2),
            profile_velocity: a.profile[0],
            profile_acceleration: a.profile[1],
            profile_deceleration: a.profile[2],
            torque_slope: a.profile[3],
        };
        if let Some(c) = self.capture.as_mut() {
            c.on_axis(a.axis as usize, a.cycle, |q| match q {
                Quantity::FollowingError => msg.following_error,
                Quantity::ActualPosition => msg.actual_position,
                Quantity::ActualVelocity => msg.actual_velocity,
                Quantity::SetpointPosition => msg.setpoint_position,
                Quantity::SetpointVelocity => msg.setpoint_velocity,
            });
        }
        self.buf.clear();
        msg.encode(&mut self.buf).expect("Vec grows");
        let t = self.time_of(a.cycle, period);
        self.write(channel, t)?;
        self.info.axis_messages += 1;
        Ok(())
    }

    /// Records the MR-JE-C axes' exchanges taken since the last call; how many.
    fn je_c_exchanges(&mut self, je_c: &JecAxes) -> Result<usize, RecorderError> {
        let mut n = 0;
        for k in 0..je_c.len() {
            let Some(channel) = self.channels().and_then(|c| c.je_c.get(k).copied()) else {
                while je_c.pop_record(k).is_some() {}
                continue;
            };
            let c = je_c.config(k);
            while let Some(r) = je_c.pop_record(k) {
                let msg = proto::JecExchange {
                    exchange: r.exchange,
                    answered: r.answered,
                    statusword: u32::from(r.inputs.statusword),
                    position_counts: r.inputs.position,
                    position: c.units(r.inputs.position),
                    velocity_drive: r.inputs.velocity,
                    alarm: u32::from(r.inputs.alarm),
                    controlword: u32::from(r.controlword),
                    round_trip_ns: r.round_trip_ns,
                    missed_in_row: r.missed_in_row,
                    missed: r.missed,
                    refused: r.refused,
                    stopped: r.stopped.map(stopped_text).unwrap_or_default(),
                };
                self.buf.clear();
                msg.encode(&mut self.buf).expect("Vec grows");
                self.write(channel, r.time_ns)?;
                self.info.je_c_messages += 1;
                n += 1;
            }
        }
        Ok(n)
    }

    /// Logs and records event `e`; returns its line (for the operator's recent events).
    fn event(&mut self, e: &EventRecord, period: u64) -> Result<String, RecorderError> {
        let config = (e.axis != NO_AXIS)
            .then(|| self.cell.axes.on_loop().get(e.axis as usize))
            .flatten();
        let axis = match config {
            Some(a) => a.name.clone(),
            None if e.axis == NO_AXIS => String::new(),
            None => format!("#{}", e.axis),
        };
        let profile = config.map(|a| &*a.profile);
        let detail = describe_event(e, profile);
        if e.kind == EventKind::Command
            && crate::handoff::CellCommand::from_code(e.value)
                == Some(crate::handoff::CellCommand::Reset)
        {
            self.info.unreset_from = self.info.drive_faults.len();
        }
        if e.kind == EventKind::DriveFault && self.info.drive_faults.len() < MAX_DRIVE_FAULTS {
            let text = profile
                .filter(|_| e.value >= 0)
                .map(|p| p.alarm_text(e.value as u16));
            self.info
                .drive_faults
                .push(DriveFault::new(&axis, Some(e.cycle), text));
        }
        let line = format!(
            "cycle {}: {}{}{}",
            e.cycle,
            e.kind.as_str(),
            if axis.is_empty() {
                String::new()
            } else {
                format!(" [{axis}]")
            },
            if detail.is_empty() {
                String::new()
            } else {
                format!(": {detail}")
            }
        );
        match e.kind {
            EventKind::Underrun
            | EventKind::SetpointRejected
            | EventKind::DriveFault
            | EventKind::MasterTimeout
            | EventKind::BusError
            | EventKind::CommandRefused
            | EventKind::PlannerLost
            | EventKind::CommunicationError
            | EventKind::AlStatus
            | EventKind::Emergency
            | EventKind::MailboxDiscarded
            | EventKind::BringUpWarning
            | EventKind::RecordsDropped => tracing::warn!(
                cell = %self.cell.name,
                axis = %axis,
                event = e.kind.as_str(),
                cycle = e.cycle,
                "{line}"
            ),
            _ => tracing::debug!(
                cell = %self.cell.name,
                axis = %axis,
                event = e.kind.as_str(),
                cycle = e.cycle,
                "{line}"
            ),
        }
        self.info.events += 1;
        if self.info.event_log.len() < EVENT_LOG_LINES {
            self.info.event_log.push(line.clone());
        }
        if let Some(c) = self.capture.as_mut() {
            c.on_event(e.kind, &line);
        }
        let Some(channel) = self.channels().map(|ch| ch.events) else {
            return Ok(line);
        };
        let msg = proto::Event {
            cycle: e.cycle,
            kind: e.kind.as_str().to_string(),
            axis,
            detail,
            value: e.value,
        };
        self.buf.clear();
        msg.encode(&mut self.buf).expect("Vec grows");
        let t = self.time_of(e.cycle, period);
        self.write(channel, t)?;
        Ok(line)
    }
}
