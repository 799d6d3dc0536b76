//! Triggered capture in the recorder (`[recording] mode = "triggered"`): the encoded messages of
//! the last `pre_s` seconds are kept in a ring; a trigger (an event kind, an axis threshold, or
//! `cellrt capture`) opens one complete MCAP file — the cell's schemas, channels and metadata,
//! then the ring — which takes every message for `post_s` seconds more and is then finished.
//! A trigger while a capture is open is part of it (noted, not a new file). Message buffers are
//! reused as the ring turns.

use std::collections::VecDeque;
use std::path::{Path, PathBuf};

use mcap::records::{MessageHeader, Metadata};

use super::sink::{open, Channels, RecorderError, Sink};
use crate::handoff::EventKind;
use cellrt_config::capture::{CaptureConfig, Quantity, Trigger};
use cellrt_config::CellConfig;

/// One encoded message.
struct Stored {
    channel: u16,
    log_time: u64,
    cycle: u64,
    data: Vec<u8>,
}

/// A capture file being written.
struct Open {
    sink: Sink,
    /// The last cycle it takes.
    until_cycle: u64,
    /// Why it was opened, and further triggers met while it was open.
    triggers: Vec<String>,
}

/// The ring, the triggers and the capture being written.
pub(super) struct Capturer {
    config: CaptureConfig,
    /// Where capture `n` goes: `<base stem>-capture-<n>.<ext>`.
    base: PathBuf,
    pub(super) channels: Channels,
    pre_cycles: u64,
    post_cycles: u64,
    ring: VecDeque<Stored>,
    spare: Vec<Vec<u8>>,
    open: Option<Open>,
    /// A trigger met (why), to act on at the next cycle.
    fired: Option<String>,
    /// Per trigger: whether its threshold held at the last sample (a threshold triggers when
    /// it starts to hold, not while it does).
    holding: Vec<bool>,
    seq: u32,
    made: u32,
    /// Finished capture files.
    pub(super) files: Vec<PathBuf>,
}

/// Path of capture `n` beside `base`.
pub fn capture_path(base: &Path, n: u32) -> PathBuf {
    let stem = base
        .file_stem()
        .map_or_else(|| "recording".into(), |s| s.to_string_lossy().into_owned());
    let ext = base
        .extension()
        .map_or_else(|| "mcap".into(), |e| e.to_string_lossy().into_owned());
    base.with_file_name(format!("{stem}-capture-{n}.{ext}"))
}

impl Capturer {
    /// A capturer for `cell` whose files go beside `base`; `channels` are the ids every file
    /// of the cell gets.
    pub(super) fn new(
        cell: &CellConfig,
        config: CaptureConfig,
        base: &Path,
        channels: Channels,
    ) -> Capturer {
        let per_s = 1e9 / cell.cycle_time.as_nanos() as f64;
        let holding = vec![false; config.triggers.len()];
        Capturer {
            holding,
            pre_cycles: (config.pre_s * per_s).ceil() as u64,
            post_cycles: (config.post_s * per_s).ceil() as u64,
            config,
            base: base.to_path_buf(),
            channels,
            ring: VecDeque::new(),
            spare: Vec::new(),
            open: None,
            fired: None,
            seq: 0,
            made: 0,
            files: Vec::new(),
        }
    }

    /// Keeps the message in the ring and writes it to the open capture.
    pub(super) fn record(
        &mut self,
        channel: u16,
        log_time: u64,
        cycle: u64,
        data: &[u8],
    ) -> Result<(), RecorderError> {
        if let Some(o) = self.open.as_mut() {
            self.seq = self.seq.wrapping_add(1);
            write(&mut o.sink, channel, log_time, self.seq, data)?;
        }
        let mut buf = self.spare.pop().unwrap_or_default();
        buf.clear();
        buf.extend_from_slice(data);
        self.ring.push_back(Stored {
            channel,
            log_time,
            cycle,
            data: buf,
        });
        Ok(())
    }

    /// An event: a trigger when its kind is one.
    pub(super) fn on_event(&mut self, kind: EventKind, line: &str) {
        if self.config.triggers.contains(&Trigger::Event(kind)) {
            self.fire(line.to_string());
        }
    }

    /// An axis' quantities this cycle: a trigger when one starts to cross its threshold.
    pub(super) fn on_axis(&mut self, axis: usize, cycle: u64, value: impl Fn(Quantity) -> f64) {
        let mut hit = None;
        for (t, holding) in self.config.triggers.iter().zip(self.holding.iter_mut()) {
            let Trigger::Threshold {
                axis: a,
                quantity,
                comparison,
                value: limit,
            } = *t
            else {
                continue;
            };
            if a != axis {
                continue;
            }
            let x = value(quantity);
            let holds = comparison.holds(x, limit);
            if holds && !*holding && hit.is_none() {
                hit = Some(format!(
                    "cycle {cycle}: axis #{axis} {} {comparison:?} {limit} (value {x})",
                    <&str>::from(quantity)
                ));
            }
            *holding = holds;
        }
        if let Some(why) = hit {
            self.fire(why);
        }
    }

    /// A trigger (or the operator's request) met.
    pub(super) fn fire(&mut self, why: String) {
        match self.open.as_mut() {
            Some(o) => {
                if o.triggers.len() < 100 {
                    o.triggers.push(why);
                }
            }
            None => {
                self.fired.get_or_insert(why);
            }
        }
    }

    /// At each cycle: opens a capture a trigger asked for, ends the open one past its post
    /// window, and lets the ring forget what is older than the pre window.
    pub(super) fn cycle(&mut self, cell: &CellConfig, cycle: u64) -> Result<(), RecorderError> {
        if let Some(why) = self.fired.take() {
            self.start(cell, cycle, why)?;
        }
        if self.open.as_ref().is_some_and(|o| cycle > o.until_cycle) {
            self.finish_open()?;
        }
        let keep_from = cycle.saturating_sub(self.pre_cycles);
        while self.ring.front().is_some_and(|m| m.cycle < keep_from) {
            let m = self.ring.pop_front().expect("checked");
            if self.spare.len() < 4096 {
                self.spare.push(m.data);
            }
        }
        Ok(())
    }

    /// Opens capture file `made + 1` with the ring in it.
    fn start(&mut self, cell: &CellConfig, cycle: u64, why: String) -> Result<(), RecorderError> {
        self.made += 1;
        let path = capture_path(&self.base, self.made);
        let mut sink = open(cell, &path)?;
        for m in &self.ring {
            self.seq = self.seq.wrapping_add(1);
            write(&mut sink, m.channel, m.log_time, self.seq, &m.data)?;
        }
        tracing::info!("capture {} ({why}) → {}", self.made, path.display());
        self.open = Some(Open {
            sink,
            until_cycle: cycle + self.post_cycles,
            triggers: vec![why],
        });
        Ok(())
    }

    /// At the end of the run: a capture a trigger asked for is written with what there is, the
    /// open one finished (its post window cut short).
    pub(super) fn finish(&mut self, cell: &CellConfig, cycle: u64) -> Result<(), RecorderError> {
        if let Some(why) = self.fired.take() {
            self.start(cell, cycle, why)?;
        }
        self.finish_open()
    }

    /// Finishes the open capture: its triggers as metadata, then the summary.
    fn finish_open(&mut self) -> Result<(), RecorderError> {
        let Some(mut o) = self.open.take() else {
            return Ok(());
        };
        let metadata = Metadata {
            name: "cellrt.capture".into(),
            metadata: o
                .triggers
                .iter()
                .enumerate()
                .map(|(i, t)| (format!("trigger_{i}"), t.clone()))
                .chain([
                    ("pre_s".to_string(), self.config.pre_s.to_string()),
                    ("post_s".to_string(), self.config.post_s.to_string()),
                ])
                .collect(),
        };
        o.sink
            .writer
            .write_metadata(&metadata)
            .map_err(|source| RecorderError::Mcap {
                path: o.sink.path.clone(),
                source,
            })?;
        let (path, _) = o.sink.finish()?;
        self.files.push(path);
        Ok(())
    }
}

fn write(
    sink: &mut Sink,
    channel: u16,
    log_time: u64,
    sequence: u32,
    data: &[u8],
) -> Result<(), RecorderError> {
    sink.count_message(data.len());
    sink.writer
        .write_to_known_channel(
            &MessageHeader {
                channel_id: channel,
                sequence,
                log_time,
                publish_time: log_time,
            },
            data,
        )
        .map_err(|source| RecorderError::Mcap {
            path: sink.path.clone(),
            source,
        })
}
