//! What the integration tests of the runtime share: the RT executive on its own thread, the
//! in-process cell rig, the RT-allocation rig, reading a cell summary's event log and asking a
//! cell's operator service. Each test uses part of it.

pub mod alloc_rig;
pub mod cell_rig;
pub mod event_log;
pub mod operator;
pub mod rt_thread;
