//! Homing in the RT loop: a requested homing started from Idle (its method written
//! acyclically in homing mode, every axis holding meanwhile), the sequencer cycled, and the end
//! reported with the new home offset read back.

use std::sync::atomic::Ordering;

use cellrt_cia402::bus::{AcyclicBus, CyclicBus};
use cellrt_cia402::homing::{HomeProcedure, HomingFailure, HomingPhase};

use super::Executive;
use crate::handoff::{CellState, EventKind, HomeRequest, HomingStatus};

impl<B: CyclicBus + AcyclicBus> Executive<B> {
    /// In Idle: starts a requested homing. In homing mode the cell enters Homing (every axis
    /// holds) while 6098h is written acyclically; the sequencer starts when the drive took it,
    /// and a refusal is reported as a failed homing.
    pub(super) fn poll_home_request(&mut self) {
        // An operator's SDO in flight holds its axis' acyclic slot for a few cycles: the
        // request waits in the hand-off until it has ended.
        if self.user_sdo_in_flight() {
            return;
        }
        let Some(req) = self.handoff.take_home_request() else {
            return;
        };
        let axis = usize::from(req.axis);
        let seq =
            HomingStatus::decode(self.handoff.status().homing.load(Ordering::Acquire)).seq + 1;
        let mut status = HomingStatus {
            seq,
            axis: req.axis,
            running: true,
            failure: 0,
        };
        // Requests from other processes bypass `choose_procedure`: without 6061h the end of a
        // homing cannot be told from csp's bit 12, so the RT thread refuses hm there too, and
        // a Controlword2 edge where the drive has no such home setting.
        let refused = if axis >= self.axes.len() || !self.axes[axis].master.is_enabled() {
            Some(HomingFailure::NotEnabled)
        } else {
            match req.procedure {
                HomeProcedure::HomingMode(_) if !self.axes[axis].mode_display_mapped => {
                    Some(HomingFailure::MethodRefused)
                }
                // Switched to pp at run time: the sequencer would return it to csp.
                HomeProcedure::HomingMode(_) if self.axes[axis].switched_to_pp() => {
                    Some(HomingFailure::MethodRefused)
                }
                HomeProcedure::HomingMode(method) => {
                    if self.request_homing_method(axis, method) {
                        self.awaiting_method = Some(req);
                        self.set_state(CellState::Homing);
                        self.handoff
                            .status()
                            .homing
                            .store(status.encode(), Ordering::Release);
                        return;
                    }
                    Some(HomingFailure::MethodRefused)
                }
                HomeProcedure::Controlword2(_) if self.axes[axis].home_setting.is_none() => {
                    Some(HomingFailure::MethodRefused)
                }
                HomeProcedure::Controlword2(_) => None,
            }
        };
        match refused {
            // A cell-level refusal (not enabled) is reported in the status only, as before.
            Some(HomingFailure::NotEnabled) => {
                status.running = false;
                status.failure = HomingFailure::NotEnabled as u8;
            }
            Some(f) => {
                status.running = false;
                status.failure = f as u8;
                self.event(EventKind::HomingFinished, req.axis, i64::from(f as u8));
            }
            None => self.start_homing(req),
        }
        self.handoff
            .status()
            .homing
            .store(status.encode(), Ordering::Release);
    }

    /// Starts the homing sequencer of `req`'s axis; the cell is Homing.
    pub(super) fn start_homing(&mut self, req: HomeRequest) {
        let ch = &mut self.axes[usize::from(req.axis)];
        match (req.procedure, ch.home_setting) {
            (HomeProcedure::Controlword2(edge), Some(bits)) => {
                ch.homing.start_setting(edge, &bits, ch.feedback.statusword)
            }
            _ => ch.homing.start(),
        }
        self.event(EventKind::HomingStarted, req.axis, req.procedure_code());
        self.set_state(CellState::Homing);
    }

    /// One cycle of homing: the other axes hold, the homing axis follows its actual position
    /// (the drive moves it, or presets 6064h); ends when the sequencer has returned to the
    /// cyclic mode.
    pub(super) fn homing_cycle(&mut self) {
        let period = self.period_s;
        let mut done = None;
        for ch in &mut self.axes {
            if ch.homing.is_active() {
                ch.track_actual();
            } else if let HomingPhase::Done(r) = ch.homing.phase() {
                ch.track_actual();
                done = Some(r);
            } else if ch.master.is_enabled() {
                ch.hold(period);
            } else {
                ch.track_actual();
            }
        }
        self.refuse_motion();
        let Some(r) = done else {
            return;
        };
        // A drive that reports its home as 607Ch: the homing ends once it is read (posted; the
        // cell stays Homing until then), so no motion starts from the old coordinates.
        let axis = usize::from(self.homing_axis());
        if r.is_none()
            && axis < self.axes.len()
            && self.axes[axis].offset_home
            && self.request_home_offset(axis)
        {
            return;
        }
        self.end_homing(r);
        self.set_state(CellState::Idle);
    }

    /// The axis of the latest homing.
    fn homing_axis(&self) -> u16 {
        HomingStatus::decode(self.handoff.status().homing.load(Ordering::Acquire)).axis
    }

    /// Reports the homing result and clears the sequencers.
    pub(super) fn end_homing(&mut self, failure: Option<HomingFailure>) {
        let mut status = HomingStatus::decode(self.handoff.status().homing.load(Ordering::Acquire));
        for ch in &mut self.axes {
            ch.homing.clear();
        }
        self.awaiting_method = None;
        status.running = false;
        status.failure = failure.map_or(0, |f| f as u8);
        let axis = usize::from(status.axis);
        if failure.is_none() && axis < self.axes.len() {
            // Its user position moved with the homing (and 607Ch, read before).
            self.axes[axis].track_actual();
        }
        self.event(
            EventKind::HomingFinished,
            status.axis,
            i64::from(status.failure),
        );
        self.handoff
            .status()
            .homing
            .store(status.encode(), Ordering::Release);
    }
}
