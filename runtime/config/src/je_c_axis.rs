//! `[[axes]]` with `drive = "mr-je-c"`: an MR-JE-C axis of the cell, reached over Ethernet or
//! RS-485 (MR-JE-C manual §2–§4) by a non-RT thread of its own, never by the RT loop. Its keys
//! beside the common ones (`name`, `unit`, `counts_per_unit`, `limits`, `mode` = "pp" | "pv" |
//! "tq" | "jog" | "point_table" | "indexer") are `transport` and the `[axes.je_c]` table.

use std::net::{IpAddr, SocketAddr};
use std::path::{Path, PathBuf};
use std::time::Duration;

use cellrt_fieldbus::mr_je_c::cell::AxisCommand;

use super::raw::{RawAxis, RawJecAxis, RawPointTable};
use super::{ConfigError, FaultReaction};
use crate::plausible::{Plausible, COUNTS_PER_REV, MOTOR_SPEED, REVS_PER_UNIT};

/// The drive name that selects an MR-JE-C axis.
pub const DRIVE: &str = "mr-je-c";

/// The shortest link period: the drive's response time (MR-JE-C manual §2.2.1: 10 ms).
pub const MIN_PERIOD_MS: u64 = 10;

/// The most point tables a drive holds (2801h–28FFh).
pub const MAX_POINT_TABLES: usize = 255;
/// The largest M code of a point table (2801h:7, 0–63h).
pub const MAX_M_CODE: u8 = 0x63;
/// [Pr. PT28]'s stations per revolution (indexer, §7.3 607Bh).
pub const STATIONS: std::ops::RangeInclusive<u32> = 2..=255;

/// One point table of a `point_table` axis, in the axis' units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JecPointTable {
    /// Position, units.
    pub position: f64,
    /// Speed, unit/s.
    pub velocity: f64,
    /// Acceleration, unit/s².
    pub acceleration: f64,
    /// Deceleration, unit/s².
    pub deceleration: f64,
    /// M code.
    pub m_code: u8,
}

/// Why an MR-JE-C axis refuses a command (a move, a jog or a torque).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum JecCommandError {
    /// A torque on an axis that runs a positioning mode.
    #[error("axis '{axis}' runs {mode}: the link devices of its positioning mode (Table 2.3) carry no torque command")]
    TorqueInPositioningMode {
        /// The axis.
        axis: String,
        /// Its mode's name.
        mode: &'static str,
    },
    /// A torque on an axis without `limits.torque`.
    #[error("axis '{axis}': a torque command needs limits.torque (% of rated torque)")]
    NoTorqueLimit {
        /// The axis.
        axis: String,
    },
    /// A torque beyond `limits.torque` (or not a number).
    #[error("torque {torque} % is outside the torque limit ±{max} % of axis '{axis}'")]
    TorqueOutsideLimit {
        /// The axis.
        axis: String,
        /// The torque asked for, %.
        torque: f64,
        /// The limit, %.
        max: f64,
    },
    /// A move target that is not a finite number.
    #[error("axis '{axis}': target {target} is not a finite number")]
    TargetNotFinite {
        /// The axis.
        axis: String,
        /// The target.
        target: f64,
    },
    /// A move target outside the axis' position range.
    #[error("axis '{axis}': target {target} {unit} is outside its position range [{lo}, {hi}]")]
    TargetOutsideRange {
        /// The axis.
        axis: String,
        /// The target.
        target: f64,
        /// The axis' unit.
        unit: String,
        /// The range's low end.
        lo: f64,
        /// The range's high end.
        hi: f64,
    },
    /// A move target that is none of the axis' point tables or stations.
    #[error("axis '{axis}': {target} is not one of its {what} ({first}–{last})")]
    NotOneOf {
        /// The axis.
        axis: String,
        /// The target.
        target: f64,
        /// "point tables" or "stations".
        what: &'static str,
        /// The first number.
        first: u8,
        /// The last number.
        last: u8,
    },
    /// A move of a jog axis.
    #[error("axis '{axis}' runs jg: it moves by jog only, not to targets")]
    JogAxisHasNoTargets {
        /// The axis.
        axis: String,
    },
    /// A jog of an indexer axis.
    #[error("axis '{axis}' is an indexer axis: it turns to stations (move), it does not jog")]
    IndexerDoesNotJog {
        /// The axis.
        axis: String,
    },
}

/// Why `je_c.stations` is refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum StationsError {
    /// A count of stations [Pr. PT28] does not take.
    #[error("{stations} stations: [Pr. PT28] takes {}–{} stations per revolution", STATIONS.start(), STATIONS.end())]
    OutOfRange {
        /// The count given.
        stations: u32,
    },
    /// An indexer axis without `je_c.stations`.
    #[error("axis '{axis}' runs the indexer: give je_c.stations, its stations per revolution ([Pr. PT28])")]
    Missing {
        /// The axis.
        axis: String,
    },
    /// `je_c.stations` on an axis that is not an indexer.
    #[error("axis '{axis}' runs {mode}: stations are for mode = \"indexer\"")]
    NotAnIndexer {
        /// The axis.
        axis: String,
        /// Its mode.
        mode: String,
    },
}

/// Where an MR-JE-C is reached.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum JecTransport {
    /// CC-Link IE Field Basic cyclic data (UDP 61450), start-up writes by SLMP (UDP 5010).
    CcLink(Option<SocketAddr>),
    /// SLMP over UDP (5010).
    Slmp(Option<SocketAddr>),
    /// Modbus/TCP (502).
    ModbusTcp(Option<SocketAddr>),
    /// Modbus RTU on an RS-485 line.
    ModbusRtu {
        /// The serial device (none: the emulator's pseudo-terminal).
        serial: Option<PathBuf>,
        /// Station number.
        station: u8,
        /// Bit rate.
        baud: u32,
    },
}

impl JecTransport {
    /// The configuration name.
    pub fn name(&self) -> &'static str {
        match self {
            JecTransport::CcLink(_) => "cclink-ief-basic",
            JecTransport::Slmp(_) => "slmp",
            JecTransport::ModbusTcp(_) => "modbus-tcp",
            JecTransport::ModbusRtu { .. } => "modbus-rtu",
        }
    }
}

/// The motion an MR-JE-C axis runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JecMode {
    /// Profile position: `move` steps.
    Pp,
    /// Profile velocity: `jog` steps.
    Pv,
    /// Profile torque: `torque` steps (needs `limits.torque`).
    Tq,
    /// jg (SW A4+): `jog` steps only.
    Jog,
    /// pt (SW A4+): `move` steps name a point table of `[[axes.je_c.point_table]]`.
    PointTable,
    /// idx (SW A4+): `move` steps name a station; positions count in stations.
    Indexer {
        /// [Pr. PT28], 2–255.
        stations: u8,
    },
}

impl JecMode {
    /// The configuration name.
    pub fn name(self) -> &'static str {
        match self {
            JecMode::Pp => "pp",
            JecMode::Pv => "pv",
            JecMode::Tq => "tq",
            JecMode::Jog => "jog",
            JecMode::PointTable => "point_table",
            JecMode::Indexer { .. } => "indexer",
        }
    }

    /// The positioning mode of the drive's Table 2.3, if the axis runs one.
    pub fn positioning(self) -> Option<cellrt_fieldbus::mr_je_c::cell::PositioningMode> {
        use cellrt_fieldbus::mr_je_c::cell::PositioningMode as P;
        match self {
            JecMode::Jog => Some(P::Jog),
            JecMode::PointTable => Some(P::PointTable),
            JecMode::Indexer { .. } => Some(P::Indexer),
            JecMode::Pp | JecMode::Pv | JecMode::Tq => None,
        }
    }
}

/// A validated MR-JE-C axis.
#[derive(Debug, Clone, PartialEq)]
pub struct JecAxisConfig {
    /// Axis name (unique among all the cell's axes).
    pub name: String,
    /// Unit name.
    pub unit: String,
    /// Pos units per unit.
    pub counts_per_unit: f64,
    /// `[min, max]`, units.
    pub position: [f64; 2],
    /// Velocity limit, unit/s.
    pub velocity: f64,
    /// Acceleration limit, unit/s².
    pub acceleration: f64,
    /// pp, pv, tq or a positioning mode.
    pub mode: JecMode,
    /// Point tables 1, 2, … (`point_table` axes; empty otherwise).
    pub point_tables: Vec<JecPointTable>,
    /// `limits.torque` and `limits.torque_slope` where set (required in tq).
    pub torque: Option<super::TorqueLimits>,
    /// Where the drive is.
    pub transport: JecTransport,
    /// Link period.
    pub period: Duration,
    /// Answer deadline of one exchange.
    pub response_timeout: Duration,
    /// Missed answers in a row that stop the axis (0: never).
    pub watchdog_missed: u32,
    /// How the watchdog stops it.
    pub watchdog_reaction: FaultReaction,
    /// The drive's own time-out, written at start-up.
    pub drive_timeout: Option<Duration>,
    /// Pos units per motor revolution.
    pub counts_per_rev: f64,
    /// Rated speed, r/min.
    pub rated_speed: f64,
    /// Run an emulated drive.
    pub emulate: bool,
}

/// The one homing method an MR-JE-C axis runs: 37, the home where the motor stands (6098h's
/// default; the MR-JE-C manual §7.3 lists no other and refers to the Profile Mode manual).
pub const HOMING_METHOD: i8 = 37;

/// Why an MR-JE-C axis does not home as asked: one refusal for a program's home step and the
/// operator's.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum JecHomingError {
    /// A home setting by a Controlword2 edge (an MR-J3-T04 procedure).
    #[error("axis '{axis}' is an MR-JE-C axis: it homes in hm, not by a Controlword2 edge")]
    Controlword2Edge {
        /// The axis.
        axis: String,
    },
    /// A homing method other than [`HOMING_METHOD`].
    #[error("method {method}: MR-JE-C axis '{axis}' homes with method {} only (the home where the motor stands; the MR-JE-C manual lists no other)", HOMING_METHOD)]
    Method {
        /// The axis.
        axis: String,
        /// The method asked for.
        method: i8,
    },
}

impl JecAxisConfig {
    /// The homing method of a request naming `method` (or none) or a Controlword2 `edge`:
    /// [`HOMING_METHOD`], else the refusal.
    pub fn homing_method(&self, method: Option<i8>, edge: bool) -> Result<i8, JecHomingError> {
        if edge {
            return Err(JecHomingError::Controlword2Edge {
                axis: self.name.clone(),
            });
        }
        match method {
            None | Some(HOMING_METHOD) => Ok(HOMING_METHOD),
            Some(method) => Err(JecHomingError::Method {
                axis: self.name.clone(),
                method,
            }),
        }
    }

    /// A speed in unit/s as 0.01 r/min (6081h, 60FFh).
    pub fn drive_speed(&self, v: f64) -> i64 {
        (v * self.counts_per_unit / self.counts_per_rev * 60.0 * 100.0).round() as i64
    }

    /// An acceleration in unit/s² as the time constant from 0 to the rated speed, ms (6083h,
    /// 6084h; at least 1).
    pub fn ramp_ms(&self, a: f64) -> u32 {
        let rated = self.rated_speed / 60.0 * self.counts_per_rev / self.counts_per_unit;
        (rated / a * 1000.0).round().clamp(1.0, f64::from(u32::MAX)) as u32
    }

    /// The tq command for `torque` % of rated torque: 6071h in 0.1 %, ramped at
    /// `limits.torque_slope` (6087h), the motor's speed held within `limits.velocity` (2D20h);
    /// refused without `limits.torque` or beyond it.
    pub fn torque_command(&self, torque: f64) -> Result<AxisCommand, JecCommandError> {
        let axis = self.name.clone();
        if self.mode.positioning().is_some() {
            return Err(JecCommandError::TorqueInPositioningMode {
                axis,
                mode: self.mode.name(),
            });
        }
        let Some(limits) = self.torque else {
            return Err(JecCommandError::NoTorqueLimit { axis });
        };
        let max = limits.max.0;
        if !(torque.is_finite() && torque.abs() <= max) {
            return Err(JecCommandError::TorqueOutsideLimit { axis, torque, max });
        }
        let tenths = |v: f64| (v * 10.0).round();
        Ok(AxisCommand::Torque {
            // Within ±1000 %: checked at load (`MAX_TORQUE_PERCENT`).
            torque: tenths(torque) as i16,
            slope: tenths(limits.slope).clamp(1.0, f64::from(u32::MAX)) as u32,
            velocity_limit: self.speed_limit(),
        })
    }

    /// 2D20h Velocity limit value in tq: `limits.velocity` in 0.01 r/min.
    pub fn speed_limit(&self) -> u32 {
        self.drive_speed(self.velocity)
            .clamp(0, i64::from(i32::MAX)) as u32
    }

    /// A position in units as pos units.
    pub fn counts(&self, x: f64) -> i32 {
        (x * self.counts_per_unit).round() as i32
    }

    /// Pos units as units.
    pub fn units(&self, counts: i32) -> f64 {
        f64::from(counts) / self.counts_per_unit
    }
}

/// Checks an `mr-je-c` axis at `key` of `file`.
pub fn validate(
    file: &Path,
    key: &str,
    a: &RawAxis,
    communication_reaction: FaultReaction,
) -> Result<JecAxisConfig, ConfigError> {
    let err = |sub: &str, m: String| ConfigError::new(file, format!("{key}.{sub}"), m);
    let raw = a.je_c.as_ref().ok_or_else(|| {
        err(
            "je_c",
            format!(
                "axis '{}': an mr-je-c axis needs an [axes.je_c] table",
                a.name
            ),
        )
    })?;
    let stations = stations(&a.name, &a.mode, raw.stations)
        .map_err(|e| err("je_c.stations", e.to_string()))?;
    let mode = match (a.mode.as_str(), stations) {
        ("pp", _) => JecMode::Pp,
        ("pv", _) => JecMode::Pv,
        ("tq", _) => JecMode::Tq,
        ("jog", _) => JecMode::Jog,
        ("point_table", _) => JecMode::PointTable,
        ("indexer", Some(stations)) => JecMode::Indexer { stations },
        (m, _) => {
            return Err(err(
                "mode",
                format!(
                    "axis '{}': mode \"{m}\": an MR-JE-C in a cell runs \"pp\", \"pv\", \"tq\", \"jog\", \"point_table\" or \"indexer\" (it has no cyclic synchronous modes)",
                    a.name
                ),
            ))
        }
    };
    let positive = |sub: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(err(sub, format!("{v} must be positive")))
        }
    };
    let plausible = |sub: &str, bound: &Plausible, v: f64| bound.check(v).map_err(|m| err(sub, m));
    let transport = transport(&err, &a.transport, raw)?;
    let period_ms = raw.period_ms.unwrap_or(MIN_PERIOD_MS);
    if period_ms < MIN_PERIOD_MS {
        return Err(err(
            "je_c.period_ms",
            format!("{period_ms} ms: the MR-JE-C answers within 10 ms (manual §2.2.1), so the link period is at least {MIN_PERIOD_MS} ms"),
        ));
    }
    let response_timeout_ms = raw.response_timeout_ms.unwrap_or(50);
    if response_timeout_ms == 0 {
        return Err(err(
            "je_c.response_timeout_ms",
            "must be at least 1 ms".into(),
        ));
    }
    let watchdog_reaction = match &raw.watchdog_reaction {
        None => communication_reaction,
        Some(r) => FaultReaction::parse(r).ok_or_else(|| {
            err(
                "je_c.watchdog_reaction",
                format!("\"{r}\": expected \"controlled_stop\", \"quick_stop\" or \"disable\""),
            )
        })?,
    };
    if matches!(mode, JecMode::Indexer { .. }) && watchdog_reaction == FaultReaction::ControlledStop
    {
        return Err(err(
            "je_c.watchdog_reaction",
            format!("axis '{}' runs the indexer, where the Halt bit is disabled (MR-JE-C manual §7.6.3): a controlled stop would not stop it; give \"quick_stop\" or \"disable\" (also as watchdogs.communication_reaction)", a.name),
        ));
    }
    let counts_per_rev = match mode {
        JecMode::Indexer { stations } => {
            if a.counts_per_unit != 1.0 {
                return Err(err(
                    "counts_per_unit",
                    format!("{}: an indexer axis counts in stations (6092h:1 = [Pr. PT28]), so counts_per_unit is 1", a.counts_per_unit),
                ));
            }
            if raw.counts_per_rev.is_some_and(|c| c != f64::from(stations)) {
                return Err(err(
                    "je_c.counts_per_rev",
                    format!("an indexer axis has je_c.stations = {stations} pos units per revolution; leave counts_per_rev out"),
                ));
            }
            f64::from(stations)
        }
        _ => plausible(
            "je_c.counts_per_rev",
            &COUNTS_PER_REV,
            raw.counts_per_rev.unwrap_or(131_072.0),
        )?,
    };
    let drive_timeout = drive_timeout(&err, &transport, raw.drive_timeout_ms)?;
    let [lo, hi] = a.limits.position;
    if !(lo.is_finite() && hi.is_finite() && lo < hi) {
        return Err(err(
            "limits.position",
            format!("[{lo}, {hi}] is not a range (min < max)"),
        ));
    }
    let velocity = positive("limits.velocity", a.limits.velocity)?;
    let acceleration = positive("limits.acceleration", a.limits.acceleration)?;
    let counts_per_unit = positive("counts_per_unit", a.counts_per_unit)?;
    plausible(
        "counts_per_unit",
        &REVS_PER_UNIT,
        counts_per_unit / counts_per_rev,
    )?;
    if let (Some((min, max)), false) = (
        target_position_range(),
        matches!(mode, JecMode::Indexer { .. }),
    ) {
        let [lo_counts, hi_counts] = [lo, hi].map(|x| (x * counts_per_unit).round());
        if lo_counts < min as f64 || hi_counts > max as f64 {
            return Err(err(
                "limits.position",
                format!("[{lo}, {hi}] {} is [{lo_counts}, {hi_counts}] pos units, beyond Target position 607Ah's setting range {min}…{max} (MR-JE-C manual §7.3): narrow the range or count coarser pos units (counts_per_unit, [Pr. PT01])", a.unit),
            ));
        }
    }
    let point_tables = point_tables(
        &a.name,
        mode,
        &raw.point_table,
        a.limits.position,
        velocity,
        acceleration,
    )
    .map_err(|(sub, m)| err(&sub, m))?;
    Ok(JecAxisConfig {
        name: a.name.clone(),
        unit: a.unit.clone(),
        counts_per_unit,
        position: a.limits.position,
        velocity,
        acceleration,
        mode,
        point_tables,
        // Set by the caller (the same check as every axis' `limits.torque`).
        torque: None,
        transport,
        period: Duration::from_millis(period_ms),
        response_timeout: Duration::from_millis(response_timeout_ms),
        watchdog_missed: raw.watchdog_missed.unwrap_or(3),
        watchdog_reaction,
        drive_timeout,
        counts_per_rev,
        rated_speed: plausible(
            "je_c.rated_speed",
            &MOTOR_SPEED,
            raw.rated_speed.unwrap_or(3000.0),
        )?,
        emulate: raw.emulate,
    })
}

/// Checks the point tables of `axis` (name `name`) against its limits; `Err((key, why))`.
pub fn point_tables(
    name: &str,
    mode: JecMode,
    raw: &[RawPointTable],
    position: [f64; 2],
    velocity: f64,
    acceleration: f64,
) -> Result<Vec<JecPointTable>, (String, String)> {
    if mode != JecMode::PointTable {
        return match raw.is_empty() {
            true => Ok(Vec::new()),
            false => Err((
                "je_c.point_table".into(),
                format!(
                    "axis '{name}' runs {}: point tables are for mode = \"point_table\"",
                    mode.name()
                ),
            )),
        };
    }
    if raw.is_empty() || raw.len() > MAX_POINT_TABLES {
        return Err((
            "je_c.point_table".into(),
            format!(
                "axis '{name}' runs point tables: give 1–{MAX_POINT_TABLES} [[axes.je_c.point_table]] (table 1 first), {} given",
                raw.len()
            ),
        ));
    }
    raw.iter()
        .enumerate()
        .map(|(k, t)| {
            let key = |sub: &str| format!("je_c.point_table[{k}].{sub}");
            let n = k + 1;
            let [lo, hi] = position;
            if !(t.position.is_finite() && (lo..=hi).contains(&t.position)) {
                return Err((
                    key("position"),
                    format!("point table {n}: {} is outside the position range [{lo}, {hi}] of axis '{name}'", t.position),
                ));
            }
            let within = |sub: &str, v: Option<f64>, limit: f64| match v {
                None => Ok(limit),
                Some(v) if v.is_finite() && v > 0.0 && v <= limit => Ok(v),
                Some(v) => Err((
                    key(sub),
                    format!("point table {n}: {sub} {v} must be > 0 and at most the axis' limit {limit}"),
                )),
            };
            let m_code = t.m_code.unwrap_or(0);
            if m_code > MAX_M_CODE {
                return Err((
                    key("m_code"),
                    format!("point table {n}: M code {m_code} is outside 0–{MAX_M_CODE} (2801h:7)"),
                ));
            }
            Ok(JecPointTable {
                position: t.position,
                velocity: within("velocity", t.velocity, velocity)?,
                acceleration: within("acceleration", t.acceleration, acceleration)?,
                deceleration: within(
                    "deceleration",
                    t.deceleration.or(t.acceleration),
                    acceleration,
                )?,
                m_code,
            })
        })
        .collect()
}

/// The stations of an indexer axis: `je_c.stations` for mode indexer, refused otherwise.
pub fn stations(
    name: &str,
    mode_name: &str,
    raw: Option<u32>,
) -> Result<Option<u8>, StationsError> {
    match (mode_name, raw) {
        ("indexer", Some(n)) if STATIONS.contains(&n) => Ok(Some(n as u8)),
        ("indexer", Some(stations)) => Err(StationsError::OutOfRange { stations }),
        ("indexer", None) => Err(StationsError::Missing { axis: name.into() }),
        (_, Some(_)) => Err(StationsError::NotAnIndexer {
            axis: name.into(),
            mode: mode_name.into(),
        }),
        (_, None) => Ok(None),
    }
}

/// Target position 607Ah's setting range in pos units, from the object table (±999999; the
/// degree unit's ±360000 is not a cell's unit).
fn target_position_range() -> Option<(i64, i64)> {
    use cellrt_fieldbus::mr_je_c::objects::entry;
    use cellrt_fieldbus::mr_je_c::types::Range;
    use cellrt_fieldbus::mr_je_c::{ObjectId, SoftwareVersion};
    match entry(ObjectId::new(0x607A, 0), SoftwareVersion::A4)?
        .1
        .range
    {
        Range::Spans(spans) => spans.first().copied(),
        _ => None,
    }
}

/// `transport` and the address keys it needs.
fn transport(
    err: &dyn Fn(&str, String) -> ConfigError,
    name: &str,
    raw: &RawJecAxis,
) -> Result<JecTransport, ConfigError> {
    let address = |default_port: u16| -> Result<Option<SocketAddr>, ConfigError> {
        match (&raw.address, raw.emulate) {
            (None, true) => Ok(None),
            (None, false) => Err(err(
                "je_c.address",
                "the drive's IP address is needed (or emulate = true)".into(),
            )),
            (Some(text), _) => {
                let ip: IpAddr = text
                    .parse()
                    .map_err(|_| err("je_c.address", format!("\"{text}\" is not an IP address")))?;
                Ok(Some(SocketAddr::new(ip, raw.port.unwrap_or(default_port))))
            }
        }
    };
    let ethernet_only = |t: JecTransport| {
        for (set, k) in [
            (raw.serial.is_some(), "serial"),
            (raw.station.is_some(), "station"),
            (raw.baud.is_some(), "baud"),
        ] {
            if set {
                return Err(err(
                    &format!("je_c.{k}"),
                    format!("a {} axis has no RS-485 line", t.name()),
                ));
            }
        }
        Ok(t)
    };
    match name {
        "cclink-ief-basic" => ethernet_only(JecTransport::CcLink(address(
            cellrt_fieldbus::cclink_ief_basic::CYCLIC_PORT,
        )?)),
        "slmp" => ethernet_only(JecTransport::Slmp(address(cellrt_fieldbus::slmp::UDP_PORT)?)),
        "modbus-tcp" => ethernet_only(JecTransport::ModbusTcp(address(
            cellrt_fieldbus::modbus::tcp::PORT,
        )?)),
        "modbus-rtu" => rtu(err, raw),
        other => Err(err(
            "transport",
            format!("\"{other}\": an mr-je-c axis is reached by \"cclink-ief-basic\", \"slmp\", \"modbus-tcp\" or \"modbus-rtu\""),
        )),
    }
}

fn rtu(
    err: &dyn Fn(&str, String) -> ConfigError,
    raw: &RawJecAxis,
) -> Result<JecTransport, ConfigError> {
    for (set, k) in [
        (raw.address.is_some(), "address"),
        (raw.port.is_some(), "port"),
    ] {
        if set {
            return Err(err(
                &format!("je_c.{k}"),
                "a modbus-rtu axis is on a serial line: give serial and station".into(),
            ));
        }
    }
    if raw.serial.is_none() && !raw.emulate {
        return Err(err(
            "je_c.serial",
            "the RS-485 line's serial device is needed (or emulate = true)".into(),
        ));
    }
    let station = raw.station.ok_or_else(|| {
        err(
            "je_c.station",
            "the drive's station number is needed (1–247)".into(),
        )
    })?;
    if !(1..=247).contains(&station) {
        return Err(err(
            "je_c.station",
            format!("{station} is not a station number (1–247; 0 never answers, manual §4.9.2)"),
        ));
    }
    let baud = raw.baud.unwrap_or(115_200);
    cellrt_fieldbus::modbus::serial::LineSettings::new(baud, Default::default())
        .map_err(|m| err("je_c.baud", m.to_string()))?;
    Ok(JecTransport::ModbusRtu {
        serial: raw.serial.clone(),
        station,
        baud,
    })
}

/// `drive_timeout_ms` in the unit of the transport's parameter.
fn drive_timeout(
    err: &dyn Fn(&str, String) -> ConfigError,
    t: &JecTransport,
    ms: Option<u64>,
) -> Result<Option<Duration>, ConfigError> {
    let Some(ms) = ms else { return Ok(None) };
    use cellrt_fieldbus::mr_je_c::parameters::{definition, PF46, PN02, PN10};
    let (parameter, name, per) = match t {
        JecTransport::CcLink(_) => (PN02, "PN02", 1),
        JecTransport::ModbusRtu { .. } => (PF46, "PF46", 1000),
        _ => (PN10, "PN10", 1000),
    };
    if per > 1 && ms % per != 0 {
        return Err(err(
            "je_c.drive_timeout_ms",
            format!(
                "{ms} ms: the {} time-out ([Pr. {name}]) is set in whole seconds",
                t.name()
            ),
        ));
    }
    // The parameter's setting range (MR-JE-C manual §5.2.3), checked before the drive is.
    let range = definition(parameter.index()).and_then(|d| d.range.bounds());
    if let Some((lo, hi)) = range.filter(|&(lo, hi)| !(lo..=hi).contains(&((ms / per) as i64))) {
        return Err(err(
            "je_c.drive_timeout_ms",
            format!(
                "{ms} ms is outside the {} time-out [Pr. {name}]'s range {}–{} ms",
                t.name(),
                lo * per as i64,
                hi * per as i64
            ),
        ));
    }
    Ok(Some(Duration::from_millis(ms)))
}
