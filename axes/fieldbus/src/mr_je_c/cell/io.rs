//! One exchange with an MR-JE-C in a cell, the same whatever the transport: the controller's
//! objects out (controlword, mode, targets and profile), the drive's back (statusword, position,
//! velocity, alarm). Over CC-Link IE Field Basic they are the RWw/RWr devices of the manual's
//! Table 2.2 (MR-JE-C manual §2.3.2) with the default response mapping; over SLMP and Modbus
//! they are object writes (only the objects that changed, the controlword last) and reads.

use std::time::{Duration, Instant};

use super::super::access::ObjectAccess;
use super::super::objects::ObjectId;
use super::super::value::Value;
use super::super::SoftwareVersion;
use super::positioning_link::{PositioningCommand, PositioningFeedback};
use crate::cclink_ief_basic::io_thread::{CyclicIo, LinkHandle, StationCommand};
use crate::cclink_ief_basic::{bit, set_bit, EndCode, READY_BIT};

/// What the controller writes to the drive.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Outputs {
    /// 6040h.
    pub controlword: u16,
    /// 6060h.
    pub mode: i8,
    /// 607Ah, pos units.
    pub target_position: i32,
    /// 60FFh, 0.01 r/min.
    pub target_velocity: i32,
    /// 6081h, 0.01 r/min.
    pub profile_velocity: u32,
    /// 6083h, ms from 0 to rated speed.
    pub acceleration_ms: u32,
    /// 6084h, ms from rated speed to 0.
    pub deceleration_ms: u32,
    /// 6071h, 0.1 % of rated torque.
    pub target_torque: i16,
    /// 6087h, 0.1 %/s (0: a step).
    pub torque_slope: u32,
    /// 2D20h, 0.01 r/min: the speed limit in tq; 0 until a tq axis or command sets it, which
    /// leaves the drive's own value (written only once set).
    pub velocity_limit: u32,
    /// 2D60h (pt: the point table, idx: the station); written only once set (SW A4+).
    pub target_point_table: Option<i16>,
}

/// What the drive answered.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Inputs {
    /// 6041h.
    pub statusword: u16,
    /// 6064h, pos units.
    pub position: i32,
    /// 606Ch, 0.01 r/min.
    pub velocity: i32,
    /// 2A42h current alarm 2 (0: none).
    pub alarm: u16,
}

/// Why an exchange brought no answer.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ExchangeError {
    /// No answer (timeout, refused connection, lost frame).
    #[error("no answer: {0}")]
    NoAnswer(String),
    /// The drive refused an access (end code, exception).
    #[error("refused: {0}")]
    Refused(String),
    /// The cyclic link answered but is not ready yet (connecting, SSR off): not a missed
    /// response.
    #[error("cyclic transmission not ready")]
    NotReady,
}

/// One exchange per link period.
pub trait DriveIo: Send {
    /// Writes `out`, reads the inputs back.
    fn exchange(&mut self, out: &Outputs) -> Result<Inputs, ExchangeError>;

    /// Writes one object outside the cycle (start-up parameters).
    fn write_object(&mut self, id: ObjectId, value: &Value) -> Result<(), ExchangeError>;

    /// The last exchange's round trip.
    fn round_trip(&self) -> Duration;
}

/// The objects of the outputs besides the controlword, in the order they are written; 2D20h
/// only once set (`None`: the drive keeps its own).
fn profile_objects(o: &Outputs) -> [(u16, Option<Value>); 10] {
    let limit = i32::try_from(o.velocity_limit).unwrap_or(i32::MAX);
    [
        (0x2D20, (o.velocity_limit != 0).then_some(Value::I32(limit))),
        (0x6060, Some(Value::I8(o.mode))),
        (0x607A, Some(Value::I32(o.target_position))),
        (0x60FF, Some(Value::I32(o.target_velocity))),
        (0x6081, Some(Value::U32(o.profile_velocity))),
        (0x6083, Some(Value::U32(o.acceleration_ms))),
        (0x6084, Some(Value::U32(o.deceleration_ms))),
        (0x6087, Some(Value::U32(o.torque_slope))),
        (0x6071, Some(Value::I16(o.target_torque))),
        (0x2D60, o.target_point_table.map(Value::I16)),
    ]
}

/// Writes one object beside the cyclic link (start-up parameters).
pub type ParameterWrite = Box<dyn FnMut(ObjectId, &Value) -> Result<(), ExchangeError> + Send>;

/// The exchange over object access (SLMP, Modbus/TCP, Modbus RTU).
pub struct ObjectIo<A> {
    access: A,
    last: Option<Outputs>,
    round_trip: Duration,
}

impl<A: ObjectAccess> ObjectIo<A> {
    /// Exchanges through `access`.
    pub fn new(access: A) -> ObjectIo<A> {
        ObjectIo {
            access,
            last: None,
            round_trip: Duration::ZERO,
        }
    }

    fn put(&mut self, index: u16, v: Value) -> Result<(), ExchangeError> {
        self.access
            .write_object(ObjectId::new(index, 0), &v)
            .map_err(sort)
    }

    fn get(&mut self, index: u16) -> Result<i64, ExchangeError> {
        let v = self
            .access
            .read_object(ObjectId::new(index, 0))
            .map_err(sort)?;
        v.as_i64()
            .ok_or_else(|| ExchangeError::Refused(format!("{index:04X}h: {v}")))
    }
}

fn sort(e: super::super::AccessError) -> ExchangeError {
    use super::super::AccessError as E;
    match e {
        E::Timeout(_) | E::Link(_) => ExchangeError::NoAnswer(e.to_string()),
        other => ExchangeError::Refused(other.to_string()),
    }
}

impl<A: ObjectAccess + Send> DriveIo for ObjectIo<A> {
    fn exchange(&mut self, out: &Outputs) -> Result<Inputs, ExchangeError> {
        let t = Instant::now();
        let before = self.last.map(|l| profile_objects(&l));
        // Each its own request: these objects have no continuous access (manual §7.3).
        for (k, (index, v)) in profile_objects(out).into_iter().enumerate() {
            let Some(v) = v else { continue };
            if before.as_ref().is_none_or(|b| b[k].1.as_ref() != Some(&v)) {
                self.put(index, v)?;
            }
        }
        self.put(0x6040, Value::U16(out.controlword))?;
        self.last = Some(*out);
        let inputs = Inputs {
            statusword: self.get(0x6041)? as u16,
            position: self.get(0x6064)? as i32,
            velocity: self.get(0x606C)? as i32,
            alarm: self.get(0x2A42)? as u16,
        };
        self.round_trip = t.elapsed();
        Ok(inputs)
    }

    fn write_object(&mut self, id: ObjectId, value: &Value) -> Result<(), ExchangeError> {
        self.access.write_object(id, value).map_err(sort)
    }

    fn round_trip(&self) -> Duration {
        self.round_trip
    }
}

/// RWw devices (manual Table 2.2, profile mode): the word offset of each output.
mod rww {
    pub const MODE: usize = 0x00;
    pub const CONTROLWORD: usize = 0x01;
    pub const TARGET_POSITION: usize = 0x05;
    pub const TARGET_VELOCITY: usize = 0x07;
    pub const PROFILE_VELOCITY: usize = 0x0C;
    pub const ACCELERATION: usize = 0x0E;
    pub const DECELERATION: usize = 0x10;
    pub const VELOCITY_LIMIT: usize = 0x09;
    pub const TARGET_TORQUE: usize = 0x0B;
    pub const TORQUE_SLOPE: usize = 0x12;
    /// The devices of Table 2.2 cellrt does not command, with their objects (2D20h until a tq
    /// axis sets it). The drive takes every RWw device into its object each cycle, so each of
    /// these carries its object's initial value (§7.3): left 0, 60E0h/60E1h would limit the
    /// torque to 0 % (a motor with no torque) and 2D20h the speed in tq to 0 r/min.
    pub const UNCOMMANDED: [(usize, u16); 9] = [
        (0x02, 0x2D01),
        (0x03, 0x2D02),
        (0x04, 0x2D03),
        (VELOCITY_LIMIT, 0x2D20),
        (0x14, 0x60E0),
        (0x15, 0x60E1),
        (0x17, 0x60B8),
        (0x18, 0x60F2),
        (0x19, 0x2D05),
    ];
}

/// RWw with the devices cellrt does not command at their objects' initial values on software
/// `sw` (the commanded ones are written over it each exchange).
pub fn uncommanded_rww(sw: SoftwareVersion) -> [u8; 64] {
    let mut words = [0u8; 64];
    for (device, index) in rww::UNCOMMANDED {
        let Some(sub) = super::super::objects::entry(ObjectId::new(index, 0), sw).map(|(_, s)| s)
        else {
            continue;
        };
        let value = sub
            .initial
            .value(sw)
            .and_then(|v| Value::from_i64(sub.ty, v));
        if let Some(v) = value {
            put_le(&mut words, device, &v.to_le());
        }
    }
    words
}

/// RWr byte offsets of the default response mapping 1A00h (6061h, pad, 6041h, 6064h, 606Ch, …,
/// 2A42h after 24 bytes).
mod rwr {
    pub const STATUSWORD: usize = 2;
    pub const POSITION: usize = 4;
    pub const VELOCITY: usize = 8;
    pub const ALARM: usize = 24;
}

/// Which table of the manual the station's link devices follow (§2.3.2): Table 2.2 for the
/// profile modes, Table 2.3 for the positioning modes (pt, idx, jg; hm is in both). The
/// manual does not say what selects the table; the extract infers [Pr. PA01]'s control mode,
/// so a cell picks it from the axis' mode and the drive must be commissioned to match.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DeviceTable {
    /// Table 2.2.
    #[default]
    Profile,
    /// Table 2.3 ([`super::positioning_link`]).
    Positioning,
}

/// The exchange over the CC-Link IE Field Basic cyclic link of one station, run inline on the
/// axis' thread (one cycle per exchange); a station not yet connected is connected first.
pub struct CyclicDriveIo {
    link: CyclicIo,
    devices: DeviceTable,
    /// Table 2.3's devices cellrt does not command (Control DI 1–3, 60B8h) at their objects'
    /// initial values.
    positioning_base: PositioningCommand,
    /// RWw before the commanded devices are written: [`uncommanded_rww`].
    base: [u8; 64],
    handle: LinkHandle,
    /// The station's object access for start-up parameters (SLMP beside the cyclic link).
    parameters: Option<ParameterWrite>,
    round_trip: Duration,
}

impl CyclicDriveIo {
    /// Exchanges on `link` (one station) with a drive of software A4; start-up writes go
    /// through `parameters`.
    pub fn new(link: CyclicIo, parameters: Option<ParameterWrite>) -> CyclicDriveIo {
        let initial = |index: u16| {
            let sw = SoftwareVersion::A4;
            super::super::objects::entry(ObjectId::new(index, 0), sw)
                .and_then(|(_, s)| s.initial.value(sw))
                .unwrap_or(0)
        };
        CyclicDriveIo {
            devices: DeviceTable::Profile,
            positioning_base: PositioningCommand {
                control_di: [0x2D01, 0x2D02, 0x2D03].map(|i| initial(i) as u16),
                touch_probe_function: initial(0x60B8) as u16,
                ..PositioningCommand::default()
            },
            base: uncommanded_rww(SoftwareVersion::A4),
            handle: link.handle(),
            link,
            parameters,
            round_trip: Duration::ZERO,
        }
    }
}

impl CyclicDriveIo {
    /// The same, on the link devices of `devices`.
    pub fn with_devices(mut self, devices: DeviceTable) -> CyclicDriveIo {
        self.devices = devices;
        self
    }

    /// RWw of Table 2.3 for `out`.
    fn positioning_rww(&self, out: &Outputs) -> [u8; 64] {
        PositioningCommand {
            mode: out.mode,
            controlword: out.controlword,
            target_point_table: out.target_point_table.unwrap_or(0),
            profile_velocity: out.profile_velocity,
            acceleration_ms: out.acceleration_ms,
            deceleration_ms: out.deceleration_ms,
            ..self.positioning_base
        }
        .rww()
    }

    /// RWw of Table 2.2 for `out`.
    fn profile_rww(&self, out: &Outputs) -> [u8; 64] {
        let mut rww = self.base;
        put_le(&mut rww, rww::MODE, &[out.mode as u8]);
        put_le(&mut rww, rww::CONTROLWORD, &out.controlword.to_le_bytes());
        put_le(
            &mut rww,
            rww::TARGET_POSITION,
            &out.target_position.to_le_bytes(),
        );
        put_le(
            &mut rww,
            rww::TARGET_VELOCITY,
            &out.target_velocity.to_le_bytes(),
        );
        put_le(
            &mut rww,
            rww::PROFILE_VELOCITY,
            &out.profile_velocity.to_le_bytes(),
        );
        put_le(
            &mut rww,
            rww::ACCELERATION,
            &out.acceleration_ms.to_le_bytes(),
        );
        put_le(
            &mut rww,
            rww::DECELERATION,
            &out.deceleration_ms.to_le_bytes(),
        );
        put_le(
            &mut rww,
            rww::TARGET_TORQUE,
            &out.target_torque.to_le_bytes(),
        );
        put_le(&mut rww, rww::TORQUE_SLOPE, &out.torque_slope.to_le_bytes());
        if out.velocity_limit != 0 {
            put_le(
                &mut rww,
                rww::VELOCITY_LIMIT,
                &out.velocity_limit.to_le_bytes(),
            );
        }
        rww
    }

    /// The inputs in RWr of the station's table.
    fn inputs(&self, rwr: &[u8; 64]) -> Inputs {
        match self.devices {
            DeviceTable::Profile => Inputs {
                statusword: u16::from_le_bytes(le(rwr, rwr::STATUSWORD)),
                position: i32::from_le_bytes(le(rwr, rwr::POSITION)),
                velocity: i32::from_le_bytes(le(rwr, rwr::VELOCITY)),
                alarm: u16::from_le_bytes(le(rwr, rwr::ALARM)),
            },
            DeviceTable::Positioning => {
                let f = PositioningFeedback::from_rwr(rwr);
                Inputs {
                    statusword: f.statusword,
                    position: f.position,
                    velocity: f.velocity,
                    alarm: f.alarm,
                }
            }
        }
    }
}

fn put_le(words: &mut [u8; 64], device: usize, bytes: &[u8]) {
    words[2 * device..2 * device + bytes.len()].copy_from_slice(bytes);
}

fn le<const N: usize>(block: &[u8; 64], at: usize) -> [u8; N] {
    let mut b = [0u8; N];
    b.copy_from_slice(&block[at..at + N]);
    b
}

impl DriveIo for CyclicDriveIo {
    fn exchange(&mut self, out: &Outputs) -> Result<Inputs, ExchangeError> {
        let rww = match self.devices {
            DeviceTable::Profile => self.profile_rww(out),
            DeviceTable::Positioning => self.positioning_rww(out),
        };
        let mut c = StationCommand {
            transmit: true,
            rww,
            ..StationCommand::default()
        };
        set_bit(&mut c.ry, READY_BIT, true);
        self.handle.command(0, c);
        let cycle = self.link.cycle();
        let f = self.handle.feedback(0).unwrap_or_default();
        self.round_trip = Duration::from_nanos(f.round_trip_ns);
        if let Err(e) = cycle {
            return Err(ExchangeError::NoAnswer(e.to_string()));
        }
        if f.missed_in_row > 0 {
            return Err(ExchangeError::NoAnswer("no cyclic response".into()));
        }
        if f.end_code != EndCode::Normal {
            return Err(ExchangeError::Refused(format!("end code {:?}", f.end_code)));
        }
        if !bit(&f.rx, READY_BIT) {
            // Connected this cycle (the request did not transmit yet), or SSR not yet on.
            return Err(ExchangeError::NotReady);
        }
        Ok(self.inputs(&f.rwr))
    }

    fn write_object(&mut self, id: ObjectId, value: &Value) -> Result<(), ExchangeError> {
        match &mut self.parameters {
            Some(write) => write(id, value),
            None => Err(ExchangeError::Refused(format!(
                "{id}: no object access beside the cyclic link"
            ))),
        }
    }

    fn round_trip(&self) -> Duration {
        self.round_trip
    }
}
