//! The cyclic executive: one fixed sequence of small steps per cycle (docs/architecture.md, "Data
//! flow of one cycle"), run on the pinned RT thread with absolute deadlines.
//!
//! Steady state does no heap allocation, takes no lock and makes no syscall other than the cycle
//! sleep, the clock read and the bus exchange (the counting-allocator test proves the first).

mod acyclic;
mod axis;
mod cell;
mod comm_watchdog;
mod homing;
mod mode_switching;
mod profile_axis;
mod profile_commands;
mod rx_command;
#[cfg(test)]
mod units_tests;

pub use axis::{AxisChannel, AxisLimitsCounts, HOMING_MODE_SETTLE, STEP_TOLERANCE};
pub use mode_switching::MODE_SWITCH_TIMEOUT;
pub use rx_command::CycleCommand;

use std::sync::atomic::Ordering;

use cellrt_cia402::bus::{AcyclicBus, CyclicBus, FaultInjection, MailboxNotice};
use cellrt_cia402::pdo::objects::{HOME_OFFSET, STATUSWORD2};
use cellrt_cia402::profiles::status_do::StatusDo;
use cellrt_cia402::Cycles;
use serde::Serialize;

use crate::handoff::{
    AxisRecord, CellState, CycleRecord, EventKind, EventRecord, RejectReason, RtEnd, StopReason,
    NO_AXIS,
};
use crate::rt::clock::{sleep_until, MonoTime};
use crate::rt::histogram::NsHistogram;
use crate::rt::injection::{InjectionSchedule, Outcome};
use crate::rt::setpoint_stream::SetpointStream;
use cellrt_config::{CellConfig, FaultReaction, InjectedFault, MissedDeadlines, WatchdogConfig};

/// Hook called by the RT thread at phase changes (test instrumentation; a plain fn pointer so
/// calling it allocates nothing).
pub type PhaseHook = fn(RtPhase);

/// Phases of the RT loop reported to a [`PhaseHook`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RtPhase {
    /// Warm-up is over: from here on the loop is in steady state.
    SteadyState,
    /// The loop is about to exit.
    Exit,
}

/// Mailbox notices (Emergencies) the loop takes per cycle at most: each may cost an acyclic
/// round trip on EtherCAT.
pub const MAILBOX_NOTICES_PER_CYCLE: usize = 2;

/// Cycles the loop runs before it calls itself steady (first iceoryx2 receives, page faults).
pub const WARMUP_CYCLES: u64 = 200;

/// Counters and histograms the RT thread hands back when it exits.
#[derive(Debug, Clone)]
pub struct RtStats {
    /// The counters the summary reports.
    pub counters: RtCounters,
    /// Events that could not be handed over.
    pub dropped_events: u64,
    /// Wakeup latency histogram.
    pub latency: NsHistogram,
    /// Loop body time histogram.
    pub loop_time: NsHistogram,
    /// Bus exchange time histogram (the process-data round trip: frame out to inputs copied).
    pub exchange_time: NsHistogram,
    /// |DC phase error| histogram of the cyclic frames (EtherCAT; empty on simulated drives).
    pub dc_phase_error: NsHistogram,
    /// The bus's frame counters at the end of the loop, where it sends frames (EtherCAT).
    pub frames: Option<cellrt_cia402::FrameCounters>,
    /// Final actual position of each axis, counts.
    pub final_positions: Vec<i32>,
    /// Final cell state.
    pub final_state: CellState,
    /// The cell's cycle number at exit: `counters.cycles - 1` unless overruns skipped cycles.
    pub final_cycle: u64,
}

/// Summary numbers of [`RtStats`] for printing and JSON.
#[derive(Debug, Clone, Copy, Default, Serialize, PartialEq, Eq)]
pub struct RtCounters {
    /// Executed cycles.
    pub cycles: u64,
    /// Missed deadlines (skipped cycles, or cycles the cell's clock fell behind under
    /// `rt.missed_deadlines = "stretch"`).
    pub overruns: u64,
    /// Setpoint underruns during motion.
    pub underruns: u64,
    /// Rejected setpoint blocks.
    pub rejected_setpoints: u64,
    /// Drive faults seen (rising edges of statusword bit 3).
    pub faults: u64,
    /// Records that could not be handed to the recorder.
    pub dropped_records: u64,
}

/// All state of the RT loop, preallocated from the configuration.
pub struct Executive<B: CyclicBus + AcyclicBus> {
    bus: B,
    axes: Vec<AxisChannel>,
    stream: SetpointStream,
    handoff: RtEnd,
    period_ns: u64,
    period_s: f64,
    cycle: u64,
    state: CellState,
    motion_id: u32,
    /// The last motion whose first block was refused: its later blocks are dropped unseen.
    refused_motion: u32,
    /// How late a motion's first block may arrive and still start (`setpoints.max_start_slip_ms`).
    max_start_slip: Cycles,
    /// How many cycles late the running motion started: its blocks are due that much later.
    slip: Cycles,
    /// The motion and the row (on its own timeline) whose setpoints were applied last: a
    /// motion ends only once its final row has been (an overrun may skip past it).
    applied_row: (u32, u64),
    stop_reason: Option<crate::handoff::StopReason>,
    /// How the current stop is carried out.
    reaction: FaultReaction,
    /// A Reset arrived while Faulted: leave Faulted once no drive reports a fault.
    fault_reset_pending: bool,
    /// A communication watchdog tripped: react in `update_cell`.
    comm_fault_pending: bool,
    /// Error streaks of the communication watchdog.
    comm_streaks: comm_watchdog::CommStreaks,
    /// The motion's last setpoint was applied; it finishes once every axis a torque motion left
    /// moving has braked to rest.
    finishing: bool,
    /// Watchdog settings.
    watchdogs: WatchdogConfig,
    /// Deadlines missed in a row (reset by a cycle that starts on time).
    overrun_streak: u32,
    /// Whether a late cycle skips the cycles it missed or stretches the cell's clock.
    missed_deadlines: MissedDeadlines,
    /// Scheduled faults the RT thread applies (stall, bus faults), by cycle.
    faults: InjectionSchedule<B>,
    /// Cycles since the previous executed cycle (more than 1 after an overrun).
    elapsed: Cycles,
    stats: RtStats,
    /// Records were dropped since the last `records_dropped` event.
    drops_unreported: bool,
    /// Per axis: what its acyclic request in flight is for.
    pending: Vec<Option<acyclic::Pending>>,
    /// The planner's node died or left and none has come back: no motion starts.
    planner_lost: bool,
    /// Per axis: a fault's 603Fh read waits for the request in flight.
    error_code_wanted: Vec<bool>,
    /// The homing request whose 6098h write is in flight.
    awaiting_method: Option<crate::handoff::HomeRequest>,
    /// An operator's SDO request taken from the hand-off, waiting for its axis' slot.
    user_sdo: Option<crate::handoff::UserSdo>,
    /// Per axis: a profile axis' drive-side motion waiting for its start cycle.
    profile_pending: Vec<Option<crate::handoff::ProfileCommand>>,
    /// The feed override the profile axes run at, ‰ (the hand-off's, taken each cycle).
    feed_permille: u32,
    hook: Option<PhaseHook>,
}

impl<B: CyclicBus + AcyclicBus> Executive<B> {
    /// Builds the executive for `cell` on the RT thread (the setpoint stream's port is not `Send`).
    /// Only here is the bus a [`FaultInjection`]: it goes into the cell's fault schedule, and
    /// the loop sees a bus without it.
    pub fn new(
        cell: &CellConfig,
        bus: B,
        stream: SetpointStream,
        handoff: RtEnd,
        hook: Option<PhaseHook>,
    ) -> Self
    where
        B: FaultInjection,
    {
        let axes: Vec<AxisChannel> = cell
            .axes
            .on_loop()
            .iter()
            .map(|a| AxisChannel::new(cell, a))
            .collect();
        let n = axes.len();
        Executive {
            bus,
            axes,
            stream,
            handoff,
            period_ns: cell.cycle_time.as_nanos(),
            period_s: cell.period(),
            cycle: 0,
            state: CellState::Disabled,
            motion_id: 0,
            refused_motion: 0,
            max_start_slip: cell.setpoints.max_start_slip,
            slip: Cycles(0),
            applied_row: (0, 0),
            stop_reason: None,
            reaction: FaultReaction::ControlledStop,
            fault_reset_pending: false,
            comm_fault_pending: false,
            comm_streaks: comm_watchdog::CommStreaks::new(cell.watchdogs.comm, n),
            finishing: false,
            watchdogs: cell.watchdogs,
            overrun_streak: 0,
            missed_deadlines: cell.rt.missed_deadlines,
            faults: InjectionSchedule::for_cell(cell),
            elapsed: Cycles(1),
            stats: RtStats {
                counters: RtCounters::default(),
                dropped_events: 0,
                latency: NsHistogram::new(),
                loop_time: NsHistogram::new(),
                exchange_time: NsHistogram::new(),
                dc_phase_error: NsHistogram::new(),
                frames: None,
                final_positions: vec![0; n],
                final_state: CellState::Disabled,
                final_cycle: 0,
            },
            drops_unreported: false,
            pending: vec![None; n],
            error_code_wanted: vec![false; n],
            planner_lost: false,
            awaiting_method: None,
            user_sdo: None,
            profile_pending: vec![None; n],
            feed_permille: 1000,
            hook,
        }
    }

    /// Runs the loop until a Quit command; returns the statistics.
    pub fn run(mut self) -> RtStats {
        // Prime the inputs: one exchange with all-zero outputs (controlword 0 commands nothing)
        // so cycle 0 already sees every drive's statusword and position.
        if self.bus.exchange(Cycles(1)).is_err() {
            self.event(EventKind::BusError, NO_AXIS, -1);
        }
        for i in 0..self.axes.len() {
            self.load_home_offset(i);
        }
        self.read_inputs();
        for ch in &mut self.axes {
            ch.track_actual();
        }
        let start = MonoTime::now().plus(self.period_ns);
        let mut deadline = start;
        self.handoff.status().running.store(true, Ordering::Release);
        let mut elapsed = Cycles(1);
        loop {
            sleep_until(deadline);
            let wake = MonoTime::now();
            let latency = wake.since(deadline);
            if self.cycle == WARMUP_CYCLES {
                if let Some(hook) = self.hook {
                    hook(RtPhase::SteadyState);
                }
            }

            let quit = self.step(elapsed);

            let end = MonoTime::now();
            let loop_ns = end.since(wake);
            self.stats.latency.record(latency);
            self.stats.loop_time.record(loop_ns);
            self.stats.counters.cycles += 1;
            self.publish(deadline, latency, loop_ns);
            if quit {
                break;
            }

            // Next deadline; deadlines already past are counted and never caught up: their
            // cycles are skipped, or under `MissedDeadlines::Stretch` the cell's clock falls
            // behind (the next cycle is the next one, one deadline later on the grid).
            // Aligned to the bus clock where it has one (EtherCAT DC: the frame's place in the
            // SYNC0 cycle); the correction moves the grid, it does not count as lateness.
            let mut next = deadline
                .plus(self.period_ns)
                .shifted(self.bus.deadline_correction_ns());
            let mut step = 1u64;
            let now = MonoTime::now();
            if now >= next {
                let missed = now.since(next) / self.period_ns + 1;
                self.stats.counters.overruns += missed;
                self.event(EventKind::Overrun, NO_AXIS, now.since(next) as i64);
                next = next.plus(missed * self.period_ns);
                if self.missed_deadlines == MissedDeadlines::Skip {
                    step += missed;
                }
                self.overrun_streak = self
                    .overrun_streak
                    .saturating_add(missed.min(u64::from(u32::MAX)) as u32);
            } else {
                self.overrun_streak = 0;
            }
            deadline = next;
            self.cycle += step;
            elapsed = Cycles(step.min(u64::from(u32::MAX)) as u32);
        }
        if let Some(hook) = self.hook {
            hook(RtPhase::Exit);
        }
        self.finish_acyclic();
        self.stats.frames = self.bus.frame_counters();
        // Out of the steady state: the bus's shutdown may block and log.
        if let Err(e) = self.bus.close() {
            tracing::warn!("bus shutdown: {e}");
        }
        self.handoff
            .status()
            .running
            .store(false, Ordering::Release);
        for (i, a) in self.axes.iter().enumerate() {
            self.stats.final_positions[i] = a.feedback.position_actual;
        }
        self.stats.final_state = self.state;
        self.stats.final_cycle = self.cycle;
        self.stats
    }

    /// One cycle: read inputs, checks, commands, setpoints, masters, outputs, exchange.
    /// Returns true when the loop should exit.
    fn step(&mut self, elapsed: Cycles) -> bool {
        self.elapsed = elapsed;
        self.inject_due_faults();
        self.read_inputs();
        self.take_mailbox_notices();
        self.poll_acyclic();
        let quit = self.take_commands();
        self.update_cell();
        self.take_profile_commands();
        self.write_outputs();
        let sent = MonoTime::now();
        let exchanged = self.bus.exchange(elapsed);
        self.stats.exchange_time.record(MonoTime::now().since(sent));
        self.watch_exchange(exchanged);
        quit
    }

    /// Applies the scheduled faults due at this cycle (fault injection; off in normal runs)
    /// and records each (event value: its [`FaultKind`](cellrt_config::FaultKind) code).
    fn inject_due_faults(&mut self) {
        while let Some(due) = self.faults.next_due(self.cycle, &mut self.bus) {
            let axis = due.fault.axis().map_or(NO_AXIS, |a| a as u16);
            let code = due.fault.kind().code();
            if due.outcome == Outcome::LeftToSegment {
                self.event(EventKind::FaultLeftToSegment, axis, code);
                continue;
            }
            self.event(EventKind::FaultInjected, axis, code);
            match (due.outcome, due.fault) {
                (Outcome::Refused, _) => self.event(EventKind::BusError, axis, -2),
                (Outcome::ForTheLoop, InjectedFault::Stall { ns }) => {
                    let until = MonoTime::now().plus(ns);
                    while MonoTime::now() < until {
                        std::hint::spin_loop();
                    }
                }
                _ => {}
            }
        }
    }

    /// Records what SubDevices sent unasked (CoE Emergencies, ETG.1000.6 §5.6.2.1), at most
    /// [`MAILBOX_NOTICES_PER_CYCLE`] per cycle; the rest wait for the next ones.
    fn take_mailbox_notices(&mut self) {
        for _ in 0..MAILBOX_NOTICES_PER_CYCLE {
            match self.bus.take_mailbox_notice() {
                None => return,
                Some(MailboxNotice::Emergency { axis, emergency }) => self.event(
                    EventKind::Emergency,
                    axis as u16,
                    crate::handoff::encode_emergency(&emergency),
                ),
                Some(MailboxNotice::Discarded {
                    axis,
                    mailbox_type,
                    service,
                }) => self.event(
                    EventKind::MailboxDiscarded,
                    axis as u16,
                    i64::from(mailbox_type) | i64::from(service) << 8,
                ),
            }
        }
    }

    /// Reads 607Ch of a drive that keeps 6064h raw, before the loop starts (blocking), and
    /// moves the axis' user coordinates with it: user = raw + home offset.
    fn load_home_offset(&mut self, i: usize) {
        if !self.axes[i].offset_home {
            return;
        }
        match self.bus.sdo_upload(i, HOME_OFFSET, 0) {
            Ok(v) => self.apply_home_offset(i, v as i32),
            Err(code) => self.event(EventKind::BusError, i as u16, i64::from(code)),
        }
    }

    /// Decodes every axis' TxPDO image and watches for FSA changes and faults.
    fn read_inputs(&mut self) {
        for i in 0..self.axes.len() {
            let ch = &mut self.axes[i];
            let old = ch.feedback.statusword;
            // Decoded in place: the image is not copied through the stack every cycle.
            if ch
                .tx_map
                .decode_tx_into(self.bus.tx_image(i), &mut ch.feedback)
                .is_err()
            {
                self.event(EventKind::BusError, i as u16, i as i64);
                continue;
            }
            // User counts where the drive keeps 6064h raw (MR-J3-T04 manual §8.11.4.2, §8.11.6, §9.1).
            ch.feedback.position_actual = ch.to_user(ch.feedback.position_actual);
            // Before this cycle's setpoint is taken: the one the drive was sent.
            if !ch.following_error_mapped {
                ch.feedback.following_error =
                    ch.computed_following_error(ch.feedback.position_actual);
            }
            let (statusword, error_code) = (ch.feedback.statusword, ch.feedback.error_code);
            self.watch_counter(
                i,
                self.axes[i].comm_check.tx_counter(&self.axes[i].feedback),
            );
            self.watch_link_state(i);
            if old.state() != statusword.state() {
                let v = statusword.state().map(fsa_index).unwrap_or(0);
                self.event(EventKind::FsaState, i as u16, v);
            }
            if statusword.fault() && !old.fault() {
                self.stats.counters.faults += 1;
                // 603Fh: from the TxPDO where mapped, else one acyclic read posted at the fault
                // edge (the event follows with its outcome).
                if self.axes[i].error_code_mapped {
                    self.event(EventKind::DriveFault, i as u16, i64::from(error_code));
                } else {
                    self.request_error_code(i);
                }
            }
        }
    }

    /// Encodes every axis' RxPDO image from its setpoint and controlword.
    fn write_outputs(&mut self) {
        for i in 0..self.axes.len() {
            let ch = &mut self.axes[i];
            let mut controlword = ch.master.update(ch.feedback.statusword);
            let mut cmd = match ch.drive_command() {
                Ok(c) => c,
                Err(_) => {
                    // Beyond the drive's object (e.g. 60FFh past I32 in its unit): refused
                    // with a reason, the last command kept for this cycle, the cell stops.
                    let held = axis::DriveCommand {
                        mode: ch.mode,
                        target_velocity: ch.sent_velocity,
                        target_torque: 0,
                    };
                    self.event(
                        EventKind::SetpointRejected,
                        i as u16,
                        RejectReason::DriveRange as i64,
                    );
                    if self.stop_reason.is_none() {
                        self.react(StopReason::SetpointRejected);
                    }
                    held
                }
            };
            let ch = &mut self.axes[i];
            ch.sent_velocity = cmd.target_velocity;
            let display = ch.mode_display_mapped.then_some(ch.feedback.mode_display);
            let enabled = ch.master.is_enabled();
            let standstill = ch.feedback.velocity_actual == 0;
            let mut controlword2 = ch.static_controlword2();
            if let Some(h) = ch.homing.update(
                ch.feedback.statusword,
                ch.feedback.extra_word(STATUSWORD2),
                enabled,
                display,
                standstill,
            ) {
                cmd.mode = h.mode;
                controlword.0 |= h.start_bit;
                controlword2 |= h.controlword2;
            }
            // A drive without 6060h in its RxPDO changes mode by SDO (only at a homing's
            // start and end), posted: the mode display tells the homing when it took effect.
            if ch.sdo_mode.is_some_and(|m| m != cmd.mode) {
                self.request_mode(i, cmd.mode);
            }
            let ch = &mut self.axes[i];
            let counter = ch.counter.as_mut().map_or(0, |c| c.next_tx());
            let mut rx = ch.rx_pdo(&CycleCommand {
                mode: cmd.mode.as_i8(),
                controlword,
                target_position: ch.to_raw(round_counts(ch.setpoint)),
                target_velocity: cmd.target_velocity,
                target_torque: cmd.target_torque,
                controlword2,
                counter,
            });
            // A homing drives the controlword's bit 4 (Homing operation start in hm), which a
            // profile axis' outputs would clear as their New set-point.
            if !self.axes[i].homing.is_active() {
                self.profile_outputs(i, &mut rx);
            }
            self.mode_switch_outputs(i, &mut rx);
            let controlword = rx.controlword;
            if self.axes[i]
                .rx_map
                .encode_rx(&rx, self.bus.rx_image_mut(i))
                .is_err()
            {
                self.event(EventKind::BusError, i as u16, i as i64);
            }
            if self.handoff.per_cycle_records_taken() {
                let ch = &self.axes[i];
                let rec = AxisRecord {
                    cycle: self.cycle,
                    axis: i as u16,
                    setpoint: ch.setpoint,
                    setpoint_velocity: ch.velocity,
                    target_position: rx.target_position,
                    position_actual: ch.feedback.position_actual,
                    velocity_actual: ch.feedback.velocity_actual,
                    following_error: ch.feedback.following_error,
                    controlword: controlword.0,
                    statusword: ch.feedback.statusword.0,
                    fsa_state: ch.feedback.statusword.state(),
                    mode_display: ch.feedback.mode_display,
                    error_code: ch.feedback.error_code,
                    target_torque: rx.target_torque,
                    mode: rx.mode,
                    target_velocity: rx.target_velocity,
                    torque_actual: ch.feedback.torque_actual,
                    counter_sent: rx.counter,
                    controlword2: rx.controlword2,
                    counter_received: ch.comm_check.tx_counter(&ch.feedback),
                    status_do: StatusDo::of(&ch.feedback).0,
                    profile: ch.profile.as_ref().map_or([0; 4], |p| p.held()),
                };
                let pushed = self.handoff.push_axis(rec);
                self.record_pushed(pushed);
            }
        }
    }

    /// Hands the cycle record and the status to the non-RT side.
    fn publish(&mut self, deadline: MonoTime, latency: u64, loop_ns: u64) {
        let status = self.handoff.status();
        status.cycle.store(self.cycle, Ordering::Release);
        status.state.store(self.state as u8, Ordering::Release);
        let dc_phase = self.bus.dc_phase_error_ns();
        if let Some(e) = dc_phase {
            self.stats.dc_phase_error.record(e.unsigned_abs());
        }
        if self.handoff.per_cycle_records_taken() {
            let rec = CycleRecord {
                cycle: self.cycle,
                deadline_ns: deadline.0,
                wakeup_latency_ns: latency.min(u64::from(u32::MAX)) as u32,
                loop_time_ns: loop_ns.min(u64::from(u32::MAX)) as u32,
                overruns: self.stats.counters.overruns,
                cell_state: self.state,
                dropped_records: self.stats.counters.dropped_records,
                dc_phase_error_ns: dc_phase
                    .map(|e| e.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32),
            };
            let pushed = self.handoff.push_cycle(rec);
            self.record_pushed(pushed);
        }
    }

    /// Counts a record the recorder queue refused; once a push succeeds again after drops,
    /// records one `records_dropped` event (value: dropped so far). Allocation-free.
    fn record_pushed(&mut self, pushed: bool) {
        if !pushed {
            self.stats.counters.dropped_records += 1;
            self.drops_unreported = true;
        } else if self.drops_unreported {
            self.drops_unreported = false;
            self.event(
                EventKind::RecordsDropped,
                NO_AXIS,
                self.stats.counters.dropped_records.min(i64::MAX as u64) as i64,
            );
        }
    }

    /// Hands an event over; a full queue is counted, never blocks.
    fn event(&mut self, kind: EventKind, axis: u16, value: i64) {
        let ev = EventRecord {
            cycle: self.cycle,
            kind,
            axis,
            value,
        };
        if !self.handoff.push_event(ev) {
            self.stats.dropped_events += 1;
        }
    }
}

/// Rounds a fractional count to the drive's 32-bit position (saturating; the range check
/// keeps setpoints far inside).
fn round_counts(v: f64) -> i32 {
    v.round().clamp(f64::from(i32::MIN), f64::from(i32::MAX)) as i32
}

/// Index of an FSA state in the recording's `FsaState` enum (its [`FsaState::code`]).
///
/// [`FsaState::code`]: cellrt_cia402::fsa::FsaState::code
pub fn fsa_index(s: cellrt_cia402::fsa::FsaState) -> i64 {
    i64::from(s.code())
}
