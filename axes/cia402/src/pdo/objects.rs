//! The typed views of the RxPDO and TxPDO images and the object indexes they carry
//! (MR-J5-G-N1 manual §4.3 and §6, axis-A indexes).

use crate::controlword::Controlword;
use crate::statusword::Statusword;

/// 6040h Controlword.
pub const CONTROLWORD: u16 = 0x6040;
/// 6041h Statusword.
pub const STATUSWORD: u16 = 0x6041;
/// 603Fh Error code.
pub const ERROR_CODE: u16 = 0x603F;
/// 2001h Controlword2 (MR-J3-T04 control inputs C_TL, C_TL1, C_MSTOP…; MR-J3-T04 manual §8.4.1(3)).
pub const CONTROLWORD2: u16 = 0x2001;
/// 2011h Statusword2 (MR-J3-T04 status outputs S_ZPAS, S_OSET…; MR-J3-T04 manual §8.4.1(3)).
pub const STATUSWORD2: u16 = 0x2011;
/// 2D11h–2D13h Status DO 1–3 (MR-J4-TM manual §5.3.2, MR-J5-G-N1 manual §7.3).
pub const STATUS_DO: [u16; 3] = [0x2D11, 0x2D12, 0x2D13];
/// 6060h Modes of operation.
pub const MODES_OF_OPERATION: u16 = 0x6060;
/// 6061h Modes of operation display.
pub const MODES_OF_OPERATION_DISPLAY: u16 = 0x6061;
/// 6062h Position demand value.
pub const POSITION_DEMAND: u16 = 0x6062;
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
/// 6098h Homing method (written by SDO before a homing).
pub const HOMING_METHOD: u16 = 0x6098;
/// 607Ch Home offset.
pub const HOME_OFFSET: u16 = 0x607C;
/// 60FFh Target velocity.
pub const TARGET_VELOCITY: u16 = 0x60FF;
/// 6081h Profile velocity (pp; MR-J4-TM manual §5.4.6).
pub const PROFILE_VELOCITY: u16 = 0x6081;
/// 6083h Profile acceleration (pp/pv; a time constant in ms on the Mitsubishi drives, §4.7).
pub const PROFILE_ACCELERATION: u16 = 0x6083;
/// 6084h Profile deceleration (pp/pv; a time constant in ms, §4.7).
pub const PROFILE_DECELERATION: u16 = 0x6084;
/// 6087h Torque slope (tq; 0.1 %/s, MR-J4-TM manual §5.4.8).
pub const TORQUE_SLOPE: u16 = 0x6087;
/// The profile objects a profile axis' motion sets, in this order wherever they are listed
/// together (the hand-off's records, the recording, `cellrt replay`).
pub const PROFILE_OBJECTS: [u16; 4] = [
    PROFILE_VELOCITY,
    PROFILE_ACCELERATION,
    PROFILE_DECELERATION,
    TORQUE_SLOPE,
];
/// 607Fh Max profile velocity (pp/pv; velocity unit, MR-J4-TM manual §5.4.6).
pub const MAX_PROFILE_VELOCITY: u16 = 0x607F;
/// 6080h Max motor speed (r/min on the Mitsubishi drives, MR-J4-TM manual §4.2).
pub const MAX_MOTOR_SPEED: u16 = 0x6080;
/// 6085h Quick stop deceleration (a time constant in ms on the Mitsubishi drives).
pub const QUICK_STOP_DECELERATION: u16 = 0x6085;
/// 607Dh Software position limit (sub 1 min, sub 2 max; pp, MR-J4-TM manual §5.4.6).
pub const SOFTWARE_POSITION_LIMIT: u16 = 0x607D;
/// 6067h Position window (pp target reached, MR-J4-TM manual §5.4.6).
pub const POSITION_WINDOW: u16 = 0x6067;
/// 6068h Position window time, ms.
pub const POSITION_WINDOW_TIME: u16 = 0x6068;
/// 605Ah Quick stop option code (1–4: the stop ends in Switch on disabled; 5–8: it stays in
/// Quick stop active, MR-JET-G-N1 manual §7.1).
pub const QUICK_STOP_OPTION: u16 = 0x605A;
/// 605Dh Halt option code.
pub const HALT_OPTION_CODE: u16 = 0x605D;
/// 60B0h Position offset (csp: the command is 607Ah + 60B0h; MR-J5-G-N1 manual §7.4 rule 2).
pub const POSITION_OFFSET: u16 = 0x60B0;
/// 2D20h Velocity limit value (cst/tq speed limit).
pub const VELOCITY_LIMIT: u16 = 0x2D20;
/// 60E0h Positive torque limit value (0.1 % of rated torque).
pub const TORQUE_LIMIT_POSITIVE: u16 = 0x60E0;
/// 60E1h Negative torque limit value (0.1 % of rated torque).
pub const TORQUE_LIMIT_NEGATIVE: u16 = 0x60E1;
/// 2020h Incremental counter (RxPDO), MR-J3-T04 (MR-J3-T04 manual §8.11.1, §5.1, §8.2.3, §7).
pub const INCREMENTAL_COUNTER_RX: u16 = 0x2020;
/// 2021h Incremental counter (TxPDO), MR-J3-T04.
pub const INCREMENTAL_COUNTER_TX: u16 = 0x2021;
/// 2D23h Watch dog counter DL (RxPDO), MR-J4-TM (MR-J4-TM manual §6.2; rule in the missing §6.2).
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
/// 60E0h/60E1h (MR-J4-TM manual §5.9), i.e. no limit below the drive's own maximum. A zero limit
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
    /// 2001h Controlword2 (MR-J3-T04; bit 3 C_TL, bit 4 C_TL1: torque-limit selection).
    pub controlword2: u16,
    /// 6081h Profile velocity (pp), where the map carries it (e.g. MR-J4-TM 1601h).
    pub profile_velocity: u32,
    /// 6083h Profile acceleration (pp), where the map carries it.
    pub profile_acceleration: u32,
    /// 6084h Profile deceleration (pp), where the map carries it.
    pub profile_deceleration: u32,
    /// 6087h Torque slope (tq), 0.1 %/s, where the map carries it (e.g. MR-J4-TM 1601h).
    pub torque_slope: u32,
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
            controlword2: 0,
            profile_velocity: 0,
            profile_acceleration: 0,
            profile_deceleration: 0,
            torque_slope: 0,
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
    /// The image's other objects, the ones a profile's TxPDO map adds to CiA 402 (a vendor's
    /// communication counter, statusword2, Status DO words), by object index.
    pub extras: TxExtras,
}

impl TxPdo {
    /// The raw value of object `index` (sub 0) among [`TxPdo::extras`], if the image carries it.
    #[inline]
    pub fn extra(&self, index: u16) -> Option<u64> {
        self.extras.get(index, 0)
    }

    /// The 16-bit object `index` (sub 0) among [`TxPdo::extras`]; 0 where the image does not
    /// carry it (statusword2 2011h, the Status DO words).
    #[inline]
    pub fn extra_word(&self, index: u16) -> u16 {
        self.extra(index).map_or(0, |v| v as u16)
    }
}

/// Most objects a [`TxPdo`] carries besides its CiA 402 fields (the Mitsubishi maps carry at
/// most five: a counter, a frame ID, statusword2 or Status DO 1–3).
pub const MAX_TX_EXTRAS: usize = 8;

/// One object of [`TxExtras`]: its index, sub-index and raw value.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct ExtraObject {
    /// Object index.
    pub index: u16,
    /// Sub-index.
    pub sub: u8,
    /// The raw bits, zero-extended: at most 32 ([`crate::PdoLayout`] refuses a wider extra
    /// object), so the table stays small in an image copied every cycle.
    pub value: u32,
}

/// The objects of a TxPDO image that are not CiA 402 fields of [`TxPdo`], by object index: a
/// fixed-size table (no allocation), filled by a [`crate::PdoLayout`] from the profile's map or
/// set by a drive that sends them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct TxExtras {
    len: u8,
    slots: [ExtraObject; MAX_TX_EXTRAS],
}

/// A [`TxExtras`] already holding [`MAX_TX_EXTRAS`] objects.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("a TxPDO image carries at most {MAX_TX_EXTRAS} objects besides CiA 402; {index:04X}h:{sub} does not fit")]
pub struct TxExtrasFull {
    /// The object that did not fit.
    pub index: u16,
    /// Its sub-index.
    pub sub: u8,
}

impl TxExtras {
    /// The objects held, in the order first set.
    #[inline]
    pub fn objects(&self) -> &[ExtraObject] {
        &self.slots[..usize::from(self.len)]
    }

    /// The raw value of `index:sub`, if held.
    #[inline]
    pub fn get(&self, index: u16, sub: u8) -> Option<u64> {
        self.objects()
            .iter()
            .find(|o| o.index == index && o.sub == sub)
            .map(|o| u64::from(o.value))
    }

    /// Sets `index:sub` to `value` (its low 32 bits: extra objects are at most 32 bits wide),
    /// adding the object if it is not held yet.
    #[inline]
    pub fn set(&mut self, index: u16, sub: u8, value: u64) -> Result<(), TxExtrasFull> {
        let value = value as u32;
        let len = usize::from(self.len);
        if let Some(o) = self.slots[..len]
            .iter_mut()
            .find(|o| o.index == index && o.sub == sub)
        {
            o.value = value;
            return Ok(());
        }
        let slot = self.slots.get_mut(len).ok_or(TxExtrasFull { index, sub })?;
        *slot = ExtraObject { index, sub, value };
        self.len += 1;
        Ok(())
    }
}

/// Sign-extends the low `bits` of `raw`.
fn signed(raw: u64, bits: u16) -> i64 {
    if bits == 0 || bits >= 64 {
        return raw as i64;
    }
    let shift = 64 - u32::from(bits);
    ((raw << shift) as i64) >> shift
}

/// The fields of [`RxPdo`], each resolved once from its object index by a [`crate::PdoLayout`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RxField {
    /// [`MODES_OF_OPERATION`].
    Mode,
    /// [`CONTROLWORD`].
    Controlword,
    /// [`TARGET_POSITION`].
    TargetPosition,
    /// [`TARGET_VELOCITY`].
    TargetVelocity,
    /// [`VELOCITY_LIMIT`].
    VelocityLimit,
    /// [`TARGET_TORQUE`].
    TargetTorque,
    /// [`TORQUE_LIMIT_POSITIVE`].
    TorqueLimitPositive,
    /// [`TORQUE_LIMIT_NEGATIVE`].
    TorqueLimitNegative,
    /// [`CONTROLWORD2`].
    Controlword2,
    /// [`PROFILE_VELOCITY`].
    ProfileVelocity,
    /// [`PROFILE_ACCELERATION`].
    ProfileAcceleration,
    /// [`PROFILE_DECELERATION`].
    ProfileDeceleration,
    /// [`TORQUE_SLOPE`].
    TorqueSlope,
    /// [`INCREMENTAL_COUNTER_RX`] or [`WATCHDOG_COUNTER_DL`].
    Counter,
}

impl RxField {
    /// The field carrying object `index:sub`, if [`RxPdo`] has one.
    pub fn of(index: u16, sub: u8) -> Option<Self> {
        if sub != 0 {
            return None;
        }
        Some(match index {
            MODES_OF_OPERATION => RxField::Mode,
            CONTROLWORD => RxField::Controlword,
            TARGET_POSITION => RxField::TargetPosition,
            TARGET_VELOCITY => RxField::TargetVelocity,
            VELOCITY_LIMIT => RxField::VelocityLimit,
            TARGET_TORQUE => RxField::TargetTorque,
            TORQUE_LIMIT_POSITIVE => RxField::TorqueLimitPositive,
            TORQUE_LIMIT_NEGATIVE => RxField::TorqueLimitNegative,
            CONTROLWORD2 => RxField::Controlword2,
            PROFILE_VELOCITY => RxField::ProfileVelocity,
            PROFILE_ACCELERATION => RxField::ProfileAcceleration,
            PROFILE_DECELERATION => RxField::ProfileDeceleration,
            TORQUE_SLOPE => RxField::TorqueSlope,
            INCREMENTAL_COUNTER_RX | WATCHDOG_COUNTER_DL => RxField::Counter,
            _ => return None,
        })
    }
}

/// The CiA 402 fields of [`TxPdo`], each resolved once from its object index by a
/// [`crate::PdoLayout`] (the image's other objects go to [`TxPdo::extras`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TxField {
    /// [`MODES_OF_OPERATION_DISPLAY`].
    ModeDisplay,
    /// [`STATUSWORD`].
    Statusword,
    /// [`POSITION_ACTUAL`].
    PositionActual,
    /// [`VELOCITY_ACTUAL`].
    VelocityActual,
    /// [`FOLLOWING_ERROR`].
    FollowingError,
    /// [`TORQUE_ACTUAL`].
    TorqueActual,
    /// [`ERROR_CODE`].
    ErrorCode,
}

impl TxField {
    /// The field carrying object `index:sub`, if [`TxPdo`] has one.
    pub fn of(index: u16, sub: u8) -> Option<Self> {
        if sub != 0 {
            return None;
        }
        Some(match index {
            MODES_OF_OPERATION_DISPLAY => TxField::ModeDisplay,
            STATUSWORD => TxField::Statusword,
            POSITION_ACTUAL => TxField::PositionActual,
            VELOCITY_ACTUAL => TxField::VelocityActual,
            FOLLOWING_ERROR => TxField::FollowingError,
            TORQUE_ACTUAL => TxField::TorqueActual,
            ERROR_CODE => TxField::ErrorCode,
            _ => return None,
        })
    }
}

impl RxPdo {
    /// The value of `field` as raw bits (sign-extended).
    #[inline]
    pub fn get(&self, field: RxField) -> u64 {
        match field {
            RxField::Mode => i64::from(self.mode) as u64,
            RxField::Controlword => u64::from(self.controlword.0),
            RxField::TargetPosition => i64::from(self.target_position) as u64,
            RxField::TargetVelocity => i64::from(self.target_velocity) as u64,
            RxField::VelocityLimit => u64::from(self.velocity_limit),
            RxField::TargetTorque => i64::from(self.target_torque) as u64,
            RxField::TorqueLimitPositive => u64::from(self.torque_limit_positive),
            RxField::TorqueLimitNegative => u64::from(self.torque_limit_negative),
            RxField::Controlword2 => u64::from(self.controlword2),
            RxField::ProfileVelocity => u64::from(self.profile_velocity),
            RxField::ProfileAcceleration => u64::from(self.profile_acceleration),
            RxField::ProfileDeceleration => u64::from(self.profile_deceleration),
            RxField::TorqueSlope => u64::from(self.torque_slope),
            RxField::Counter => u64::from(self.counter),
        }
    }

    /// Stores the raw bits of a `bits`-wide object into `field`.
    #[inline]
    pub fn set(&mut self, field: RxField, bits: u16, raw: u64) {
        match field {
            RxField::Mode => self.mode = signed(raw, bits) as i8,
            RxField::Controlword => self.controlword = Controlword(raw as u16),
            RxField::TargetPosition => self.target_position = signed(raw, bits) as i32,
            RxField::TargetVelocity => self.target_velocity = signed(raw, bits) as i32,
            RxField::VelocityLimit => self.velocity_limit = raw as u32,
            RxField::TargetTorque => self.target_torque = signed(raw, bits) as i16,
            RxField::TorqueLimitPositive => self.torque_limit_positive = raw as u16,
            RxField::TorqueLimitNegative => self.torque_limit_negative = raw as u16,
            RxField::Controlword2 => self.controlword2 = raw as u16,
            RxField::ProfileVelocity => self.profile_velocity = raw as u32,
            RxField::ProfileAcceleration => self.profile_acceleration = raw as u32,
            RxField::ProfileDeceleration => self.profile_deceleration = raw as u32,
            RxField::TorqueSlope => self.torque_slope = raw as u32,
            RxField::Counter => self.counter = raw as u8,
        }
    }
}

impl TxPdo {
    /// The value of `field` as raw bits (sign-extended).
    #[inline]
    pub fn get(&self, field: TxField) -> u64 {
        match field {
            TxField::ModeDisplay => i64::from(self.mode_display) as u64,
            TxField::Statusword => u64::from(self.statusword.0),
            TxField::PositionActual => i64::from(self.position_actual) as u64,
            TxField::VelocityActual => i64::from(self.velocity_actual) as u64,
            TxField::FollowingError => i64::from(self.following_error) as u64,
            TxField::TorqueActual => i64::from(self.torque_actual) as u64,
            TxField::ErrorCode => u64::from(self.error_code),
        }
    }

    /// Stores the raw bits of a `bits`-wide object into `field`.
    #[inline]
    pub fn set(&mut self, field: TxField, bits: u16, raw: u64) {
        match field {
            TxField::ModeDisplay => self.mode_display = signed(raw, bits) as i8,
            TxField::Statusword => self.statusword = Statusword(raw as u16),
            TxField::PositionActual => self.position_actual = signed(raw, bits) as i32,
            TxField::VelocityActual => self.velocity_actual = signed(raw, bits) as i32,
            TxField::FollowingError => self.following_error = signed(raw, bits) as i32,
            TxField::TorqueActual => self.torque_actual = signed(raw, bits) as i16,
            TxField::ErrorCode => self.error_code = raw as u16,
        }
    }
}
