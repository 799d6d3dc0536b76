//! cellrt runtime: the cell configuration, the RT thread and its cyclic executive, the lock-free
//! hand-offs, the iceoryx2 setpoint transport, the non-RT planner thread and the MCAP recorder.

pub mod cell_bus;
pub mod cell_lock;
pub mod config;
pub mod controller;
pub mod executive;
pub mod handoff;
pub mod link;
pub mod link_server;
pub mod motion;
pub mod operator;
pub mod planner;
pub mod program;
pub mod record;
pub mod rt;
pub mod services;
pub mod setpoints;
