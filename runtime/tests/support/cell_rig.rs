//! An in-process cell on the simulated bus for the e2e tests of drive-side motion: the RT
//! executive on its own thread, its records and events drained, the peaks of 606Ch judged on
//! consecutive recorded cycles.

use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use cellrt_config::CellConfig;
use cellrt_runtime::handoff::{
    self, AxisRecord, CellCommand, CellState, EventKind, EventRecord, HostEnd, ProfileCommand,
    ProfileMotion,
};
use cellrt_runtime::rt::executive::RtStats;
use cellrt_runtime::services;

use super::rt_thread;

/// Cycles over which an acceleration is measured.
pub const ACCEL_WINDOW: usize = 5;
/// Consecutive cycles before an acceleration window (the servo loop settled after a gap).
pub const SETTLED: usize = 20;

/// A cell's RT executive and the test's end of its hand-off.
pub struct Rig {
    pub handoff: HostEnd,
    rt: Option<JoinHandle<RtStats>>,
    _node: iceoryx2::node::Node<iceoryx2::prelude::ipc::Service>,
    pub events: Vec<EventRecord>,
    pub records: Vec<AxisRecord>,
    pub cell: CellConfig,
}

impl Rig {
    pub fn start(cell: CellConfig) -> Rig {
        let (h, handoff) = handoff::new(1, 20_000, handoff::PerCycleRecords::Taken);
        let node = services::node(&cell.name, "test").unwrap();
        let _publisher = services::setpoint_publisher(&node, &cell.name, 1).unwrap();
        let rt = rt_thread::spawn_rt(&cell, h, None);
        let mut rig = Rig {
            handoff,
            rt: Some(rt),
            _node: node,
            events: Vec::new(),
            records: Vec::new(),
            cell,
        };
        rig.handoff.send_command(CellCommand::PowerOn).unwrap();
        rig.wait(|r| r.handoff.status().state() == CellState::Idle, "idle");
        rig
    }

    pub fn drain(&mut self) {
        while let Some(e) = self.handoff.pop_event() {
            self.events.push(e);
        }
        while let Some(r) = self.handoff.pop_axis() {
            self.records.push(r);
        }
        while self.handoff.pop_cycle().is_some() {}
    }

    pub fn wait(&mut self, done: impl Fn(&Rig) -> bool, what: &str) {
        let end = Instant::now() + Duration::from_secs(30);
        loop {
            self.drain();
            if done(self) {
                return;
            }
            assert!(Instant::now() < end, "never {what}: {:?}", self.events);
            std::thread::sleep(Duration::from_millis(2));
        }
    }

    /// 606Ch of `r` in mm/s.
    pub fn speed(&self, r: &AxisRecord) -> f64 {
        let a = &self.cell.axes.on_loop()[0];
        a.drive_units.velocity_from_drive(r.velocity_actual) / a.scaling.counts_per_unit()
    }

    /// Peak |speed| (mm/s) and peak |acceleration| (mm/s², over [`ACCEL_WINDOW`] cycles of
    /// consecutive records, [`SETTLED`] cycles after a gap of the loaded machine).
    pub fn peaks(&self, span: &[AxisRecord]) -> (f64, f64) {
        let peak_v = span.iter().fold(0.0f64, |m, r| m.max(self.speed(r).abs()));
        let (n, k) = (ACCEL_WINDOW, SETTLED);
        let peak_a = span
            .windows(k + n + 1)
            .filter(|w| w.windows(2).all(|p| p[1].cycle == p[0].cycle + 1))
            .fold(0.0f64, |m, w| {
                m.max((self.speed(&w[k + n]) - self.speed(&w[k])).abs() / (n as f64 * 1e-3))
            });
        (peak_v, peak_a)
    }

    /// After a request: waits for its `end` event and then for `records_after` records from
    /// that cycle on; returns the cycle of the `start` event (`None`: refused before it
    /// started), the end event and every event since `seen` (the event count before the
    /// request).
    pub fn until(
        &mut self,
        seen: usize,
        (start, end): (EventKind, EventKind),
        records_after: usize,
    ) -> (Option<u64>, EventRecord, Vec<EventRecord>) {
        self.wait(
            |r| r.events[seen..].iter().any(|e| e.kind == end),
            end.as_str(),
        );
        let events = self.events[seen..].to_vec();
        let finished = *events.iter().find(|e| e.kind == end).unwrap();
        let started = events.iter().find(|e| e.kind == start).map(|e| e.cycle);
        self.wait(
            |r| {
                r.records
                    .iter()
                    .filter(|a| a.cycle >= finished.cycle)
                    .count()
                    >= records_after
            },
            "the records after the end",
        );
        (started, finished, events)
    }

    /// Sends `motion` to axis 0 and waits for its `profile_finished` and `records_after`
    /// records from its cycle on (see [`Rig::until`]).
    pub fn profile(
        &mut self,
        motion: ProfileMotion,
        records_after: usize,
    ) -> (Option<u64>, EventRecord, Vec<EventRecord>) {
        let seen = self.events.len();
        self.handoff
            .send_profile_command(ProfileCommand {
                axis: 0,
                motion,
                start_cycle: 0,
            })
            .unwrap();
        let kinds = (EventKind::ProfileStarted, EventKind::ProfileFinished);
        self.until(seen, kinds, records_after)
    }

    /// The records of cycles `from..=to`.
    pub fn span(&self, from: u64, to: u64) -> Vec<AxisRecord> {
        self.records
            .iter()
            .filter(|r| r.cycle >= from && r.cycle <= to)
            .copied()
            .collect()
    }

    pub fn stop(mut self) {
        self.handoff.send_command(CellCommand::PowerOff).unwrap();
        self.wait(
            |r| r.handoff.status().state() == CellState::Disabled,
            "disabled",
        );
        self.handoff.send_command(CellCommand::Quit).unwrap();
        self.rt.take().unwrap().join().unwrap();
    }
}
