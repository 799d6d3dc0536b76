//! The non-RT side of the controller process: the controller that starts and joins the threads,
//! the bus a cell runs on, the planner thread and its programs and motions, the link thread to
//! other processes, the operator service and the MCAP recorder. Nothing here runs on the RT
//! thread; it reaches the RT thread only through the [`crate::handoff::HostEnd`].

pub mod cell_bus;
pub mod cell_lock;
pub mod controller;
pub mod faults;
pub mod je_c;
pub mod link;
pub mod link_server;
pub mod live;
pub mod live_page;
pub mod motion;
pub mod operator;
pub mod planner;
pub mod privileges;
pub mod program;
pub mod record;
pub mod service;
