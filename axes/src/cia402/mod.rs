//! CiA 402 (IEC 61800-7-201) drive profile: words, modes and the PDS state machine on both sides.
//!
//! `controlword`/`statusword` are the two wire words (6040h/6041h), `fsa` is the drive-side state
//! machine, `master` the controller-side sequencer that drives an axis to a requested state,
//! `mode_switch` the controller-side change of the mode of operation (607Ah/60B0h rule for csp).

pub mod controlword;
pub mod error_code;
pub mod fsa;
pub mod homing;
pub mod master;
pub mod mode;
pub mod mode_switch;
pub mod statusword;
