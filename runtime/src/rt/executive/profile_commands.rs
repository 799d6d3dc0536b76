//! The executive's side of profile axes: takes their drive-side motions from the hand-off,
//! writes the profile objects the RxPDO lacks by SDO, runs each axis' `ProfileChannel` in the
//! outputs and joins the cell's stop (`profile_axis`).

use std::sync::atomic::Ordering;

use cellrt_cia402::bus::{AcyclicBus, CyclicBus, SdoData, SdoRequest};
use cellrt_cia402::pdo::RxPdo;

use super::acyclic::Pending;
use super::profile_axis::ProfileEnd;
use super::Executive;
use crate::handoff::{CellState, EventKind, ProfileCommand, ProfileMotion};

/// Profile commands taken per cycle at most.
const PROFILE_COMMANDS_PER_CYCLE: usize = 4;

/// `profile_finished` values.
pub(super) const FINISHED_DONE: i64 = 0;
pub(super) const FINISHED_REFUSED: i64 = 1;
const FINISHED_CANCELLED: i64 = 2;
const FINISHED_SUPERSEDED: i64 = 3;

impl<B: CyclicBus + AcyclicBus> Executive<B> {
    /// Applies a changed feed override to the profile axes (`ProfileChannel::set_feed`), then
    /// takes the drive-side motions sent for profile axes: each waits for its start cycle (one
    /// per axis; a newer one supersedes it), then starts on an enabled profile axis while the
    /// cell is idle or moving, refused otherwise (`profile_finished`, value 1); then posts the
    /// next profile object a starting motion needs by SDO.
    pub(super) fn take_profile_commands(&mut self) {
        let feed = self.handoff.feed_override_permille().min(1000);
        if feed != self.feed_permille {
            self.feed_permille = feed;
            let f = f64::from(feed) / 1000.0;
            for p in self.axes.iter_mut().filter_map(|ch| ch.profile.as_mut()) {
                p.set_feed(f);
            }
        }
        for _ in 0..PROFILE_COMMANDS_PER_CYCLE {
            let Some(cmd) = self.handoff.next_profile_command() else {
                break;
            };
            let i = usize::from(cmd.axis);
            if i >= self.axes.len() {
                self.event(EventKind::ProfileFinished, cmd.axis, FINISHED_REFUSED);
                continue;
            }
            if self.profile_pending[i].replace(cmd).is_some() {
                self.profile_finished(i, FINISHED_SUPERSEDED);
            }
        }
        for i in 0..self.axes.len() {
            if let Some(cmd) = self.profile_pending[i].filter(|c| c.start_cycle <= self.cycle) {
                self.profile_pending[i] = None;
                self.start_profile(cmd);
            }
        }
        for i in 0..self.axes.len() {
            self.post_profile_object(i);
        }
    }

    fn start_profile(&mut self, cmd: ProfileCommand) {
        let i = usize::from(cmd.axis);
        if let ProfileMotion::SwitchMode(to) = cmd.motion {
            if self.start_mode_switch(i, to) {
                self.event(EventKind::ProfileStarted, cmd.axis, cmd.motion.code());
            } else {
                self.profile_finished(i, FINISHED_REFUSED);
            }
            return;
        }
        let accepting = matches!(self.state, CellState::Idle | CellState::Moving);
        let period = self.period_s;
        let mut superseded = false;
        let started = match self.axes.get_mut(i) {
            Some(ch)
                if accepting
                    && ch.powered
                    && ch.master.is_enabled()
                    && ch.mode_switch.is_none() =>
            {
                let position = ch.to_raw(ch.feedback.position_actual);
                let units = ch.drive_units;
                ch.profile.as_mut().is_some_and(|p| {
                    let busy = p.busy();
                    let ok = p.start(cmd.motion, &units, position, period).is_ok();
                    superseded = busy && ok;
                    ok
                })
            }
            _ => false,
        };
        if superseded {
            // Every motion taken ends once: the one this replaces ends here.
            self.profile_finished(i, FINISHED_SUPERSEDED);
        }
        if started {
            self.event(EventKind::ProfileStarted, cmd.axis, cmd.motion.code());
        } else {
            self.profile_finished(i, FINISHED_REFUSED);
        }
    }

    fn post_profile_object(&mut self, i: usize) {
        let Some((index, value)) = self.axes[i]
            .profile
            .as_ref()
            .filter(|p| p.writing_objects())
            .and_then(|p| p.next_sdo_object())
        else {
            return;
        };
        if self.pending[i].is_some() {
            return;
        }
        if let Some(data) = SdoData::new(&value.to_le_bytes()) {
            let write = SdoRequest::Download {
                index,
                sub: 0,
                data,
            };
            if self.post_acyclic(i, Pending::ProfileObject(index), write) {
                if let Some(p) = self.axes[i].profile.as_mut() {
                    p.posted(index, value);
                }
            } else {
                // No acyclic channel: the motion cannot get its objects.
                self.profile_object_written(i, index, false);
            }
        }
    }

    /// The SDO write of a profile object of axis `i` ended; a refused one ends the motion.
    pub(super) fn profile_object_written(&mut self, i: usize, index: u16, taken: bool) {
        let end = self.axes[i]
            .profile
            .as_mut()
            .and_then(|p| p.object_written(index, taken));
        if end == Some(ProfileEnd::Refused) {
            self.profile_finished(i, FINISHED_REFUSED);
        }
    }

    /// Axis `i`'s profile objects and controlword bits in this cycle's `rx`; the setpoint
    /// follows the drive (it moves the axis, not the setpoint stream). A motion the drive can
    /// no longer carry out (not enabled) is cancelled.
    pub(super) fn profile_outputs(&mut self, i: usize, rx: &mut RxPdo) {
        let elapsed = self.elapsed.0;
        let ch = &mut self.axes[i];
        if ch.profile.is_none() {
            return;
        }
        ch.setpoint = f64::from(ch.feedback.position_actual);
        ch.velocity = 0.0;
        ch.acceleration = 0.0;
        let raw = ch.to_raw(ch.feedback.position_actual);
        let enabled = ch.master.is_enabled();
        let sw = ch.feedback.statusword;
        let Some(p) = ch.profile.as_mut() else {
            return;
        };
        let cancelled = !enabled && p.busy();
        if cancelled {
            p.cancel();
        }
        if !enabled {
            p.forget_written();
        }
        p.follow(raw);
        let end = p.cycle(sw, rx, elapsed);
        if cancelled {
            self.profile_finished(i, FINISHED_CANCELLED);
        } else if end == Some(ProfileEnd::Done) {
            self.profile_finished(i, FINISHED_DONE);
        }
    }

    /// A drive-side motion of axis `i` ended with `outcome`: the event and the status counters
    /// (an axis index beyond the cell, from a bad command, only gets the event).
    pub(super) fn profile_finished(&mut self, i: usize, outcome: i64) {
        self.event(EventKind::ProfileFinished, i as u16, outcome);
        if let Some(live) = self
            .handoff
            .status()
            .live
            .get(i)
            .filter(|_| i < self.axes.len())
        {
            if outcome == FINISHED_REFUSED || outcome == FINISHED_CANCELLED {
                live.profile_failed.fetch_add(1, Ordering::Relaxed);
            }
            live.profile_finished.fetch_add(1, Ordering::Release);
        }
    }

    /// True while a profile axis' drive is moving it by a command of the cell.
    pub(super) fn profile_axes_moving(&self) -> bool {
        self.axes
            .iter()
            .filter_map(|ch| ch.profile.as_ref())
            .any(|p| p.moving())
    }

    /// A stop of the cell: the drive-side motions still waiting for their start cycle end
    /// unstarted (`profile_finished` 2).
    pub(super) fn cancel_pending_profiles(&mut self) {
        for i in 0..self.axes.len() {
            if self.profile_pending[i].take().is_some() {
                self.profile_finished(i, FINISHED_CANCELLED);
            }
        }
    }

    /// A controlled stop of the profile axes: each halts (605Dh) and drops its motion.
    pub(super) fn stop_profile_axes(&mut self) {
        let period = self.period_s;
        for p in self.axes.iter_mut().filter_map(|ch| ch.profile.as_mut()) {
            p.stop(period);
        }
    }
}
