//! The CiA 402 core of cellrt: the drive profile (IEC 61800-7-201) words, modes and the PDS state
//! machine on both sides, byte-exact PDO images, the drive profiles of every supported model
//! (their typed units and facts), the incremental-counter check, the bus traits every backend
//! implements, and the master's side of the FSoE safety process data.
//!
//! `controlword`/`statusword` are the two wire words (6040h/6041h), `fsa` is the drive-side state
//! machine, `master` the controller-side sequencer that drives an axis to a requested state,
//! `mode_switch` the controller-side change of the mode of operation (607Ah/60B0h rule for csp).
//! Everything called per cycle is allocation-free and lock-free. Nothing here starts a thread.

#![warn(missing_docs)]

pub mod bus;
pub mod comm;
pub mod controlword;
pub mod cycles;
pub mod drive_scaling;
pub mod error_code;
pub mod fsa;
pub mod fsoe;
pub mod homing;
pub mod master;
pub mod mode;
pub mod mode_switch;
pub mod pdo;
pub mod profiles;
pub mod shared_slice;
pub mod statusword;

pub use bus::{AcyclicBus, BusError, CyclicBus, FaultInjection, FrameCounters};
pub use comm::{
    CounterParams, CounterVerdict, Detection, DetectorParams, ErrorDetector, IncrementalCounter,
};
pub use controlword::{Command, Controlword};
pub use cycles::{CycleTime, CycleTimeError, Cycles};
pub use fsa::{drive_transition, FsaQuirks, FsaState};
pub use master::{AxisMaster, MasterParams, MasterRequest, MasterState, QuickStopSubstitute};
pub use mode::ModeOfOperation;
pub use mode_switch::{
    ModeSwitch, ModeSwitchError, ModeSwitchParams, ModeSwitchPhase, ModeSwitchProgress,
};
pub use pdo::{PdoEntry, PdoError, PdoMap, RxPdo, TxPdo};
pub use profiles::{profile, DriveModel, DriveProfile, SharedProfile};
pub use shared_slice::SharedSlice;
pub use statusword::Statusword;
