//! The RT loop's acyclic requests: posted to the bus (EtherCAT: the mailbox worker) and
//! finished in the cycle their outcome arrives, so that no cycle waits for a mailbox. One
//! request per axis at a time, each with what it is for.

use cellrt_cia402::bus::{AcyclicBus, CyclicBus, PostError, SdoData, SdoOutcome, SdoRequest};
use cellrt_cia402::homing::HomingFailure;
use cellrt_cia402::mode::ModeOfOperation;
use cellrt_cia402::pdo::objects::{ERROR_CODE, HOME_OFFSET, HOMING_METHOD, MODES_OF_OPERATION};
use cellrt_cia402::Cycles;

use super::Executive;
use crate::handoff::{CellState, EventKind, UserSdo, UserSdoOutcome};

/// Cycles the loop's end waits at most for the requests still in flight.
const FINISH_CYCLES: u32 = 500;

/// What an axis' request in flight is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Pending {
    /// 603Fh read at a fault edge, for a map without it: the `drive_fault` event waits for it.
    ErrorCode,
    /// 6060h written, for a drive without it in its RxPDO (a homing's start and end).
    ModeChange(ModeOfOperation),
    /// 6098h written before a homing in homing mode starts.
    HomingMethod,
    /// The axis' `k`-th homing object (6099h, 609Ah, the shift) written after 6098h.
    HomingObject(u8),
    /// 607Ch read after a homing, for a drive that keeps 6064h raw: the homing ends with it.
    HomeOffset,
    /// An operator's request (`cellrt sdo`), by its sequence number: its outcome is published.
    User(u16),
    /// A profile object (6081h, 6083h, 6084h, 6087h) written before a profile axis' motion.
    ProfileObject(u16),
}

impl<B: CyclicBus + AcyclicBus> Executive<B> {
    /// Posts `request` for axis `i`, for `purpose`; false where the axis has one in flight or
    /// the bus has no acyclic channel.
    pub(super) fn post_acyclic(&mut self, i: usize, purpose: Pending, request: SdoRequest) -> bool {
        if self.pending[i].is_some() || self.bus.post_sdo(i, request).is_err() {
            return false;
        }
        self.pending[i] = Some(purpose);
        true
    }

    /// Posts the 603Fh read of a fault edge, once the axis' request in flight has ended;
    /// without an acyclic channel the fault is recorded at once with the code unknown (-1).
    pub(super) fn request_error_code(&mut self, i: usize) {
        if self.pending[i].is_some() {
            self.error_code_wanted[i] = true;
            return;
        }
        self.error_code_wanted[i] = false;
        let read = SdoRequest::Upload {
            index: ERROR_CODE,
            sub: 0,
        };
        if !self.post_acyclic(i, Pending::ErrorCode, read) {
            self.event(EventKind::DriveFault, i as u16, -1);
        }
    }

    /// Posts the 6060h write of `mode` to a drive that takes it by SDO (once in flight).
    pub(super) fn request_mode(&mut self, i: usize, mode: ModeOfOperation) {
        if let Some(data) = SdoData::new(&[mode.as_i8() as u8]) {
            let write = SdoRequest::Download {
                index: MODES_OF_OPERATION,
                sub: 0,
                data,
            };
            self.post_acyclic(i, Pending::ModeChange(mode), write);
        }
    }

    /// Posts the 6098h write of a homing request; false if it could not be posted.
    pub(super) fn request_homing_method(&mut self, i: usize, method: i8) -> bool {
        match SdoData::new(&[method as u8]) {
            Some(data) => self.post_acyclic(
                i,
                Pending::HomingMethod,
                SdoRequest::Download {
                    index: HOMING_METHOD,
                    sub: 0,
                    data,
                },
            ),
            None => false,
        }
    }

    /// Posts the 607Ch read after a homing, once the axis' request in flight (the 6060h
    /// write back to the cyclic mode) has ended; true while it is to come, false where it
    /// cannot be posted (the homing then ends without it).
    pub(super) fn request_home_offset(&mut self, i: usize) -> bool {
        if self.pending[i].is_some() {
            return true;
        }
        let read = SdoRequest::Upload {
            index: HOME_OFFSET,
            sub: 0,
        };
        self.post_acyclic(i, Pending::HomeOffset, read)
    }

    /// True while an operator's SDO request is posted on some axis.
    pub(super) fn user_sdo_in_flight(&self) -> bool {
        self.pending
            .iter()
            .any(|p| matches!(p, Some(Pending::User(_))))
    }

    /// Takes an operator's SDO request from the hand-off and posts it once its axis' slot is
    /// free (a fault's 603Fh read goes first) and no homing runs (its own requests come
    /// first); an axis without an acyclic channel (or none by that index) gets it published as
    /// unsupported.
    fn serve_user_sdo(&mut self) {
        if self.user_sdo.is_none() {
            self.user_sdo = self.handoff.take_sdo_request();
        }
        let Some(UserSdo { seq, axis, request }) = self.user_sdo else {
            return;
        };
        let i = usize::from(axis);
        if i >= self.axes.len() {
            self.user_sdo = None;
            self.handoff
                .publish_sdo_outcome(seq, UserSdoOutcome::Unsupported);
            return;
        }
        if self.pending[i].is_some() || self.error_code_wanted[i] || self.state == CellState::Homing
        {
            return;
        }
        match self.bus.post_sdo(i, request) {
            Ok(()) => {
                self.pending[i] = Some(Pending::User(seq));
                self.user_sdo = None;
            }
            Err(PostError::Busy) => {}
            Err(PostError::Unsupported) => {
                self.user_sdo = None;
                self.handoff
                    .publish_sdo_outcome(seq, UserSdoOutcome::Unsupported);
            }
        }
    }

    /// Takes the outcomes that have arrived and finishes what each was for; a fault's 603Fh
    /// read that waited for the axis' slot is posted, then an operator's request.
    pub(super) fn poll_acyclic(&mut self) {
        self.poll_outcomes();
        self.serve_user_sdo();
    }

    fn poll_outcomes(&mut self) {
        for i in 0..self.axes.len() {
            if self.error_code_wanted[i] && self.pending[i].is_none() {
                self.request_error_code(i);
            }
            let Some(purpose) = self.pending[i] else {
                continue;
            };
            let Some(outcome) = self.bus.take_sdo(i) else {
                continue;
            };
            self.pending[i] = None;
            let abort = match outcome {
                SdoOutcome::Aborted(code) => Some(code),
                _ => None,
            };
            let internal = !matches!(purpose, Pending::ErrorCode | Pending::User(_));
            if let Some(code) = abort.filter(|_| internal) {
                self.event(EventKind::BusError, i as u16, i64::from(code));
            }
            match (purpose, outcome) {
                (Pending::ErrorCode, SdoOutcome::Uploaded(v)) => {
                    self.event(EventKind::DriveFault, i as u16, i64::from(v as u16))
                }
                (Pending::ErrorCode, _) => self.event(EventKind::DriveFault, i as u16, -1),
                (Pending::ModeChange(mode), SdoOutcome::Downloaded) => {
                    self.axes[i].sdo_mode = Some(mode)
                }
                (Pending::ModeChange(_), _) => {}
                (Pending::HomingMethod, outcome) => {
                    self.homing_object_written(i, 0, outcome == SdoOutcome::Downloaded)
                }
                (Pending::HomingObject(k), outcome) => {
                    self.homing_object_written(i, k + 1, outcome == SdoOutcome::Downloaded)
                }
                (Pending::ProfileObject(index), outcome) => {
                    self.profile_object_written(i, index, outcome == SdoOutcome::Downloaded)
                }
                (Pending::User(seq), outcome) => self
                    .handoff
                    .publish_sdo_outcome(seq, UserSdoOutcome::Done(outcome)),
                (Pending::HomeOffset, outcome) => {
                    if let SdoOutcome::Uploaded(v) = outcome {
                        self.apply_home_offset(i, v as i32);
                    }
                    if self.state == CellState::Homing {
                        self.end_homing(None);
                        self.set_state(CellState::Idle);
                    }
                }
            }
        }
    }

    /// After the loop: the requests still in flight finish (a fault's 603Fh read gets its
    /// `drive_fault` event), the exchange going on at the cycle time to carry them, for at
    /// most [`FINISH_CYCLES`] cycles.
    pub(super) fn finish_acyclic(&mut self) {
        let period = std::time::Duration::from_nanos(self.period_ns);
        for _ in 0..FINISH_CYCLES {
            if self.pending.iter().all(Option::is_none) && !self.error_code_wanted.contains(&true) {
                return;
            }
            std::thread::sleep(period);
            self.cycle += 1;
            let _ = self.bus.exchange(Cycles(1));
            self.poll_outcomes();
        }
    }

    /// A homing write ended: the axis' `next` homing object is posted, or, after the last
    /// (or a refusal), the homing starts or fails.
    fn homing_object_written(&mut self, i: usize, next: u8, taken: bool) {
        let object = self.axes[i].homing_objects.get(usize::from(next));
        let Some((index, sub, value)) = object.filter(|_| taken) else {
            return self.method_written(i, taken);
        };
        let posted = SdoData::new(&value.to_le_bytes()).is_some_and(|data| {
            let write = SdoRequest::Download { index, sub, data };
            self.post_acyclic(i, Pending::HomingObject(next), write)
        });
        if !posted {
            self.method_written(i, false);
        }
    }

    /// The homing writes of the homing awaiting them ended: the homing starts, or fails as
    /// refused.
    fn method_written(&mut self, i: usize, taken: bool) {
        let Some(request) = self.awaiting_method.take() else {
            return; // the homing ended meanwhile (power off, fault)
        };
        if usize::from(request.axis) != i || self.state != CellState::Homing {
            return;
        }
        if taken {
            self.start_homing(request);
        } else {
            self.end_homing(Some(HomingFailure::MethodRefused));
            self.set_state(CellState::Idle);
        }
    }

    /// Moves axis `i`'s user coordinates with a new home offset: user = raw + 607Ch.
    pub(super) fn apply_home_offset(&mut self, i: usize, new: i32) {
        let ch = &mut self.axes[i];
        ch.feedback.position_actual = ch
            .feedback
            .position_actual
            .wrapping_sub(ch.home_offset)
            .wrapping_add(new);
        ch.home_offset = new;
    }
}
