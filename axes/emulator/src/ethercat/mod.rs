//! The EtherCAT SubDevice emulator: the Mitsubishi drives presented as EtherCAT SubDevices,
//! with ESC registers, SII EEPROM, CoE mailbox and process data wired to the simulated drive
//! models. Runs in-process ([`Segment::process`] on each frame) or on a network interface.

pub mod coe;
pub mod delay_line;
pub mod esi_od;
pub mod layout;
pub mod link;
pub mod schedule;
pub mod segment;
pub mod sii;
pub mod station;
pub mod variant;
pub mod wire;

pub use link::{segment_of, DelayFrames, DropFrames, InProcessLink};
pub use schedule::{FaultSchedule, ScheduledFault, WireFault};
pub use segment::{Delivery, Segment};
pub use station::{Station, UnitError};
pub use variant::{CycleTimeObject, EmulatedDc, SubDeviceVariant};

/// True if `profile` runs its PDOs at a cycle of `ns` nanoseconds (1C32h:02, SYNC0 cycle).
pub fn allows_cycle_ns(profile: &cellrt_cia402::profiles::DriveProfile, ns: u32) -> bool {
    ns.is_multiple_of(1000) && profile.cycle.cycle_times_us.contains(&(ns / 1000))
}
