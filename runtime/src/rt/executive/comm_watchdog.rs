//! The master side of the communication watchdog: lost frames and working-counter errors in a
//! row, SubDevices out of OP, incremental-counter errors. Each trip is one
//! `communication_error` event naming the watchdog ([`CommWatchdog`]); the cell reacts with
//! `watchdogs.communication_reaction` in the next cycle's `update_cell`.

use cellrt_cia402::bus::{AcyclicBus, BusError, CyclicBus};
use cellrt_cia402::comm::CounterVerdict;

use super::Executive;
use crate::handoff::{EventKind, NO_AXIS};
use cellrt_config::{CommWatchdog, CommWatchdogConfig};

/// Error streaks of the cyclic exchange and of each axis' link, in cycles; preallocated.
#[derive(Debug, Clone)]
pub(super) struct CommStreaks {
    config: CommWatchdogConfig,
    lost_frames: u32,
    working_counter: u32,
    out_of_op: Vec<u32>,
}

impl CommStreaks {
    /// No errors seen, for `axes` axes.
    pub(super) fn new(config: CommWatchdogConfig, axes: usize) -> Self {
        CommStreaks {
            config,
            lost_frames: 0,
            working_counter: 0,
            out_of_op: vec![0; axes],
        }
    }

    /// Counts one exchange's result; the watchdog it trips in this very exchange (once per
    /// streak: the streak's `max`-th error).
    pub(super) fn exchange(&mut self, result: Result<(), BusError>) -> Option<CommWatchdog> {
        let (lost, wkc) = match result {
            Err(BusError::FrameLost) => (true, false),
            Err(BusError::WorkingCounter { .. }) => (false, true),
            _ => (false, false),
        };
        let lost_trip = step(&mut self.lost_frames, lost, self.config.max_lost_frames);
        let wkc_trip = step(
            &mut self.working_counter,
            wkc,
            self.config.max_working_counter_errors,
        );
        if lost_trip {
            Some(CommWatchdog::LostFrames)
        } else if wkc_trip {
            Some(CommWatchdog::WorkingCounter)
        } else {
            None
        }
    }

    /// Counts one cycle of `axis`' link; true when it has been out of OP for
    /// `max_cycles_out_of_op` cycles as of this one (once per streak).
    pub(super) fn link(&mut self, axis: usize, operational: bool) -> bool {
        step(
            &mut self.out_of_op[axis],
            !operational,
            self.config.max_cycles_out_of_op,
        )
    }
}

/// Advances one streak; true at its `max`-th error in a row (`max` 0: never).
fn step(streak: &mut u32, error: bool, max: u32) -> bool {
    *streak = if error { streak.saturating_add(1) } else { 0 };
    max > 0 && *streak == max
}

impl<B: CyclicBus + AcyclicBus> Executive<B> {
    /// Records a communication watchdog's trip on `axis` ([`NO_AXIS`] for the whole segment)
    /// and has the cell react in the next `update_cell`.
    pub(super) fn comm_watchdog_tripped(&mut self, axis: u16, which: CommWatchdog) {
        if let Some(ch) = self.axes.get_mut(usize::from(axis)) {
            ch.comm_fault = true;
        }
        self.comm_fault_pending = true;
        self.event(EventKind::CommunicationError, axis, which as i64);
    }

    /// Counts this cycle's exchange result (a `bus_error` event for each failed one).
    pub(super) fn watch_exchange(&mut self, result: Result<(), BusError>) {
        if result.is_err() {
            self.event(EventKind::BusError, NO_AXIS, -1);
        }
        if let Some(which) = self.comm_streaks.exchange(result) {
            self.comm_watchdog_tripped(NO_AXIS, which);
        }
    }

    /// Checks axis `i`'s incremental-counter echo of this cycle (MR-J3-T04 manual §8.11.1):
    /// a continuous or intermittent error trips the watchdog once until a reset.
    pub(super) fn watch_counter(&mut self, i: usize, echo: u8) {
        let ch = &mut self.axes[i];
        let Some(counter) = ch.counter.as_mut() else {
            return;
        };
        let verdict = counter.check_rx(echo);
        if verdict.is_fault() && !ch.comm_fault {
            let which = match verdict {
                CounterVerdict::Continuous { .. } => CommWatchdog::CounterContinuous,
                _ => CommWatchdog::CounterIntermittent,
            };
            self.comm_watchdog_tripped(i as u16, which);
        }
    }

    /// Records a change of the link state of axis `i`'s node (EtherCAT: its SubDevice's AL
    /// status; the first state seen only if it is not operational) and counts the cycles it is
    /// not operational: `max_cycles_out_of_op` of them take the axis' outputs away, a
    /// communication fault of the axis (ETG.1000.6 §6.4).
    pub(super) fn watch_link_state(&mut self, i: usize) {
        let now = self.bus.link_state(i);
        let operational = now.is_none_or(|s| s.operational);
        if self.comm_streaks.link(i, operational) && !self.axes[i].comm_fault {
            self.comm_watchdog_tripped(i as u16, CommWatchdog::OutOfOp);
        }
        let ch = &mut self.axes[i];
        if now == ch.link_state {
            return;
        }
        let first = ch.link_state.is_none();
        ch.link_state = now;
        if let Some(s) = now.filter(|s| !(first && s.operational)) {
            self.event(EventKind::AlStatus, i as u16, s.encoded);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn streaks(lost: u32, wkc: u32, op: u32) -> CommStreaks {
        CommStreaks::new(
            CommWatchdogConfig {
                max_lost_frames: lost,
                max_working_counter_errors: wkc,
                max_cycles_out_of_op: op,
                counter: None,
            },
            2,
        )
    }

    const WKC: Result<(), BusError> = Err(BusError::WorkingCounter {
        expected: 3,
        found: 0,
    });

    #[test]
    fn lost_frames_trip_at_the_configured_count_in_a_row_once_per_streak() {
        let mut s = streaks(3, 0, 0);
        let lost = Err(BusError::FrameLost);
        // Two lost, one good: the streak starts again.
        let got: Vec<_> = [lost, lost, Ok(()), lost, lost, lost, lost]
            .into_iter()
            .map(|r| s.exchange(r))
            .collect();
        assert_eq!(
            got,
            [
                None,
                None,
                None,
                None,
                None,
                Some(CommWatchdog::LostFrames),
                None
            ]
        );
    }

    #[test]
    fn working_counter_errors_count_apart_from_lost_frames_and_zero_is_off() {
        let mut s = streaks(2, 2, 0);
        assert_eq!(s.exchange(WKC), None);
        assert_eq!(s.exchange(Err(BusError::FrameLost)), None);
        assert_eq!(s.exchange(WKC), None, "a lost frame ends the WKC streak");
        assert_eq!(s.exchange(WKC), Some(CommWatchdog::WorkingCounter));
        let mut off = streaks(0, 0, 0);
        assert!((0..1000).all(|_| off.exchange(WKC).is_none()));
    }

    #[test]
    fn out_of_op_trips_per_axis_after_the_configured_cycles() {
        let mut s = streaks(0, 0, 4);
        let got: Vec<_> = (0..6).map(|_| s.link(1, false)).collect();
        assert_eq!(got, [false, false, false, true, false, false]);
        assert!(!s.link(0, true));
        let mut first = streaks(0, 0, 1);
        assert!(first.link(0, false), "1: the first cycle out of OP");
    }
}
