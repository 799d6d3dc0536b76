//! CiA 402, drive profiles, PDO images, simulated drives and bus backends.
//!
//! `cia402` holds the wire words and both state machines, `pdo` the byte-exact images,
//! `profiles` one module per drive model, `sim` the simulated servo drive, `bus` the backends,
//! `fsoe` the master's side of the FSoE safety process data.
//! Everything called per cycle is allocation-free and lock-free.

#![warn(missing_docs)]

pub mod bus;
pub mod cclink_ief_basic;
pub mod cia402;
pub mod comm;
pub mod cycles;
pub mod drive_scaling;
pub mod esi;
pub mod ethercat;
pub mod fsoe;
pub mod modbus;
pub mod mr_je_c;
pub mod pdo;
pub mod profiles;
mod reply_read;
pub mod sim;
pub mod slmp;

pub use bus::{AcyclicBus, BusError, CyclicBus, FaultInjection, FrameCounters, SimBus};
pub use cia402::controlword::{Command, Controlword};
pub use cia402::fsa::{drive_transition, FsaQuirks, FsaState};
pub use cia402::master::{
    AxisMaster, MasterParams, MasterRequest, MasterState, QuickStopSubstitute,
};
pub use cia402::mode::ModeOfOperation;
pub use cia402::mode_switch::{
    ModeSwitch, ModeSwitchError, ModeSwitchParams, ModeSwitchPhase, ModeSwitchProgress,
};
pub use cia402::statusword::Statusword;
pub use comm::{
    CounterParams, CounterVerdict, Detection, DetectorParams, ErrorDetector, IncrementalCounter,
};
pub use cycles::{CycleTime, CycleTimeError, Cycles};
pub use pdo::{PdoEntry, PdoError, PdoMap, RxPdo, TxPdo};
pub use profiles::{profile, DriveModel, DriveProfile};
pub use sim::comm::CommParams;
pub use sim::drive::{HomingParams, MissedCommand, SimDrive, SimDriveParams};
pub use sim::plant::{PlantParams, ServoPlant};
