//! The typed views of the RxPDO and TxPDO images and the object indexes they carry
//! (mr-j5-g-n1.md §5.2 and §6, axis-A indexes).

use crate::cia402::controlword::Controlword;
use crate::cia402::statusword::Statusword;

/// 6040h Controlword.
pub const CONTROLWORD: u16 = 0x6040;
/// 6041h Statusword.
pub const STATUSWORD: u16 = 0x6041;
/// 603Fh Error code.
pub const ERROR_CODE: u16 = 0x603F;
/// 6060h Modes of operation.
pub const MODES_OF_OPERATION: u16 = 0x6060;
/// 6061h Modes of operation display.
pub const MODES_OF_OPERATION_DISPLAY: u16 = 0x6061;
/// 6064h Position actual value.
pub const POSITION_ACTUAL: u16 = 0x6064;
/// 606Ch Velocity actual value.
pub const VELOCITY_ACTUAL: u16 = 0x606C;
/// 6071h Target torque.
pub const TARGET_TORQUE: u16 = 0x6071;
/// 6077h Torque actual value.
pub const TORQUE_ACTUAL: u16 = 0x6077;
/// 607Ah Target position.
pub const TARGET_POSITION: u16 = 0x607A;
/// 60F4h Following error actual value.
pub const FOLLOWING_ERROR: u16 = 0x60F4;
/// 60FFh Target velocity.
pub const TARGET_VELOCITY: u16 = 0x60FF;
/// 2D20h Velocity limit value (cst/tq speed limit).
pub const VELOCITY_LIMIT: u16 = 0x2D20;

/// The master's outputs of one axis, as carried by the RxPDO.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct RxPdo {
    /// 6060h Modes of operation (raw, so unsupported values reach the drive as sent).
    pub mode: i8,
    /// 6040h Controlword.
    pub controlword: Controlword,
    /// 607Ah Target position (csp).
    pub target_position: i32,
    /// 60FFh Target velocity (csv).
    pub target_velocity: i32,
    /// 2D20h Velocity limit value (cst).
    pub velocity_limit: u32,
    /// 6071h Target torque (cst).
    pub target_torque: i16,
}

/// The drive's inputs of one axis, as carried by the TxPDO.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct TxPdo {
    /// 6061h Modes of operation display (raw).
    pub mode_display: i8,
    /// 6041h Statusword.
    pub statusword: Statusword,
    /// 6064h Position actual value.
    pub position_actual: i32,
    /// 606Ch Velocity actual value.
    pub velocity_actual: i32,
    /// 60F4h Following error actual value.
    pub following_error: i32,
    /// 6077h Torque actual value.
    pub torque_actual: i16,
    /// 603Fh Error code (0 when not mapped; the default MR-J5 maps do not map it).
    pub error_code: u16,
}

/// Sign-extends the low `bits` of `raw`.
fn signed(raw: u64, bits: u16) -> i64 {
    if bits == 0 || bits >= 64 {
        return raw as i64;
    }
    let shift = 64 - u32::from(bits);
    ((raw << shift) as i64) >> shift
}

impl RxPdo {
    /// The value of object `index:sub` as raw bits (0 for objects this view does not carry).
    pub(super) fn object_value(&self, index: u16, sub: u8) -> u64 {
        if sub != 0 {
            return 0;
        }
        match index {
            MODES_OF_OPERATION => i64::from(self.mode) as u64,
            CONTROLWORD => u64::from(self.controlword.0),
            TARGET_POSITION => i64::from(self.target_position) as u64,
            TARGET_VELOCITY => i64::from(self.target_velocity) as u64,
            VELOCITY_LIMIT => u64::from(self.velocity_limit),
            TARGET_TORQUE => i64::from(self.target_torque) as u64,
            _ => 0,
        }
    }

    /// Stores raw bits of object `index:sub` (ignored when this view does not carry it).
    pub(super) fn set_object(&mut self, index: u16, sub: u8, bits: u16, raw: u64) {
        if sub != 0 {
            return;
        }
        match index {
            MODES_OF_OPERATION => self.mode = signed(raw, bits) as i8,
            CONTROLWORD => self.controlword = Controlword(raw as u16),
            TARGET_POSITION => self.target_position = signed(raw, bits) as i32,
            TARGET_VELOCITY => self.target_velocity = signed(raw, bits) as i32,
            VELOCITY_LIMIT => self.velocity_limit = raw as u32,
            TARGET_TORQUE => self.target_torque = signed(raw, bits) as i16,
            _ => {}
        }
    }
}

impl TxPdo {
    /// The value of object `index:sub` as raw bits (0 for objects this view does not carry).
    pub(super) fn object_value(&self, index: u16, sub: u8) -> u64 {
        if sub != 0 {
            return 0;
        }
        match index {
            MODES_OF_OPERATION_DISPLAY => i64::from(self.mode_display) as u64,
            STATUSWORD => u64::from(self.statusword.0),
            POSITION_ACTUAL => i64::from(self.position_actual) as u64,
            VELOCITY_ACTUAL => i64::from(self.velocity_actual) as u64,
            FOLLOWING_ERROR => i64::from(self.following_error) as u64,
            TORQUE_ACTUAL => i64::from(self.torque_actual) as u64,
            ERROR_CODE => u64::from(self.error_code),
            _ => 0,
        }
    }

    /// Stores raw bits of object `index:sub` (ignored when this view does not carry it).
    pub(super) fn set_object(&mut self, index: u16, sub: u8, bits: u16, raw: u64) {
        if sub != 0 {
            return;
        }
        match index {
            MODES_OF_OPERATION_DISPLAY => self.mode_display = signed(raw, bits) as i8,
            STATUSWORD => self.statusword = Statusword(raw as u16),
            POSITION_ACTUAL => self.position_actual = signed(raw, bits) as i32,
            VELOCITY_ACTUAL => self.velocity_actual = signed(raw, bits) as i32,
            FOLLOWING_ERROR => self.following_error = signed(raw, bits) as i32,
            TORQUE_ACTUAL => self.torque_actual = signed(raw, bits) as i16,
            ERROR_CODE => self.error_code = raw as u16,
            _ => {}
        }
    }
}
