//! The cell state machine of the RT loop: commands, power sequencing, following the setpoint
//! stream, underrun and setpoint checks, the controlled stop and the group reaction to faults
//! (homing is in [`super::homing`]).

use std::sync::atomic::Ordering;

use cellrt_cia402::bus::{AcyclicBus, CyclicBus};
use cellrt_cia402::master::{MasterRequest, MasterState};
use cellrt_cia402::mode::ModeOfOperation;
use cellrt_cia402::Cycles;

use super::Executive;
use crate::handoff::{CellCommand, CellState, EventKind, RejectReason, StopReason, NO_AXIS};
use crate::setpoints::BLOCK_CYCLES;
use cellrt_cia402::homing::HomingFailure;
use cellrt_config::FaultReaction;

/// Commands taken per cycle at most (bounds the cycle's work).
const COMMANDS_PER_CYCLE: usize = 4;

/// Outcome of looking up this cycle's setpoints in the stream.
enum Lookup {
    /// Setpoints applied.
    Applied,
    /// The motion ended with the previous cycle.
    Finished,
    /// No setpoint for this cycle.
    Underrun,
    /// A setpoint was refused.
    Rejected(u16, RejectReason),
}

impl<B: CyclicBus + AcyclicBus> Executive<B> {
    /// Takes pending commands; returns true on Quit.
    pub(super) fn take_commands(&mut self) -> bool {
        for _ in 0..COMMANDS_PER_CYCLE {
            let Some(cmd) = self.handoff.next_command() else {
                break;
            };
            let accepted = match (cmd, self.state) {
                (CellCommand::Quit, _) => return true,
                (
                    CellCommand::PowerOn,
                    CellState::Disabled | CellState::Enabling | CellState::Idle,
                ) => {
                    self.power_on_all();
                    true
                }
                (
                    CellCommand::PowerOnAxis(a),
                    CellState::Disabled | CellState::Enabling | CellState::Idle,
                ) if usize::from(a) < self.axes.len() => {
                    let ch = &mut self.axes[usize::from(a)];
                    if !ch.powered {
                        ch.powered = true;
                        ch.master.request(MasterRequest::Enable);
                        self.set_state(CellState::Enabling);
                    }
                    true
                }
                (CellCommand::PowerOffAxis(a), CellState::Idle | CellState::Enabling)
                    if usize::from(a) < self.axes.len() =>
                {
                    let ch = &mut self.axes[usize::from(a)];
                    ch.powered = false;
                    ch.master.request(MasterRequest::Disable);
                    if !self.axes.iter().any(|ch| ch.powered) {
                        self.stream.discard_all();
                        self.set_state(CellState::Disabling);
                    }
                    true
                }
                // Nothing is powered: nothing to do.
                (CellCommand::PowerOffAxis(_), CellState::Disabled | CellState::Disabling) => true,
                (
                    CellCommand::PowerOff,
                    CellState::Idle
                    | CellState::Enabling
                    | CellState::Stopped
                    | CellState::Faulted
                    | CellState::Disabling
                    | CellState::Disabled
                    | CellState::Homing,
                ) => {
                    if self.state == CellState::Homing {
                        self.end_homing(Some(HomingFailure::NotEnabled));
                    }
                    for ch in &mut self.axes {
                        ch.powered = false;
                    }
                    self.request_all(MasterRequest::Disable);
                    self.stream.discard_all();
                    self.set_state(CellState::Disabling);
                    true
                }
                (CellCommand::Stop, CellState::Moving) => {
                    self.react(StopReason::Command);
                    true
                }
                (CellCommand::Stop, CellState::Idle) if self.profile_axes_moving() => {
                    self.react(StopReason::Command);
                    true
                }
                (CellCommand::Stop, _) => true,
                // Latched: a motion its blocks would still start from the buffer is refused too.
                (CellCommand::PlannerLost | CellCommand::PlannerConnected, state) => {
                    self.planner_lost = cmd == CellCommand::PlannerLost;
                    if self.planner_lost && state == CellState::Moving {
                        self.react(StopReason::PlannerLost);
                    }
                    true
                }
                (CellCommand::Reset, CellState::Stopped) => {
                    self.reset_stopped();
                    true
                }
                (CellCommand::Reset, CellState::Faulted) => {
                    self.reset_faulted();
                    true
                }
                (CellCommand::Reset, _) => true,
                _ => false,
            };
            let kind = if accepted {
                EventKind::Command
            } else {
                EventKind::CommandRefused
            };
            self.event(kind, cmd.axis().unwrap_or(NO_AXIS), cmd.event_value());
        }
        false
    }

    /// MC_Power on every axis not yet powered; the cell enables them. A disabled cell with no
    /// axis on the RT loop (only MR-JE-C axes, run by their link threads) is enabled at once.
    fn power_on_all(&mut self) {
        let mut any = false;
        for ch in &mut self.axes {
            if !ch.powered {
                ch.powered = true;
                ch.master.request(MasterRequest::Enable);
                any = true;
            }
        }
        if any || self.state == CellState::Disabled {
            self.set_state(CellState::Enabling);
        }
    }

    /// MC_Reset of a Stopped cell: counters and the stop reason cleared, the stream emptied;
    /// Idle, or a clean power-off where a reaction left drives disabled.
    fn reset_stopped(&mut self) {
        for ch in &mut self.axes {
            if let Some(c) = ch.counter.as_mut() {
                c.reset();
            }
            ch.comm_fault = false;
        }
        self.clear_stop_reason();
        self.stream.discard_all();
        if self.axes.iter().all(|a| a.master.is_enabled() == a.powered) {
            self.set_state(CellState::Idle);
        } else {
            // A quick stop or disable reaction left drives disabled: power off cleanly; the
            // next power on starts from Disabled.
            for ch in &mut self.axes {
                ch.powered = false;
            }
            self.request_all(MasterRequest::Disable);
            self.set_state(CellState::Disabling);
        }
    }

    /// MC_Reset of a Faulted cell: a fault reset to every drive in Fault; the cell leaves
    /// Faulted once none reports one.
    fn reset_faulted(&mut self) {
        self.fault_reset_pending = true;
        self.clear_stop_reason();
        for ch in &mut self.axes {
            if ch.feedback.statusword.fault() {
                ch.master.request(MasterRequest::FaultReset);
            }
        }
    }

    fn clear_stop_reason(&mut self) {
        self.stop_reason = None;
        self.handoff
            .status()
            .stop_reason
            .store(0, Ordering::Release);
    }

    /// One cycle of the cell state machine.
    pub(super) fn update_cell(&mut self) {
        if self.comm_fault_pending {
            self.comm_fault_pending = false;
            if matches!(self.state, CellState::Idle | CellState::Moving) {
                self.react(StopReason::Communication);
            }
        }
        let limit = self.watchdogs.max_consecutive_overruns;
        if limit > 0 && self.overrun_streak >= limit {
            self.overrun_streak = 0;
            if matches!(self.state, CellState::Idle | CellState::Moving) {
                self.react(StopReason::Overrun);
            }
        }
        match self.state {
            CellState::Disabled => {
                self.track_all();
                self.refuse_motion();
            }
            CellState::Enabling => {
                self.track_all();
                self.refuse_motion();
                if self.any_fault_or_timeout() {
                    self.enter_faulted();
                } else if self
                    .axes
                    .iter()
                    .all(|a| !a.powered || a.master.is_enabled())
                {
                    self.set_state(CellState::Idle);
                }
            }
            CellState::Idle => {
                if self.any_fault_or_timeout() {
                    self.enter_faulted();
                } else {
                    self.hold_all();
                    // A homing request waits in the hand-off while an axis switches its mode.
                    if !self.mode_switching() {
                        self.poll_home_request();
                    }
                    if self.state == CellState::Idle && self.planner_lost {
                        self.refuse_motion();
                    } else if self.state == CellState::Idle {
                        self.poll_motion_start();
                    }
                }
            }
            CellState::Homing => {
                if self.any_fault_or_timeout() {
                    self.end_homing(Some(HomingFailure::NotEnabled));
                    self.enter_faulted();
                } else {
                    self.homing_cycle();
                }
            }
            CellState::Moving => {
                if self.any_fault_or_timeout() {
                    self.react(StopReason::DriveFault);
                    self.stop_cycle();
                    self.publish_holds();
                    return;
                }
                if self.finishing {
                    self.finish_motion();
                    self.publish_holds();
                    return;
                }
                match self.follow_stream() {
                    Lookup::Applied => {}
                    Lookup::Finished => {
                        self.stream.pop();
                        self.finishing = true;
                        self.finish_motion();
                    }
                    Lookup::Underrun => {
                        self.stats.counters.underruns += 1;
                        self.event(EventKind::Underrun, NO_AXIS, i64::from(self.motion_id));
                        self.react(StopReason::Underrun);
                        self.stop_cycle();
                    }
                    Lookup::Rejected(axis, reason) => {
                        self.stats.counters.rejected_setpoints += 1;
                        self.event(EventKind::SetpointRejected, axis, reason as i64);
                        self.react(StopReason::SetpointRejected);
                        self.stop_cycle();
                    }
                }
            }
            CellState::Stopping => self.stop_cycle(),
            CellState::Stopped => {
                if self.any_fault_or_timeout() {
                    self.enter_faulted();
                } else {
                    self.hold_all();
                    self.refuse_motion();
                }
            }
            CellState::Disabling => {
                // Hold until each drive has really left Operation enabled, then track it.
                self.hold_all();
                self.refuse_motion();
                if self.axes.iter().all(|a| !a.master.is_enabled()) {
                    self.set_state(CellState::Disabled);
                }
            }
            CellState::Faulted => {
                self.track_all();
                self.refuse_motion();
                // The fault must be reset before the cell can be disabled and powered again.
                if self.fault_reset_pending
                    && self.axes.iter().all(|a| !a.feedback.statusword.fault())
                {
                    self.fault_reset_pending = false;
                    self.request_all(MasterRequest::Disable);
                    self.set_state(CellState::Disabling);
                }
            }
        }
        self.publish_holds();
    }

    /// Holds every axis; once none is still braking after a torque motion, reports the motion
    /// done and returns to Idle.
    fn finish_motion(&mut self) {
        self.hold_all();
        if self.axes.iter().any(|a| a.braking) {
            return;
        }
        self.finishing = false;
        self.handoff
            .status()
            .motion_done
            .store(self.motion_id, Ordering::Release);
        self.event(
            EventKind::MotionFinished,
            NO_AXIS,
            i64::from(self.motion_id),
        );
        self.set_state(CellState::Idle);
    }

    fn request_all(&mut self, req: MasterRequest) {
        for ch in &mut self.axes {
            ch.master.request(req);
        }
    }

    fn track_all(&mut self) {
        for ch in &mut self.axes {
            ch.track_actual();
        }
    }

    fn hold_all(&mut self) {
        let period = self.period_s;
        for ch in &mut self.axes {
            if ch.master.is_enabled() {
                ch.hold(period);
            } else {
                ch.track_actual();
            }
        }
    }

    fn publish_holds(&self) {
        for (i, ch) in self.axes.iter().enumerate() {
            self.handoff.status().hold[i].store(ch.setpoint.to_bits(), Ordering::Release);
            let live = &self.handoff.status().live[i];
            let f = &ch.feedback;
            live.position_actual
                .store(f.position_actual, Ordering::Relaxed);
            live.velocity_actual
                .store(f.velocity_actual, Ordering::Relaxed);
            live.following_error
                .store(f.following_error, Ordering::Relaxed);
            live.statusword.store(f.statusword.0, Ordering::Relaxed);
            live.error_code.store(f.error_code, Ordering::Relaxed);
            live.mode_display.store(f.mode_display, Ordering::Relaxed);
            live.powered.store(ch.powered, Ordering::Relaxed);
            live.mode.store(ch.mode.as_i8(), Ordering::Release);
            let status_do = cellrt_cia402::profiles::status_do::StatusDo::of(f);
            for (word, value) in live.status_do.iter().zip(status_do.0) {
                word.store(value, Ordering::Relaxed);
            }
        }
    }

    fn any_fault_or_timeout(&self) -> bool {
        self.axes.iter().any(|a| {
            a.master.fault()
                || matches!(
                    a.master.state(),
                    MasterState::TimedOut | MasterState::EnableLost
                )
        })
    }

    fn enter_faulted(&mut self) {
        for i in 0..self.axes.len() {
            if self.axes[i].master.state() == MasterState::TimedOut {
                self.event(EventKind::MasterTimeout, i as u16, 0);
            }
        }
        self.stop_reason = Some(StopReason::DriveFault);
        self.handoff
            .status()
            .stop_reason
            .store(StopReason::DriveFault as u8, Ordering::Release);
        for ch in &mut self.axes {
            ch.powered = false;
        }
        self.request_all(MasterRequest::Disable);
        self.stream.discard_all();
        self.fault_reset_pending = false;
        self.set_state(CellState::Faulted);
    }

    pub(super) fn set_state(&mut self, s: CellState) {
        if self.state != s {
            self.state = s;
            self.handoff
                .status()
                .state
                .store(s as u8, Ordering::Release);
            self.event(EventKind::CellState, NO_AXIS, s as i64);
        }
    }

    /// Drops blocks that arrive while the cell does not accept motion, with an event per block.
    pub(super) fn refuse_motion(&mut self) {
        for _ in 0..BLOCK_CYCLES {
            match self.stream.front() {
                Ok(Some(_)) => {
                    self.stream.pop();
                    self.event(
                        EventKind::SetpointRejected,
                        NO_AXIS,
                        RejectReason::NotAccepting as i64,
                    );
                }
                _ => break,
            }
        }
    }

    /// In Idle: starts the motion whose first block begins this cycle. A motion whose first
    /// block is refused never starts: the status names it (`motion_refused`) so its planner
    /// stops waiting, and its later blocks are dropped.
    fn poll_motion_start(&mut self) {
        // Stale blocks (of an ended or refused motion) and a refused motion's first block are
        // dropped all in one cycle: one per cycle would hold up the next motion's first block
        // behind them until it is late too. Bounded by the subscriber's buffer.
        for _ in 0..crate::services::SETPOINT_BUFFER_BLOCKS + 2 {
            if !self.poll_motion_start_once() {
                return;
            }
        }
    }

    /// One look at the stream's front in Idle; true when a block was dropped (look again).
    fn poll_motion_start_once(&mut self) -> bool {
        let cycle = self.cycle;
        let n = self.axes.len();
        let last_motion = self.motion_id;
        let switching = self.mode_switching();
        let verdict = match self.stream.front() {
            Ok(Some(b)) => {
                let h = b.header;
                if (h.motion_id <= last_motion && h.motion_id != 0 && last_motion != 0)
                    || (h.motion_id == self.refused_motion && h.motion_id != 0)
                {
                    Some(Err(None)) // stale block of an ended or refused motion
                } else if !b.is_well_formed(n) {
                    Some(Err(Some((RejectReason::Malformed, h.motion_id))))
                } else if h.start_cycle + u64::from(self.max_start_slip.0) < cycle {
                    Some(Err(Some((RejectReason::LateBlock, h.motion_id))))
                } else if h.start_cycle <= cycle && switching {
                    Some(Err(Some((RejectReason::NotAccepting, h.motion_id))))
                } else if h.start_cycle <= cycle {
                    // At rest, a late first block shifts the whole motion instead of failing it.
                    Some(Ok((h.motion_id, Cycles((cycle - h.start_cycle) as u32))))
                } else {
                    None
                }
            }
            _ => None,
        };
        match verdict {
            None => false,
            Some(Err(None)) => {
                self.stream.pop();
                true
            }
            Some(Err(Some((reason, id)))) => {
                self.stats.counters.rejected_setpoints += 1;
                self.event(EventKind::SetpointRejected, NO_AXIS, reason as i64);
                self.stream.pop();
                self.refuse_start(id);
                true
            }
            Some(Ok((id, slip))) => {
                self.motion_id = id;
                self.slip = slip;
                match self.follow_stream() {
                    Lookup::Applied => {
                        let status = self.handoff.status();
                        status.motion_slip.store(slip.0, Ordering::Relaxed);
                        status.motion_id.store(id, Ordering::Release);
                        self.event(EventKind::MotionStarted, NO_AXIS, i64::from(id));
                        if slip.0 > 0 {
                            self.event(EventKind::StartSlipped, NO_AXIS, i64::from(slip.0));
                        }
                        self.set_state(CellState::Moving);
                    }
                    Lookup::Rejected(axis, reason) => {
                        self.stats.counters.rejected_setpoints += 1;
                        self.event(EventKind::SetpointRejected, axis, reason as i64);
                        self.stream.discard_all();
                        self.motion_id = last_motion;
                        self.refuse_start(id);
                    }
                    Lookup::Finished | Lookup::Underrun => {
                        self.stream.pop();
                        self.motion_id = last_motion;
                        self.refuse_start(id);
                    }
                }
                false
            }
        }
    }

    /// Marks motion `id` as never started, for its planner and for the blocks still to come.
    fn refuse_start(&mut self, id: u32) {
        self.refused_motion = id;
        self.handoff
            .status()
            .motion_refused
            .store(id, Ordering::Release);
    }

    /// Applies this cycle's setpoints from the stream, checking continuity and limits before
    /// anything is applied.
    fn follow_stream(&mut self) -> Lookup {
        // The motion's own timeline: the cycle its blocks name.
        let cycle = self.cycle - u64::from(self.slip.0);
        let n = self.axes.len();
        // After an overrun the setpoint may move as far as the skipped cycles allow.
        let steps = f64::from(self.elapsed.0.max(1));
        // Blocks looked at: the one in use, those an overrun skipped entirely, and the one that
        // covers this cycle; bounded by the subscriber's buffer.
        let max_blocks = (self.elapsed.0 as usize / BLOCK_CYCLES + 2)
            .min(crate::services::SETPOINT_BUFFER_BLOCKS + 2);
        for _ in 0..max_blocks {
            let front = match self.stream.front() {
                Ok(Some(b)) => b,
                _ => return Lookup::Underrun,
            };
            if front.header.motion_id != self.motion_id || !front.is_well_formed(n) {
                return Lookup::Rejected(NO_AXIS, RejectReason::Discontinuous);
            }
            if cycle < front.header.start_cycle {
                return Lookup::Underrun;
            }
            // The row this cycle applies: the one it names, or the motion's final row where an
            // overrun skipped past the end before it was applied.
            let mut row = cycle;
            if cycle >= front.end_cycle() && front.is_last() {
                let last = front.end_cycle() - 1;
                if self.applied_row == (self.motion_id, last) {
                    return Lookup::Finished;
                }
                row = last;
            } else if cycle >= front.end_cycle() {
                let end = front.end_cycle();
                self.stream.pop();
                match self.stream.front() {
                    Ok(Some(next))
                        if next.header.start_cycle != end
                            && next.header.motion_id == self.motion_id =>
                    {
                        return Lookup::Rejected(NO_AXIS, RejectReason::Discontinuous)
                    }
                    _ => continue,
                }
            }
            // Check every axis first, then apply: a rejected cycle changes nothing.
            let torque_block = front.is_torque();
            let dt = self.period_s * steps;
            for (i, ch) in self.axes.iter().enumerate() {
                let Some(sp) = front.get(row, i) else {
                    return Lookup::Rejected(i as u16, RejectReason::Malformed);
                };
                if ch.profile.is_some() {
                    // A profile axis' drive moves it; the planner streams none of its motion
                    // (its rows hold where the planner last saw it).
                    continue;
                }
                if !ch.powered {
                    // Its rows hold (the planner's idea of where it is); anything else is motion.
                    if sp.velocity != 0.0 || sp.torque != 0.0 {
                        return Lookup::Rejected(i as u16, RejectReason::AxisNotPowered);
                    }
                    continue;
                }
                if torque_block && ch.mode == ModeOfOperation::CyclicSyncTorque {
                    if let Err(reason) = ch.check_torque(sp.torque * 10.0, dt) {
                        return Lookup::Rejected(i as u16, reason);
                    }
                    // Torque does not steer the position: stop once the motor leaves its range.
                    let actual = f64::from(ch.feedback.position_actual);
                    if actual < ch.limits.position_min || actual > ch.limits.position_max {
                        return Lookup::Rejected(i as u16, RejectReason::OutsideRange);
                    }
                    continue;
                }
                if !sp.position.is_finite() || !sp.velocity.is_finite() {
                    return Lookup::Rejected(i as u16, RejectReason::Malformed);
                }
                if sp.position < ch.limits.position_min || sp.position > ch.limits.position_max {
                    return Lookup::Rejected(i as u16, RejectReason::OutsideRange);
                }
                if (sp.position - ch.setpoint).abs() > ch.limits.max_step * steps
                    || (sp.velocity * self.period_s).abs() > ch.limits.max_step
                {
                    return Lookup::Rejected(i as u16, RejectReason::VelocityStep);
                }
            }
            for (i, ch) in self.axes.iter_mut().enumerate() {
                if ch.profile.is_some() {
                    continue; // its setpoint follows the drive (`profile_outputs`)
                }
                if !ch.powered {
                    ch.track_actual();
                } else if let Some(sp) = front.get(row, i) {
                    if torque_block && ch.mode == ModeOfOperation::CyclicSyncTorque {
                        ch.apply_torque(sp.torque * 10.0);
                    } else {
                        ch.apply(sp.position, sp.velocity, dt);
                    }
                }
            }
            self.applied_row = (self.motion_id, row);
            return Lookup::Applied;
        }
        Lookup::Underrun
    }

    /// Starts the configured reaction to `reason` (a Stop command is always a controlled stop).
    /// After a reaction other than a commanded stop the cell refuses motion until reset.
    pub(super) fn react(&mut self, reason: StopReason) {
        let reaction = match reason {
            StopReason::Command => FaultReaction::ControlledStop,
            StopReason::Underrun | StopReason::SetpointRejected | StopReason::PlannerLost => {
                self.watchdogs.underrun_reaction
            }
            StopReason::DriveFault => self.watchdogs.drive_fault_reaction,
            StopReason::Overrun => self.watchdogs.overrun_reaction,
            StopReason::Communication => self.watchdogs.communication_reaction,
        };
        self.stop_reason = Some(reason);
        self.reaction = reaction;
        self.finishing = false;
        self.cancel_pending_profiles();
        self.handoff
            .status()
            .stop_reason
            .store(reason as u8, Ordering::Release);
        match reaction {
            FaultReaction::ControlledStop => {
                for ch in &mut self.axes {
                    ch.begin_stop();
                }
                self.stop_profile_axes();
            }
            FaultReaction::QuickStop => {
                for ch in self.axes.iter_mut().filter(|ch| ch.powered) {
                    ch.master.request(MasterRequest::QuickStop);
                }
            }
            FaultReaction::Disable => self.request_all(MasterRequest::Disable),
        }
        self.stream.discard_all();
        let code = reason as i64 * 16
            + match reaction {
                FaultReaction::ControlledStop => 0,
                FaultReaction::QuickStop => 1,
                FaultReaction::Disable => 2,
            };
        self.event(EventKind::StopStarted, NO_AXIS, code);
        self.set_state(CellState::Stopping);
    }

    /// One cycle of the stop in progress; ends it when every axis stands still (controlled stop)
    /// or every drive has left Operation enabled (quick stop, disable).
    fn stop_cycle(&mut self) {
        self.stream.discard_all();
        let period = self.period_s;
        let drive_side = self.reaction != FaultReaction::ControlledStop;
        for ch in &mut self.axes {
            if drive_side || !ch.master.is_enabled() {
                // The drive stops on its own: the setpoint follows it (no jump at re-enable).
                ch.track_actual();
                ch.stopped = !ch.master.is_enabled();
            } else if let Some(p) = &ch.profile {
                // A profile axis halts on the drive's own deceleration (605Dh).
                ch.stopped = p.at_rest();
                ch.track_actual();
            } else {
                ch.stop_step(period);
            }
        }
        if self.axes.iter().all(|a| a.stopped) {
            self.event(EventKind::StopFinished, NO_AXIS, 0);
            match self.stop_reason {
                Some(StopReason::Command) => {
                    self.stop_reason = None;
                    self.set_state(CellState::Idle)
                }
                Some(StopReason::DriveFault) => self.enter_faulted(),
                _ => self.set_state(CellState::Stopped),
            }
        }
    }
}
