//! The drive side of the cyclic communication checks, per model (`CommFacts::check`).
//!
//! * MR-J3-T04 (MR-J3-T04 manual §8.11.1, §5.1, §8.2.3, §7): incremental counter echo (last good received + 1, delayed by
//!   the echo lag), counter update errors against PO03 digit 0 → AL.34, RxPDO loss against PO03
//!   digit 2 → AL.36 (continuous after about 7 ms).
//! * MR-JET / MR-J5 (§2.4): a sync-error counter against 10F1h:02 → AL.086.1; the manual gives
//!   no counting rule, so the ETG.1020 convention (+3 per lost frame, −1 per good one) is used
//!   as a configurable default.
//! * MR-J4-TM (MR-J4-TM manual §6.2, §6.2 MISSING): provisional echo of 2D23h + 1 in 2D24h when both
//!   are mapped; lost frames count like the sync-error counter → AL. 86.1.

use std::time::Duration;

use cellrt_cia402::comm::{Detection, DetectorParams, ErrorDetector, MAX_ECHO_LAG};
use cellrt_cia402::cycles::CycleTime;
use cellrt_cia402::profiles::CommCheck;

/// Configuration of the drive's communication checks. Every default that the manuals leave open
/// is named here with the gap it fills.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CommParams {
    /// Echo lag L of the counter (0…3 cycles). MR-J3-T04 §6.2: figure lost, default 1.
    pub echo_lag: u8,
    /// MR-J3-T04 PO03 communication protection switch (§6.3): digit 0 (bits 0–3) = counter
    /// update error detection (0 off, 1 both, 2 continuous, 3 intermittent), digit 2
    /// (bits 8–11) = RxPDO reception error (0 both, 2 continuous only). Default 0000h.
    pub po03: u16,
    /// MR-J3-T04 PO02 synchronisation mode (§2.4): digit 0 = 0 DC mode (default), 1 free-run
    /// (test connections only; with the counter check enabled in PO03 → AL.37 at power-on).
    pub po02: u16,
    /// Counter update error thresholds (MR-J3-T04 §6.4: "regulated level" not given; placeholder).
    pub counter_errors: DetectorParams,
    /// Continuous RxPDO loss raising AL.36: "about 7 ms" (MR-J3-T04 §6.4), rounded up to whole
    /// cycles (7 at 1 ms, 14 at 0.5 ms, 4 at 2 ms).
    pub rx_loss_timeout: Duration,
    /// Intermittent RxPDO loss thresholds (`continuous` unused; level not given, placeholder).
    pub rx_loss_intermittent: DetectorParams,
    /// Sync-error counter increment per lost frame (ETG.1020 convention, not in the manuals).
    pub sync_error_increment: u32,
    /// Sync-error counter decrement per good frame (ETG.1020 convention).
    pub sync_error_decrement: u32,
    /// 10F1h:02 Sync Error Counter Limit / PN18: the alarm is raised when the counter exceeds
    /// it. Default 4 (common ETG.1020 default; the manuals give none); a value the master wrote
    /// to 10F1h:02 replaces it from the next entry into OP.
    pub sync_error_limit: u32,
    /// MR-J4-TM: echo 2D23h + 1 in 2D24h when both are mapped (provisional: §6.2 MISSING).
    pub watchdog_echo: bool,
}

impl Default for CommParams {
    fn default() -> Self {
        CommParams {
            echo_lag: cellrt_cia402::comm::DEFAULT_ECHO_LAG,
            po03: 0x0000,
            po02: 0x0000,
            counter_errors: cellrt_cia402::comm::UNSTATED_LEVEL,
            rx_loss_timeout: Duration::from_millis(7),
            rx_loss_intermittent: DetectorParams {
                continuous: 0,
                ..cellrt_cia402::comm::UNSTATED_LEVEL
            },
            sync_error_increment: 3,
            sync_error_decrement: 1,
            sync_error_limit: cellrt_cia402::profiles::generic_cia402::SYNC_ERROR_COUNTER_LIMIT
                as u32,
            watchdog_echo: true,
        }
    }
}

/// The drive-side check state.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct DriveComm {
    check: CommCheck,
    params: CommParams,
    loss_timeout_cycles: u32,
    last_rx: u8,
    have_last: bool,
    /// Echo values, most recent first (index L is sent).
    echo: [u8; MAX_ECHO_LAG as usize + 1],
    counter_errors: ErrorDetector,
    counter_intermittent: ErrorDetector,
    loss_intermittent: ErrorDetector,
    lost_in_row: u32,
    sync_errors: u32,
    counter_mapped: bool,
}

impl DriveComm {
    pub(crate) fn new(
        check: CommCheck,
        params: CommParams,
        cycle: CycleTime,
        counter_mapped: bool,
    ) -> Self {
        let params = CommParams {
            echo_lag: params.echo_lag.min(MAX_ECHO_LAG),
            ..params
        };
        DriveComm {
            check,
            params,
            loss_timeout_cycles: cycle.cycles_for(params.rx_loss_timeout).0.max(1),
            last_rx: 0,
            have_last: false,
            echo: [1; MAX_ECHO_LAG as usize + 1],
            counter_errors: ErrorDetector::new(DetectorParams {
                intermittent: 0,
                ..params.counter_errors
            }),
            counter_intermittent: ErrorDetector::new(DetectorParams {
                continuous: 0,
                ..params.counter_errors
            }),
            loss_intermittent: ErrorDetector::new(params.rx_loss_intermittent),
            lost_in_row: 0,
            sync_errors: 0,
            counter_mapped,
        }
    }

    /// Whether the PDOs carry the counter (a remapped drive may drop it).
    pub(crate) fn set_counter_mapped(&mut self, mapped: bool) {
        self.counter_mapped = mapped;
    }

    /// Restarts the checks (power cycle, new PDO start).
    pub(crate) fn reset(&mut self) {
        self.last_rx = 0;
        self.have_last = false;
        self.echo = [1; MAX_ECHO_LAG as usize + 1];
        self.counter_errors.reset();
        self.counter_intermittent.reset();
        self.loss_intermittent.reset();
        self.lost_in_row = 0;
        self.sync_errors = 0;
    }

    /// The echo to put in the TxPDO counter object.
    pub(crate) fn echo(&self) -> u8 {
        match self.check {
            CommCheck::WatchdogCounter { .. } if !self.params.watchdog_echo => 0,
            _ => self.echo[usize::from(self.params.echo_lag)],
        }
    }

    fn push_echo(&mut self) {
        self.echo.copy_within(0..MAX_ECHO_LAG as usize, 1);
        self.echo[0] = self.last_rx.wrapping_add(1);
    }

    /// An RxPDO arrived with `counter`; returns the alarm to raise, if any.
    pub(crate) fn received(&mut self, counter: u8) -> Option<u16> {
        self.lost_in_row = 0;
        self.loss_intermittent.record(false);
        let mut alarm = None;
        match self.check {
            CommCheck::IncrementalCounter { counter_alarm, .. } => {
                let bad = self.have_last && counter != self.last_rx.wrapping_add(1);
                let (cont, inter) = match self.params.po03 & 0x000F {
                    1 => (true, true),
                    2 => (true, false),
                    3 => (false, true),
                    _ => (false, false),
                };
                // Two detectors so that "intermittent only" (digit 0 = 3) also sees a run.
                let c = self.counter_errors.record(bad) == Detection::Continuous;
                let i = self.counter_intermittent.record(bad) == Detection::Intermittent;
                if ((cont && c) || (inter && i)) && self.counter_mapped {
                    alarm = Some(counter_alarm);
                }
                if self.counter_mapped {
                    self.last_rx = counter;
                    self.have_last = true;
                }
            }
            CommCheck::WatchdogCounter { .. } => {
                if self.counter_mapped {
                    self.last_rx = counter;
                }
                self.sync_errors = self
                    .sync_errors
                    .saturating_sub(self.params.sync_error_decrement);
            }
            CommCheck::SyncErrorCounter { .. } => {
                self.sync_errors = self
                    .sync_errors
                    .saturating_sub(self.params.sync_error_decrement);
            }
        }
        self.push_echo();
        alarm
    }

    /// No RxPDO this cycle; returns the alarm to raise, if any. The echo repeats last good + 1.
    pub(crate) fn lost(&mut self) -> Option<u16> {
        self.lost_in_row = self.lost_in_row.saturating_add(1);
        let alarm = match self.check {
            CommCheck::IncrementalCounter { loss_alarm, .. } => {
                let digit2 = (self.params.po03 >> 8) & 0x000F;
                let continuous = self.lost_in_row >= self.loss_timeout_cycles;
                let intermittent = self.loss_intermittent.record(true) == Detection::Intermittent;
                let hit = continuous || (digit2 == 0 && intermittent);
                hit.then_some(loss_alarm)
            }
            CommCheck::WatchdogCounter { loss_alarm: a, .. }
            | CommCheck::SyncErrorCounter { alarm: a } => {
                self.sync_errors = self
                    .sync_errors
                    .saturating_add(self.params.sync_error_increment);
                (self.sync_errors > self.params.sync_error_limit).then_some(a)
            }
        };
        self.push_echo();
        alarm
    }

    /// Sets the sync-error counter limit (10F1h:02).
    pub(crate) fn set_sync_error_limit(&mut self, limit: u32) {
        self.params.sync_error_limit = limit;
    }

    /// The sync-error counter (MR-JET/MR-J5/MR-J4-TM models).
    pub(crate) fn sync_errors(&self) -> u32 {
        self.sync_errors
    }
}
