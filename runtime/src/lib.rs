//! cellrt runtime: the RT thread and its cyclic executive, the lock-free
//! hand-offs, the iceoryx2 setpoint transport, the non-RT planner thread and the MCAP recorder.
//!
//! The folders follow the RT boundary: [`rt`] is what runs on the RT thread (and nothing else
//! runs there), [`handoff`] is the only way in and out of it (an RT end and a host end), and
//! [`host`] is every non-RT thread of the controller process. [`setpoints`] and [`services`] are
//! shared declarations: the setpoint payload and the iceoryx2 services; the cell's configuration
//! is the crate `cellrt-config` below this one.

pub mod handoff;
pub mod host;
pub mod output_file;
pub mod rt;
pub mod runtime_dir;
pub mod services;
pub mod setpoints;
pub mod shm_guard;
