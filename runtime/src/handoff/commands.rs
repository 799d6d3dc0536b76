//! Commands from the non-RT threads to the RT thread: cell commands (PLCopen MC_Power,
//! MC_Stop, MC_Reset and the process' own) and homing requests, with the codes they travel and
//! are recorded as.

use cellrt_cia402::homing::{HomeProcedure, HomeSettingEdge};

use crate::setpoints::MAX_AXES;

/// What a non-RT thread asks of the cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq, strum::IntoStaticStr)]
#[strum(serialize_all = "snake_case")]
pub enum CellCommand {
    /// Bring every axis to Operation enabled (MC_Power on).
    PowerOn,
    /// Clean shutdown of every axis: Shutdown by controlword (MC_Power off).
    PowerOff,
    /// Controlled stop of any motion; the cell returns to Idle (MC_Stop).
    Stop,
    /// Clear a Stopped or Faulted cell (MC_Reset).
    Reset,
    /// Leave the RT loop (after PowerOff).
    Quit,
    /// The planner's node died or left: stop any motion, and start none until a planner is
    /// back (the link thread sends this).
    PlannerLost,
    /// A planner's node appeared (again): motions may start (the link thread sends this).
    PlannerConnected,
    /// Bring one axis (index) to Operation enabled, the others as they are (MC_Power on one
    /// axis).
    PowerOnAxis(u16),
    /// Clean shutdown of one axis (index); the cell powers off when no axis stays powered.
    PowerOffAxis(u16),
}

/// First code of [`CellCommand::PowerOnAxis`] (plus the axis index).
const POWER_ON_AXIS_CODE: i64 = 0x200;
/// First code of [`CellCommand::PowerOffAxis`] (plus the axis index).
const POWER_OFF_AXIS_CODE: i64 = 0x300;

impl CellCommand {
    /// Short name for events and messages.
    pub fn as_str(self) -> &'static str {
        self.into()
    }

    fn code(self) -> i64 {
        match self {
            CellCommand::PowerOn => 0,
            CellCommand::PowerOff => 1,
            CellCommand::Stop => 2,
            CellCommand::Reset => 3,
            CellCommand::Quit => 4,
            CellCommand::PlannerLost => 5,
            CellCommand::PlannerConnected => 6,
            CellCommand::PowerOnAxis(a) => POWER_ON_AXIS_CODE + i64::from(a),
            CellCommand::PowerOffAxis(a) => POWER_OFF_AXIS_CODE + i64::from(a),
        }
    }

    /// Inverse of the event value the RT thread records for a command.
    pub fn from_code(v: i64) -> Option<CellCommand> {
        let axis = |base: i64| {
            u16::try_from(v - base)
                .ok()
                .filter(|&a| usize::from(a) < MAX_AXES)
        };
        Some(match v {
            0 => CellCommand::PowerOn,
            1 => CellCommand::PowerOff,
            2 => CellCommand::Stop,
            3 => CellCommand::Reset,
            4 => CellCommand::Quit,
            5 => CellCommand::PlannerLost,
            6 => CellCommand::PlannerConnected,
            _ if (POWER_ON_AXIS_CODE..POWER_OFF_AXIS_CODE).contains(&v) => {
                CellCommand::PowerOnAxis(axis(POWER_ON_AXIS_CODE)?)
            }
            _ if (POWER_OFF_AXIS_CODE..POWER_OFF_AXIS_CODE + 0x100).contains(&v) => {
                CellCommand::PowerOffAxis(axis(POWER_OFF_AXIS_CODE)?)
            }
            _ => return None,
        })
    }

    /// The axis a per-axis command names.
    pub fn axis(self) -> Option<u16> {
        match self {
            CellCommand::PowerOnAxis(a) | CellCommand::PowerOffAxis(a) => Some(a),
            _ => None,
        }
    }

    /// Value recorded with command events.
    pub fn event_value(self) -> i64 {
        self.code()
    }
}

/// A homing request from the non-RT side, packed for [`HostEnd::request_homing`]
///
/// [`HostEnd::request_homing`]: super::HostEnd::request_homing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HomeRequest {
    /// Axis index.
    pub axis: u16,
    /// hm with a 6098h method, or a Controlword2 edge.
    pub procedure: HomeProcedure,
}

/// [`HomeRequest::procedure_code`] of a C_CR home setting (outside the i8 range of 6098h).
pub const HOME_BY_C_CR: i64 = 0x100;
/// [`HomeRequest::procedure_code`] of a C_CR2 home setting.
pub const HOME_BY_C_CR2: i64 = 0x101;

impl HomeRequest {
    /// Packed form (never 0): bit 31 set, bits 24–25 the procedure (0 hm, 1 C_CR, 2 C_CR2),
    /// bits 8–23 the axis, bits 0–7 the 6098h method.
    pub fn encode(self) -> u32 {
        let (kind, method) = match self.procedure {
            HomeProcedure::HomingMode(m) => (0, m),
            HomeProcedure::Controlword2(HomeSettingEdge::Clear) => (1, 0),
            HomeProcedure::Controlword2(HomeSettingEdge::ClearZ) => (2, 0),
        };
        0x8000_0000 | (kind << 24) | (u32::from(self.axis) << 8) | u32::from(method as u8)
    }

    /// Inverse of [`HomeRequest::encode`]; `None` for 0 (no request) or an unknown procedure.
    pub fn decode(v: u32) -> Option<HomeRequest> {
        if v & 0x8000_0000 == 0 {
            return None;
        }
        let procedure = match (v >> 24) & 0x7F {
            0 => HomeProcedure::HomingMode((v & 0xFF) as u8 as i8),
            1 => HomeProcedure::Controlword2(HomeSettingEdge::Clear),
            2 => HomeProcedure::Controlword2(HomeSettingEdge::ClearZ),
            _ => return None,
        };
        Some(HomeRequest {
            axis: ((v >> 8) & 0xFFFF) as u16,
            procedure,
        })
    }

    /// Value of the `HomingStarted` event: the 6098h method, or [`HOME_BY_C_CR`] /
    /// [`HOME_BY_C_CR2`].
    pub fn procedure_code(self) -> i64 {
        match self.procedure {
            HomeProcedure::HomingMode(m) => i64::from(m),
            HomeProcedure::Controlword2(HomeSettingEdge::Clear) => HOME_BY_C_CR,
            HomeProcedure::Controlword2(HomeSettingEdge::ClearZ) => HOME_BY_C_CR2,
        }
    }
}
