//! Cyclic communication checks shared by the master and the simulated drives: the consecutive /
//! intermittent error detector and the master side of the MR-J3-T04 incremental counter.
//!
//! The MR-J3-T04 manual says a counter error raises its alarm when it happens "consecutively or
//! frequently more than a regulated level" without giving the level (MR-J3-T04 manual §8.11.1, §5.1, §8.2.3, §7, errata
//! #3). The thresholds are therefore named parameters; each model's profile states its
//! defaults (`CommCheck::master_counter`), documented as placeholders where the manual is
//! silent, and `[watchdogs]` may override them. Everything is allocation-free and clock-free.

/// Thresholds of an [`ErrorDetector`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct DetectorParams {
    /// Errors in a row that count as a continuous error (0 = continuous detection off).
    pub continuous: u32,
    /// Errors within `intermittent_window` cycles that count as intermittent (0 = off; at most
    /// [`MAX_INTERMITTENT`]).
    pub intermittent: u8,
    /// The sliding window of the intermittent check, in cycles.
    pub intermittent_window: u32,
}

/// The thresholds cellrt uses where a manual raises a counter alarm "consecutively or
/// frequently more than a regulated level" without the level (MR-J3-T04 manual §8.11.1,
/// errata #3): 3 in a row, or 3 within 1000 cycles. **Placeholders**, overridable per cell.
pub const UNSTATED_LEVEL: DetectorParams = DetectorParams {
    continuous: 3,
    intermittent: 3,
    intermittent_window: 1000,
};

/// Largest supported [`DetectorParams::intermittent`].
pub const MAX_INTERMITTENT: u8 = 16;

/// What an [`ErrorDetector`] concluded this cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Detection {
    /// No threshold reached.
    None,
    /// `continuous` errors in a row.
    Continuous,
    /// `intermittent` errors within the window (not in a row long enough to be continuous).
    Intermittent,
}

/// Counts bad cycles and reports continuous and intermittent errors; one call per cycle.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ErrorDetector {
    params: DetectorParams,
    consecutive: u32,
    /// Cycle numbers of the most recent errors (ring).
    recent: [u64; MAX_INTERMITTENT as usize],
    head: usize,
    count: usize,
    now: u64,
}

impl ErrorDetector {
    /// A detector with no errors seen.
    pub fn new(params: DetectorParams) -> Self {
        ErrorDetector {
            params,
            consecutive: 0,
            recent: [0; MAX_INTERMITTENT as usize],
            head: 0,
            count: 0,
            now: 0,
        }
    }

    /// Forgets every error (e.g. after a power cycle or a new PDO start).
    pub fn reset(&mut self) {
        *self = ErrorDetector::new(self.params);
    }

    /// Errors in a row so far.
    pub fn consecutive(&self) -> u32 {
        self.consecutive
    }

    /// Records one cycle, bad or good, and returns what the thresholds say.
    pub fn record(&mut self, error: bool) -> Detection {
        let now = self.now;
        self.now += 1;
        if !error {
            self.consecutive = 0;
            return Detection::None;
        }
        self.consecutive = self.consecutive.saturating_add(1);
        self.recent[self.head] = now;
        self.head = (self.head + 1) % self.recent.len();
        self.count = (self.count + 1).min(self.recent.len());
        if self.params.continuous > 0 && self.consecutive >= self.params.continuous {
            return Detection::Continuous;
        }
        let n = usize::from(self.params.intermittent.min(MAX_INTERMITTENT));
        if n > 0 && self.count >= n {
            // The n-th most recent error.
            let idx = (self.head + self.recent.len() - n) % self.recent.len();
            if now - self.recent[idx] < u64::from(self.params.intermittent_window) {
                return Detection::Intermittent;
            }
        }
        Detection::None
    }
}

/// Parameters of the master-side [`IncrementalCounter`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct CounterParams {
    /// Echo lag L in cycles: the echo read after exchange k answers the value sent in exchange
    /// k − L. The manual's timing figure is lost (MR-J3-T04 manual §8.11.1, §5.1, §8.2.3, §7, errata #4); default 1, the
    /// simulator's default too. At most [`MAX_ECHO_LAG`].
    pub echo_lag: u8,
    /// Thresholds for continuous and intermittent echo errors.
    pub detector: DetectorParams,
}

/// Largest supported echo lag.
pub const MAX_ECHO_LAG: u8 = 3;

/// Echo lag L = 1 (MR-J3-T04 manual §8.11.1, §5.1, §8.2.3, §7 (inferred), configurable).
pub const DEFAULT_ECHO_LAG: u8 = 1;

/// The master's view of one received echo.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CounterVerdict {
    /// Fewer than L + 1 values sent yet: nothing to compare.
    Warmup,
    /// The echo is the expected sent value + 1.
    Ok,
    /// A wrong echo, below the thresholds.
    Mismatch {
        /// Sent value + 1.
        expected: u8,
        /// What 2021h carried.
        received: u8,
    },
    /// Continuous echo errors: take protective action (stop the axis).
    Continuous {
        /// Sent value + 1.
        expected: u8,
        /// What 2021h carried.
        received: u8,
    },
    /// Intermittent echo errors: take protective action.
    Intermittent {
        /// Sent value + 1.
        expected: u8,
        /// What 2021h carried.
        received: u8,
    },
}

impl CounterVerdict {
    /// True for [`CounterVerdict::Continuous`] and [`CounterVerdict::Intermittent`].
    pub const fn is_fault(self) -> bool {
        matches!(self, Self::Continuous { .. } | Self::Intermittent { .. })
    }
}

/// Master side of the 8-bit incremental counter (2020h out, 2021h back; MR-J3-T04 manual §8.11.1, §5.1, §8.2.3, §7).
///
/// Each cycle the RT loop calls [`IncrementalCounter::check_rx`] with the echo of the TxPDO it
/// just read, then [`IncrementalCounter::next_tx`] for the RxPDO it writes. Allocation-free.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct IncrementalCounter {
    params: CounterParams,
    /// Sent values, most recent first.
    sent: [u8; MAX_ECHO_LAG as usize + 1],
    sent_count: u32,
    detector: ErrorDetector,
    faulted: bool,
}

impl IncrementalCounter {
    /// A counter whose first sent value is `start + 1` (the manual allows any initial value).
    pub fn new(params: CounterParams, start: u8) -> Self {
        let params = CounterParams {
            echo_lag: params.echo_lag.min(MAX_ECHO_LAG),
            ..params
        };
        let mut sent = [0u8; MAX_ECHO_LAG as usize + 1];
        sent[0] = start;
        IncrementalCounter {
            params,
            sent,
            sent_count: 0,
            detector: ErrorDetector::new(params.detector),
            faulted: false,
        }
    }

    /// The value for 2020h of this cycle: the previous one + 1, wrapping 255 → 0.
    pub fn next_tx(&mut self) -> u8 {
        let v = self.sent[0].wrapping_add(1);
        self.sent.copy_within(0..MAX_ECHO_LAG as usize, 1);
        self.sent[0] = v;
        self.sent_count = self.sent_count.saturating_add(1);
        v
    }

    /// Checks the 2021h echo read this cycle (before [`IncrementalCounter::next_tx`]).
    ///
    /// Expected: the value sent L exchanges before the last one, + 1. Once a continuous or
    /// intermittent error has been reported, every later wrong echo reports it again until
    /// [`IncrementalCounter::reset`].
    pub fn check_rx(&mut self, echo: u8) -> CounterVerdict {
        let lag = usize::from(self.params.echo_lag);
        if self.sent_count <= lag as u32 {
            return CounterVerdict::Warmup;
        }
        let expected = self.sent[lag].wrapping_add(1);
        let bad = echo != expected;
        let detection = self.detector.record(bad);
        let (expected, received) = (expected, echo);
        match detection {
            Detection::Continuous => {
                self.faulted = true;
                CounterVerdict::Continuous { expected, received }
            }
            Detection::Intermittent => {
                self.faulted = true;
                CounterVerdict::Intermittent { expected, received }
            }
            Detection::None if bad => CounterVerdict::Mismatch { expected, received },
            Detection::None => CounterVerdict::Ok,
        }
    }

    /// True once a continuous or intermittent error has been reported.
    pub fn faulted(&self) -> bool {
        self.faulted
    }

    /// Restarts the check (new PDO start): keeps the next value, forgets errors and history.
    pub fn reset(&mut self) {
        let last = self.sent[0];
        *self = IncrementalCounter::new(self.params, last);
    }

    /// The parameters.
    pub fn params(&self) -> CounterParams {
        self.params
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn detector_continuous_and_intermittent() {
        let mut d = ErrorDetector::new(DetectorParams {
            continuous: 3,
            intermittent: 3,
            intermittent_window: 10,
        });
        assert_eq!(d.record(true), Detection::None);
        assert_eq!(d.record(true), Detection::None);
        assert_eq!(d.record(true), Detection::Continuous);
        d.reset();
        // Errors at cycles 0, 4, 8: the third is within a 10-cycle window of the first.
        let mut got = Vec::new();
        for k in 0..9 {
            got.push(d.record(k % 4 == 0));
        }
        assert_eq!(got[8], Detection::Intermittent);
        assert!(got[..8].iter().all(|&g| g == Detection::None));
        // Spread wider than the window: never intermittent.
        let mut d = ErrorDetector::new(DetectorParams {
            continuous: 0,
            intermittent: 2,
            intermittent_window: 5,
        });
        for k in 0..50 {
            assert_eq!(d.record(k % 5 == 0), Detection::None, "{k}");
        }
    }

    #[test]
    fn master_counter_wraps_and_checks_with_lag() {
        let mut c = IncrementalCounter::new(crate::profiles::mr_j3_t04::MASTER_COUNTER_CHECK, 252);
        assert_eq!(c.check_rx(0), CounterVerdict::Warmup);
        assert_eq!(c.next_tx(), 253);
        assert_eq!(
            c.check_rx(0),
            CounterVerdict::Warmup,
            "L = 1: one value in flight"
        );
        assert_eq!(c.next_tx(), 254);
        assert_eq!(c.check_rx(254), CounterVerdict::Ok);
        assert_eq!(c.next_tx(), 255);
        assert_eq!(c.check_rx(255), CounterVerdict::Ok);
        assert_eq!(c.next_tx(), 0);
        assert_eq!(c.check_rx(0), CounterVerdict::Ok, "255 → 0 is not an error");
        assert_eq!(c.next_tx(), 1);
        assert_eq!(
            c.check_rx(7),
            CounterVerdict::Mismatch {
                expected: 1,
                received: 7
            }
        );
    }
}
