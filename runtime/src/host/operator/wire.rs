//! The operator service's messages: JSON documents in byte payloads, so any process (a shell
//! tool, a Python HMI) can speak it and a malformed request gets a precise reason back.
//!
//! PLCopen counterparts: `power` MC_Power, `move` MC_MoveAbsolute / MC_MoveRelative (`relative`),
//! `velocity` MC_MoveVelocity, `torque` MC_TorqueControl, `halt` MC_Halt, `stop` MC_Stop,
//! `reset` MC_Reset, `override` MC_SetOverride.

use std::collections::BTreeMap;
use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use crate::services::MAX_OPERATOR_REQUEST_BYTES;

/// A request to the cell.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "command", rename_all = "snake_case", deny_unknown_fields)]
pub enum Request {
    /// The cell and axis status.
    Status,
    /// MC_Power: enable (`on`) or cleanly disable the named axes (every axis when none).
    Power {
        /// On or off.
        on: bool,
        /// Axis names; empty = the whole cell.
        #[serde(default)]
        axes: Vec<String>,
    },
    /// MC_MoveAbsolute / MC_MoveRelative: a time-synchronised move of the named axes.
    Move {
        /// Axis name → target (or distance when `relative`), in the axis unit.
        targets: BTreeMap<String, f64>,
        /// Targets are distances from the current position.
        #[serde(default)]
        relative: bool,
        /// Velocity limit of the move, unit/s (axis limit when absent).
        #[serde(
            default,
            deserialize_with = "number_or_absent",
            skip_serializing_if = "Option::is_none"
        )]
        velocity: Option<f64>,
        /// Acceleration limit of the move, unit/s² (axis limit when absent).
        #[serde(
            default,
            deserialize_with = "number_or_absent",
            skip_serializing_if = "Option::is_none"
        )]
        acceleration: Option<f64>,
        /// Jerk limit of the move, unit/s³ (axis limit when absent).
        #[serde(
            default,
            deserialize_with = "number_or_absent",
            skip_serializing_if = "Option::is_none"
        )]
        jerk: Option<f64>,
        /// Lower a limit above an axis limit to it instead of refusing the move.
        #[serde(default)]
        clamp: bool,
        /// A straight line in the axes' space (a gantry; all axes of one unit): `velocity` is
        /// then the path speed.
        #[serde(default)]
        line: bool,
    },
    /// A waypoint move from rest: through each waypoint but the last, to the last at rest
    /// (every waypoint names the same axes).
    Path {
        /// Axis name → position, per waypoint; the last is the target.
        waypoints: Vec<BTreeMap<String, f64>>,
        /// Velocity limit, unit/s (axis limit when absent).
        #[serde(
            default,
            deserialize_with = "number_or_absent",
            skip_serializing_if = "Option::is_none"
        )]
        velocity: Option<f64>,
        /// Acceleration limit, unit/s² (axis limit when absent).
        #[serde(
            default,
            deserialize_with = "number_or_absent",
            skip_serializing_if = "Option::is_none"
        )]
        acceleration: Option<f64>,
        /// Jerk limit, unit/s³ (axis limit when absent).
        #[serde(
            default,
            deserialize_with = "number_or_absent",
            skip_serializing_if = "Option::is_none"
        )]
        jerk: Option<f64>,
        /// Lower a limit above an axis limit to it instead of refusing.
        #[serde(default)]
        clamp: bool,
    },
    /// MC_MoveVelocity: jog one axis at a signed velocity until halted (or the range ends).
    Velocity {
        /// Axis name.
        axis: String,
        /// Velocity, unit/s (signed).
        velocity: f64,
        /// Acceleration of the ramp, unit/s² (axis limit when absent).
        #[serde(
            default,
            deserialize_with = "number_or_absent",
            skip_serializing_if = "Option::is_none"
        )]
        acceleration: Option<f64>,
        /// Lower a velocity above the axis limit to it instead of refusing.
        #[serde(default)]
        clamp: bool,
    },
    /// MC_TorqueControl: torque on cst axes, ramped at the axis slope, held, ramped to zero.
    Torque {
        /// Axis name → torque, % of rated torque.
        targets: BTreeMap<String, f64>,
        /// Seconds at the target torque.
        seconds: f64,
    },
    /// MC_Home: home one axis in its drive's homing mode (hm) with a method the drive's manual
    /// lists (the model's data-set method by default: home = the current position).
    Home {
        /// Axis name.
        axis: String,
        /// 6098h homing method (default: the model's data-set method).
        #[serde(default)]
        method: Option<i8>,
        /// Home setting by a Controlword2 edge instead of hm: "clear" (C_CR, home where the
        /// axis stands) or "clear_z" (C_CR2, home at the last Z phase); MR-J3-T04 §8.3.
        #[serde(default)]
        setting: Option<cellrt_cia402::homing::HomeSettingEdge>,
    },
    /// Switch a csp axis to pp (the drive positions it by its own profile) or back to csp, at
    /// standstill, by the drive's mode-switch rules.
    Mode {
        /// Axis name.
        axis: String,
        /// "pp" or "csp".
        mode: String,
    },
    /// MC_Halt: brake the motion (all axes, or the named ones) to rest; the cell stays usable.
    Halt {
        /// Axes to halt (all when empty).
        #[serde(default)]
        axes: Vec<String>,
    },
    /// MC_Stop: the RT thread's controlled stop; the motion is abandoned.
    Stop,
    /// MC_Reset: clear a stopped or faulted cell.
    Reset,
    /// MC_SetOverride: feed override, 0–100 %, applied smoothly.
    Override {
        /// Percent of the programmed velocity.
        percent: f64,
    },
    /// Run a program file (validated against the cell first).
    Program {
        /// The program (TOML).
        path: PathBuf,
    },
    /// Read (no `value`) or write one object of an axis' drive by SDO, checked against the
    /// drive's object dictionary first.
    Sdo {
        /// Axis name.
        axis: String,
        /// Object index.
        index: u16,
        /// Sub-index.
        #[serde(default)]
        sub: u8,
        /// The value to write; absent for a read.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        value: Option<i64>,
    },
    /// An axis' object dictionary: read from the drive by SDO Information where it offers
    /// it, else the drive profile's own table (the reply says which).
    SdoList {
        /// Axis name.
        axis: String,
    },
    /// The servo parameters of an axis' drive by their manual names (PA14, PC02, …), each
    /// read or written by SDO through the object that carries it.
    Param {
        /// Axis name.
        axis: String,
        /// What to do.
        op: ParamOp,
    },
    /// The alarm history of an axis' drive, or its clearing.
    Alarms {
        /// Axis name.
        axis: String,
        /// Clear the history instead of reading it.
        #[serde(default)]
        clear: bool,
    },
    /// The EtherCAT segment's diagnostics: per SubDevice its links, ESC error counters, AL
    /// status and DC time difference; the master's frame counters.
    BusDiag,
    /// Write the triggered recording's capture ring now (one file: the last `pre_s` seconds
    /// and the next `post_s`).
    Capture,
}

/// A `param` request's operation.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "op", rename_all = "snake_case", deny_unknown_fields)]
pub enum ParamOp {
    /// Every parameter of the model's table with its value.
    List,
    /// One parameter.
    Get {
        /// Its name, e.g. "PA14".
        name: String,
    },
    /// Writes one parameter (range-checked first).
    Set {
        /// Its name.
        name: String,
        /// The value.
        value: i64,
    },
    /// Stores every parameter in the drive's non-volatile memory (1010h).
    Save,
    /// The parameters whose value differs from the model's initial value.
    Diff,
}

impl Request {
    /// True for a request that writes to a drive's objects (`sdo write`, `param set`,
    /// `param save`, `alarms --clear`): refused while a program runs.
    pub fn writes_to_a_drive(&self) -> bool {
        match self {
            Request::Sdo { value, .. } => value.is_some(),
            Request::Param { op, .. } => matches!(op, ParamOp::Set { .. } | ParamOp::Save),
            Request::Alarms { clear, .. } => *clear,
            _ => false,
        }
    }

    /// The command's name (the `command` tag).
    pub fn name(&self) -> &'static str {
        match self {
            Request::Status => "status",
            Request::Power { .. } => "power",
            Request::Move { .. } => "move",
            Request::Path { .. } => "path",
            Request::Velocity { .. } => "velocity",
            Request::Torque { .. } => "torque",
            Request::Home { .. } => "home",
            Request::Mode { .. } => "mode",
            Request::Halt { .. } => "halt",
            Request::Stop => "stop",
            Request::Reset => "reset",
            Request::Override { .. } => "override",
            Request::Program { .. } => "program",
            Request::Sdo { .. } => "sdo",
            Request::SdoList { .. } => "sdo_list",
            Request::Param { .. } => "param",
            Request::Alarms { .. } => "alarms",
            Request::BusDiag => "bus_diag",
            Request::Capture => "capture",
        }
    }
}

/// The answer to a request.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "reply", rename_all = "snake_case")]
pub enum Reply {
    /// Taken; `id` names the command in the status.
    Accepted {
        /// Command id (increasing per cell run).
        id: u64,
    },
    /// Refused; nothing changed.
    Rejected {
        /// Why, naming what is wrong.
        reason: String,
    },
    /// The status.
    Status(Box<StatusReport>),
    /// How an SDO request ended at the drive.
    Sdo(SdoReply),
    /// The parameters read, written or saved.
    Param(ParamReply),
    /// The alarm history read or cleared.
    Alarms(AlarmsReply),
    /// The EtherCAT segment's diagnostics.
    BusDiag(Box<super::bus_diag::BusDiagReply>),
    /// An axis' object dictionary and where it came from.
    SdoList(Box<super::sdo_list::SdoListReply>),
}

impl Reply {
    /// A refusal whose reason is `e`'s message: where the service's typed errors become the
    /// text a client reads.
    pub fn rejected(e: impl std::fmt::Display) -> Reply {
        Reply::Rejected {
            reason: e.to_string(),
        }
    }
}

/// The answer to a `param` request.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamReply {
    /// Axis name.
    pub axis: String,
    /// Drive model.
    pub model: String,
    /// The parameters read or written (none for a save).
    pub parameters: Vec<ParamValue>,
    /// What happened beyond the values (a save, a value pending a power cycle).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// One parameter as the drive answered it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamValue {
    /// Number, e.g. "PA14".
    pub name: String,
    /// Abbreviation as the manual prints it ("*POL": `*` = after power cycle).
    pub symbol: String,
    /// The parameter's name.
    pub title: String,
    /// The carrying object, e.g. "2300h:0E".
    pub object: String,
    /// The value read or written; absent where the drive refused the read.
    pub value: Option<i64>,
    /// The value as the manual prints it, or the drive's refusal.
    pub shown: String,
    /// The manual's initial value, as printed.
    pub default: String,
    /// The values the manual allows.
    pub setting: String,
    /// Units of one LSB ("" where dimensionless).
    pub units: String,
    /// When a change takes effect ("immediately", "after power cycle").
    pub effect: String,
}

/// The answer to an `alarms` request.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AlarmsReply {
    /// Axis name.
    pub axis: String,
    /// Drive model.
    pub model: String,
    /// The history, newest first, empty entries left out; empty after a clear.
    pub entries: Vec<AlarmEntry>,
    /// The history was cleared.
    pub cleared: bool,
}

/// One alarm history entry.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AlarmEntry {
    /// Position in the history (0 = newest).
    pub entry: u8,
    /// Alarm No. as the drive reports it.
    pub number: u16,
    /// The alarm's display name and name from the manual ("AL.52 Error excessive"), or
    /// the number in hex where the profile does not name it.
    pub name: String,
    /// Hours of operation when it occurred.
    pub hours: u32,
    /// Alarm detail.
    pub detail: u16,
    /// The manual's cause, where it gives one.
    #[serde(default)]
    pub cause: Option<String>,
    /// The manual's remedy, where it gives one.
    #[serde(default)]
    pub remedy: Option<String>,
}

/// The answer of a drive to an SDO request.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SdoReply {
    /// Axis name.
    pub axis: String,
    /// Object index.
    pub index: u16,
    /// Sub-index.
    pub sub: u8,
    /// The object's name in the dictionary ("" where the dictionary lists none).
    pub name: String,
    /// The object's data type as CiA 301 names it (e.g. "UNSIGNED16").
    pub data_type: String,
    /// The type's size in bits (0 where unstated), for the value in hex.
    pub bits: u16,
    /// What happened.
    pub outcome: SdoAnswer,
}

/// What the drive did with an SDO request.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum SdoAnswer {
    /// The value read.
    Read {
        /// The value, typed by the object's data type.
        value: i64,
    },
    /// The value was written.
    Written {
        /// The value written.
        value: i64,
    },
    /// The drive refused: the CiA 301 abort code and its meaning.
    Aborted {
        /// Abort code.
        code: u32,
        /// CiA 301 meaning.
        meaning: String,
    },
}

/// Status of the cell as the operator sees it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StatusReport {
    /// Cell name.
    pub cell: String,
    /// RT cycle.
    pub cycle: u64,
    /// Cycle time, µs.
    pub cycle_time_us: f64,
    /// Cell state (`disabled`, `idle`, `moving`, …).
    pub state: String,
    /// Why the last stop happened, while stopped or faulted.
    pub stop_reason: Option<String>,
    /// Feed override, %.
    pub override_percent: f64,
    /// The command being executed.
    pub active_command: Option<ActiveCommand>,
    /// The last command that ended (done, failed or replaced).
    pub last_finished: Option<FinishedCommand>,
    /// The latest events, oldest first ("cycle N: kind [axis]: detail"; in-process only).
    #[serde(default)]
    pub recent_events: Vec<String>,
    /// Per axis, in configuration order, whichever backend moves it.
    pub axes: Vec<AxisStatus>,
}

/// The MR-JE-C link of an axis driven over one: its exchanges with the drive.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LinkStatus {
    /// Transport (`cclink-ief-basic`, `slmp`, `modbus-tcp`, `modbus-rtu`).
    pub transport: String,
    /// A move, jog or homing runs on the drive.
    pub busy: bool,
    /// Why the axis was stopped by its link watchdog or an alarm, if it was.
    pub stopped: Option<String>,
    /// Exchanges run.
    pub exchanges: u64,
    /// Exchanges without an answer.
    pub missed: u64,
    /// Of them, in a row now.
    pub missed_in_row: u32,
    /// The last round trip, µs.
    pub round_trip_us: f64,
}

/// A command in execution.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ActiveCommand {
    /// Its id.
    pub id: u64,
    /// Its name.
    pub command: String,
}

/// A command that ended.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FinishedCommand {
    /// Its id.
    pub id: u64,
    /// Its name.
    pub command: String,
    /// Why it did not complete (`None`: done).
    pub error: Option<String>,
}

/// Status of one axis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AxisStatus {
    /// Axis name.
    pub name: String,
    /// How its motion is carried out (`streamed`, `profile`, `mr-je-c link`).
    #[serde(default)]
    pub backend: String,
    /// Unit of positions.
    pub unit: String,
    /// The mode the controller runs the axis in: its configured one, or the one `mode` switched
    /// it to (csp, csv, cst, pp, pv, tq; on an MR-JE-C also jog, point_table, indexer).
    pub mode: String,
    /// Mode the drive displays (6061h: csp, csv, cst, hm, …; "?" where not mapped or unknown).
    #[serde(default)]
    pub mode_display: String,
    /// MC_Power is on for the axis.
    #[serde(default)]
    pub powered: bool,
    /// CiA 402 FSA state from the statusword.
    pub fsa: String,
    /// Position setpoint, unit (an axis whose drive runs its own profile: its actual position).
    pub setpoint: f64,
    /// Actual position, unit.
    pub position: f64,
    /// Actual velocity, unit/s.
    pub velocity: f64,
    /// Following error, unit (0 where the drive does not report it).
    pub following_error: f64,
    /// Alarm / error code (603Fh; 2A42h on an MR-JE-C), 0 when none.
    pub error_code: u16,
    /// The error code in words (the manual's number, name, cause and remedy where it lists
    /// them); `None` when there is none.
    #[serde(default)]
    pub alarm: Option<String>,
    /// The Status DO signals that are on (2D11h–2D13h: S_ZSP, S_INP, …), in the manual's order;
    /// empty where the drive does not map them.
    #[serde(default)]
    pub status_do: Vec<String>,
    /// Its MR-JE-C link, for an axis driven over one.
    #[serde(default)]
    pub link: Option<LinkStatus>,
}

/// An optional number: left out when not given. `null` is refused: a NaN or infinity encoded
/// as JSON arrives as `null` and must not turn into "not given".
fn number_or_absent<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
    f64::deserialize(d).map(Some)
}

/// Encodes a message.
pub fn encode<T: Serialize>(message: &T) -> Vec<u8> {
    serde_json::to_vec(message).expect("operator messages serialise")
}

/// What is wrong with a request that could not be decoded.
#[derive(Debug, thiserror::Error)]
pub enum MalformedRequest {
    /// Longer than [`MAX_OPERATOR_REQUEST_BYTES`] (bytes).
    #[error("malformed request: {0} bytes is more than the {max} allowed", max = MAX_OPERATOR_REQUEST_BYTES)]
    TooLong(usize),
    /// Not a request document.
    #[error("malformed request: {0}")]
    Json(#[from] serde_json::Error),
}

/// Decodes a request, naming what is wrong with a malformed one.
pub fn decode_request(bytes: &[u8]) -> Result<Request, MalformedRequest> {
    if bytes.len() > MAX_OPERATOR_REQUEST_BYTES {
        return Err(MalformedRequest::TooLong(bytes.len()));
    }
    Ok(serde_json::from_slice(bytes)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_limit_left_out_is_not_given_and_a_null_is_refused() {
        let given =
            decode_request(br#"{"command":"move","targets":{"x":100.0},"velocity":50.0}"#).unwrap();
        assert!(matches!(given, Request::Move { velocity: Some(v), .. } if v == 50.0));
        let absent = decode_request(br#"{"command":"move","targets":{"x":100.0}}"#).unwrap();
        assert!(matches!(absent, Request::Move { velocity: None, .. }));
        // serde_json writes NaN and infinities as null: such a request is refused.
        for field in ["velocity", "acceleration", "jerk"] {
            let text = format!(r#"{{"command":"move","targets":{{"x":100.0}},"{field}":null}}"#);
            let e = decode_request(text.as_bytes()).unwrap_err();
            assert!(e.to_string().contains("null"), "{field}: {e}");
        }
        let e = decode_request(
            br#"{"command":"velocity","axis":"x","velocity":1.0,"acceleration":null}"#,
        )
        .unwrap_err();
        assert!(e.to_string().contains("null"), "{e}");
        // What the CLI encodes for "not given" decodes as not given.
        let bytes = encode(&Request::Move {
            targets: BTreeMap::from([("x".to_string(), 1.0)]),
            relative: false,
            velocity: None,
            acceleration: Some(10.0),
            jerk: None,
            clamp: false,
            line: false,
        });
        assert!(!String::from_utf8_lossy(&bytes).contains("null"));
        assert!(matches!(
            decode_request(&bytes).unwrap(),
            Request::Move { velocity: None, acceleration: Some(a), .. } if a == 10.0
        ));
    }
}
