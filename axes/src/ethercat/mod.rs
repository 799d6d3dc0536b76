//! EtherCAT: the wire format, the ESC registers, the drive identities, the SubDevice emulator
//! and the MainDevice backend (ethercrab for bring-up, cellrt's own cyclic frame in OP).

pub mod emergency;
pub mod emulator;
pub mod frame;
pub mod identity;
pub mod master;
pub mod raw_socket;
pub mod register;
