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
/// 60E0h Positive torque limit value (0.1 % of rated torque).
pub const TORQUE_LIMIT_POSITIVE: u16 = 0x60E0;
/// 60E1h Negative torque limit value (0.1 % of rated torque).
pub const TORQUE_LIMIT_NEGATIVE: u16 = 0x60E1;
/// 2020h Incremental counter (RxPDO), MR-J3-T04 (mr-j3-t04.md §6).
pub const INCREMENTAL_COUNTER_RX: u16 = 0x2020;
/// 2021h Incremental counter (TxPDO), MR-J3-T04.
pub const INCREMENTAL_COUNTER_TX: u16 = 0x2021;
/// 2D23h Watch dog counter DL (RxPDO), MR-J4-TM (mr-j4-tm.md §8.3; rule in the missing §6.2).
pub const WATCHDOG_COUNTER_DL: u16 = 0x2D23;
/// 2D24h Watch dog counter UL (TxPDO), MR-J4-TM.
pub const WATCHDOG_COUNTER_UL: u16 = 0x2D24;
/// Every object that carries [`RxPdo::counter`] / [`TxPdo::counter`].
pub const COUNTER_OBJECTS: [u16; 4] = [
    INCREMENTAL_COUNTER_RX,
    INCREMENTAL_COUNTER_TX,
    WATCHDOG_COUNTER_DL,
    WATCHDOG_COUNTER_UL,
];

/// [`RxPdo`]'s default torque limit: 10000 = 1000.0 % of rated torque, the MR-J4-TM default of
/// 60E0h/60E1h (mr-j4-tm.md §8.6), i.e. no limit below the drive's own maximum. A zero limit
/// means "no torque" (§5.2 warning), so the default image must not be zero there.
pub const DEFAULT_TORQUE_LIMIT: u16 = 10_000;

/// The master's outputs of one axis, as carried by the RxPDO.
///
/// Fields whose object the active map does not carry are not sent.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
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
    /// 6071h Target torque (cst), 0.1 % of rated torque.
    pub target_torque: i16,
    /// 60E0h Positive torque limit value, 0.1 % of rated torque (0 = no torque).
    pub torque_limit_positive: u16,
    /// 60E1h Negative torque limit value, 0.1 % of rated torque (0 = no torque).
    pub torque_limit_negative: u16,
    /// Communication counter: 2020h (MR-J3-T04) or 2D23h (MR-J4-TM), where the map carries it
    /// ([`crate::PdoMap::has_counter`]). See [`crate::IncrementalCounter`].
    pub counter: u8,
}

impl Default for RxPdo {
    /// All zero except the torque limits ([`DEFAULT_TORQUE_LIMIT`]).
    fn default() -> Self {
        RxPdo {
            mode: 0,
            controlword: Controlword::default(),
            target_position: 0,
            target_velocity: 0,
            velocity_limit: 0,
            target_torque: 0,
            torque_limit_positive: DEFAULT_TORQUE_LIMIT,
            torque_limit_negative: DEFAULT_TORQUE_LIMIT,
            counter: 0,
        }
    }
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
    /// Communication counter echo: 2021h (MR-J3-T04) or 2D24h (MR-J4-TM), where mapped.
    pub counter: u8,
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
            TORQUE_LIMIT_POSITIVE => u64::from(self.torque_limit_positive),
            TORQUE_LIMIT_NEGATIVE => u64::from(self.torque_limit_negative),
            INCREMENTAL_COUNTER_RX | WATCHDOG_COUNTER_DL => u64::from(self.counter),
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
            TORQUE_LIMIT_POSITIVE => self.torque_limit_positive = raw as u16,
            TORQUE_LIMIT_NEGATIVE => self.torque_limit_negative = raw as u16,
            INCREMENTAL_COUNTER_RX | WATCHDOG_COUNTER_DL => self.counter = raw as u8,
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
            INCREMENTAL_COUNTER_TX | WATCHDOG_COUNTER_UL => u64::from(self.counter),
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
            INCREMENTAL_COUNTER_TX | WATCHDOG_COUNTER_UL => self.counter = raw as u8,
            _ => {}
        }
    }
}
