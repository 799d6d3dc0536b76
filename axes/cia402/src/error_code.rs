//! CiA 402 error codes (603Fh) that cellrt reports where a drive manual names none (CiA 402-2
//! error code table, CiA 301 §7.2.7.3.1).

/// 8611h "Following error".
pub const FOLLOWING_ERROR: u16 = 0x8611;
/// 8400h "Velocity speed controller", the overspeed class.
pub const OVERSPEED: u16 = 0x8400;
