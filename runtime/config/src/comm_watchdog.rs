//! The master's communication watchdog (`[watchdogs]` `max_lost_frames`,
//! `max_working_counter_errors`, `max_cycles_out_of_op`, `counter_*`): thresholds in cycles at
//! which the RT thread stops the cell with `communication_reaction`, and the names of the
//! watchdogs as the recording shows them.

use cellrt_cia402::comm::{CounterParams, DetectorParams};

/// Thresholds of the communication watchdog, in cycles; 0 turns a threshold off.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CommWatchdogConfig {
    /// Cyclic frames lost in a row (not back within `ethercat.frame_timeout_us`).
    pub max_lost_frames: u32,
    /// Cyclic frames in a row that returned with a wrong working counter.
    pub max_working_counter_errors: u32,
    /// Cycles in a row an axis' SubDevice reports itself out of OP (or OP with its error bit).
    pub max_cycles_out_of_op: u32,
    /// Incremental-counter error levels for every axis with a counter mapped; `None` takes each
    /// model's own (`CommCheck::master_counter`).
    pub counter: Option<DetectorParams>,
}

/// Default of `watchdogs.max_lost_frames`: the sync-error counters of MR-JET and MR-J5
/// (+3 per lost frame against a limit of 4, ETG.1020) alarm after the second; the master
/// stops the cell on the third at the latest.
pub const DEFAULT_MAX_LOST_FRAMES: u32 = 3;
/// Default of `watchdogs.max_working_counter_errors` (as lost frames: no process data).
pub const DEFAULT_MAX_WORKING_COUNTER_ERRORS: u32 = 3;
/// Default of `watchdogs.max_cycles_out_of_op`: the first cycle out of OP.
pub const DEFAULT_MAX_CYCLES_OUT_OF_OP: u32 = 1;

impl Default for CommWatchdogConfig {
    fn default() -> Self {
        CommWatchdogConfig {
            max_lost_frames: DEFAULT_MAX_LOST_FRAMES,
            max_working_counter_errors: DEFAULT_MAX_WORKING_COUNTER_ERRORS,
            max_cycles_out_of_op: DEFAULT_MAX_CYCLES_OUT_OF_OP,
            counter: None,
        }
    }
}

impl CommWatchdogConfig {
    /// The incremental-counter check of an axis whose model checks `model` by default.
    pub fn counter_params(&self, model: CounterParams) -> CounterParams {
        CounterParams {
            detector: self.counter.unwrap_or(model.detector),
            ..model
        }
    }
}

/// Which communication watchdog stopped the cell: the value of a `communication_error` event
/// (`as i64`), named in the recording by its `[watchdogs]` key.
#[derive(Debug, Clone, Copy, PartialEq, Eq, strum::FromRepr)]
#[repr(u8)]
pub enum CommWatchdog {
    /// Incremental-counter echo wrong `counter_continuous_errors` times in a row.
    CounterContinuous = 1,
    /// Incremental-counter echo wrong `counter_intermittent_errors` times within the window.
    CounterIntermittent = 2,
    /// `max_lost_frames` cyclic frames lost in a row.
    LostFrames = 3,
    /// `max_working_counter_errors` frames in a row with a wrong working counter.
    WorkingCounter = 4,
    /// A SubDevice out of OP for `max_cycles_out_of_op` cycles.
    OutOfOp = 5,
}

impl CommWatchdog {
    /// Inverse of `as i64`.
    pub fn from_code(code: i64) -> Option<CommWatchdog> {
        u8::try_from(code).ok().and_then(Self::from_repr)
    }

    /// What tripped, naming the `[watchdogs]` key that sets its threshold.
    pub fn describe(self) -> &'static str {
        match self {
            Self::CounterContinuous => {
                "continuous incremental-counter errors (watchdogs.counter_continuous_errors)"
            }
            Self::CounterIntermittent => {
                "intermittent incremental-counter errors (watchdogs.counter_intermittent_errors)"
            }
            Self::LostFrames => "cyclic frames lost in a row (watchdogs.max_lost_frames)",
            Self::WorkingCounter => {
                "working-counter errors in a row (watchdogs.max_working_counter_errors)"
            }
            Self::OutOfOp => "SubDevice out of OP (watchdogs.max_cycles_out_of_op)",
        }
    }
}
