//! What the integration tests of the runtime share: the RT executive on its own thread, the
//! in-process cell rig, the RT-allocation rig and reading a cell summary's event log. Each test
//! uses part of it.

pub mod alloc_rig;
pub mod cell_rig;
pub mod event_log;
pub mod rt_thread;
