//! The objects a controller uses most, with their Rust types (MR-JE-C manual §7.3, §7.6).

use super::super::alarm::Alarm;
use super::super::objects::ObjectId;
use super::super::types::DataType;
use super::super::value::Value;
use cellrt_cia402::{controlword::Controlword as Cw, statusword::Statusword as Sw};

/// An object with a fixed Rust type.
pub trait TypedObject {
    /// Index and sub-index.
    const ID: ObjectId;
    /// The dictionary type.
    const TYPE: DataType;
    /// The Rust type.
    type Value;
    /// The Rust value of a read value (`None`: not of the type).
    fn decode(v: &Value) -> Option<Self::Value>;
    /// The value to write.
    fn encode(v: Self::Value) -> Value;
}

macro_rules! integer_object {
    ($(#[$doc:meta])* $name:ident, $index:expr, $ty:ident, $rust:ty) => {
        $(#[$doc])*
        pub struct $name;
        integer_object_impl!($name, $index, $ty, $rust);
    };
}

macro_rules! integer_object_impl {
    ($name:ident, $index:expr, $ty:ident, $rust:ty) => {
        impl TypedObject for $name {
            const ID: ObjectId = ObjectId::new($index, 0);
            const TYPE: DataType = DataType::$ty;
            type Value = $rust;
            fn decode(v: &Value) -> Option<$rust> {
                match *v {
                    Value::$ty(x) => Some(x),
                    _ => None,
                }
            }
            fn encode(v: $rust) -> Value {
                Value::$ty(v)
            }
        }
    };
}

integer_object!(
    /// 603Fh Error code (1000h: generic error).
    ErrorCode, 0x603F, U16, u16
);
integer_object!(
    /// 6060h Modes of operation (MR-JE-C values include −100 jg, −101 pt, −103 idx).
    ModesOfOperation, 0x6060, I8, i8
);
integer_object!(
    /// 6061h Modes of operation display.
    ModesOfOperationDisplay, 0x6061, I8, i8
);
integer_object!(
    /// 6064h Position actual value, pos units.
    PositionActualValue, 0x6064, I32, i32
);
integer_object!(
    /// 606Ch Velocity actual value, 0.01 r/min.
    VelocityActualValue, 0x606C, I32, i32
);
integer_object!(
    /// 607Ah Target position (pp), pos units.
    TargetPosition, 0x607A, I32, i32
);
integer_object!(
    /// 60FFh Target velocity (pv), 0.01 r/min.
    TargetVelocity, 0x60FF, I32, i32
);
integer_object!(
    /// 6081h Profile velocity, 0.01 r/min.
    ProfileVelocity, 0x6081, U32, u32
);
integer_object!(
    /// 6083h Profile acceleration: ms from 0 to rated speed.
    ProfileAcceleration, 0x6083, U32, u32
);
integer_object!(
    /// 6084h Profile deceleration: ms from rated speed to 0.
    ProfileDeceleration, 0x6084, U32, u32
);
integer_object!(
    /// 6085h Quick stop deceleration, ms (0 acts as 100 ms).
    QuickStopDeceleration, 0x6085, U32, u32
);
integer_object!(
    /// 6502h Supported drive modes.
    SupportedDriveModes, 0x6502, U32, u32
);

/// 6040h Controlword.
pub struct Controlword;
impl TypedObject for Controlword {
    const ID: ObjectId = ObjectId::new(0x6040, 0);
    const TYPE: DataType = DataType::U16;
    type Value = Cw;
    fn decode(v: &Value) -> Option<Cw> {
        match *v {
            Value::U16(x) => Some(Cw(x)),
            _ => None,
        }
    }
    fn encode(v: Cw) -> Value {
        Value::U16(v.0)
    }
}

/// 6041h Statusword.
pub struct Statusword;
impl TypedObject for Statusword {
    const ID: ObjectId = ObjectId::new(0x6041, 0);
    const TYPE: DataType = DataType::U16;
    type Value = Sw;
    fn decode(v: &Value) -> Option<Sw> {
        match *v {
            Value::U16(x) => Some(Sw(x)),
            _ => None,
        }
    }
    fn encode(v: Sw) -> Value {
        Value::U16(v.0)
    }
}

/// 2A42h Current alarm 2: the alarm, or none.
pub struct CurrentAlarm;
impl TypedObject for CurrentAlarm {
    const ID: ObjectId = ObjectId::new(0x2A42, 0);
    const TYPE: DataType = DataType::U16;
    type Value = Option<Alarm>;
    fn decode(v: &Value) -> Option<Option<Alarm>> {
        match *v {
            Value::U16(x) => Some(Alarm::from_current2(x)),
            _ => None,
        }
    }
    fn encode(v: Option<Alarm>) -> Value {
        Value::U16(v.map_or(0, Alarm::current2))
    }
}

/// 2A46h Reset alarm: writing [`ResetAlarm::KEY`] resets the alarm.
pub struct ResetAlarm;
impl ResetAlarm {
    /// The value that resets (any other is ignored, §7.3).
    pub const KEY: u16 = 0x1EA5;
}
integer_object_impl!(ResetAlarm, 0x2A46, U16, u16);

/// 2A40h Clear alarm history: writing [`ResetAlarm::KEY`] clears it.
pub struct ClearAlarmHistory;
integer_object_impl!(ClearAlarmHistory, 0x2A40, U16, u16);
