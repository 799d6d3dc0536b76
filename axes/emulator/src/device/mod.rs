//! The CiA 402 device core every emulated drive shares (the simulated EtherCAT drives in
//! `sim::drive` and the emulated MR-JE-C in `mr_je_c`): what a drive keeps the same whatever
//! its model and transport, each model adding its facts as data or small hooks. The motion
//! generators are in `motion`.

pub mod alarm_history;
pub mod pds;
