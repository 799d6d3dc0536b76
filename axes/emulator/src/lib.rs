//! The drive emulators of cellrt: the simulated servo drive (`sim`: a mechanical plant under
//! a cascaded servo loop and the drive firmware around it), the in-process simulated bus
//! (`sim_bus`), the EtherCAT SubDevice emulator (`ethercat`) and the emulated MR-JE-C
//! (`mr_je_c`) with its transports, both moving their motors through one set of CiA 402 motion
//! generators (`motion`) and one device core (`device`: PDS steps, alarm history). It decodes
//! what a MainDevice sends on its own path and shares no unit conversion with the master. The
//! emulators' server threads start here.

#![warn(missing_docs)]

pub mod device;
pub mod ethercat;
pub mod motion;
pub mod mr_je_c;
pub mod sim;
pub mod sim_bus;

pub use sim::comm::CommParams;
pub use sim::drive::{HomingParams, MissedCommand, SimDrive, SimDriveParams};
pub use sim::plant::{PlantParams, ServoPlant};
pub use sim_bus::SimBus;
