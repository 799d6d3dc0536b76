//! The MR-JE-C axes between an external planner and the controller that runs their threads:
//! the planner's commands one [`AxisCommand`] a sample (`je-c-commands`), the axes' feedback
//! one [`AxisFeedback`] a sample (`je-c-feedback`). Both carry the link's version and the
//! cell's MR-JE-C shape ([`je_c_shape`]), so a planner of another configuration is refused.
//! Their encodings are here and nowhere else.

use iceoryx2::node::Node;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::publish_subscribe;

use cellrt_fieldbus::mr_je_c::cell::{AxisCommand, AxisFeedback, Inputs, Stopped};

use super::{service_error, ServiceError};
use crate::setpoints::MAX_AXES;
use cellrt_config::je_c_axis::JecAxisConfig;

/// The version of both samples' layout and meaning; a peer of another version is refused.
pub const JE_C_LINK_VERSION: u32 = 1;

/// The cell's MR-JE-C axes as both processes must see them: a hash (FNV-1a) of each axis'
/// name, transport and scaling in order, so commands in drive units reach the axis the
/// planner meant, scaled as it scaled them.
pub fn je_c_shape(axes: &[JecAxisConfig]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |bytes: &[u8]| {
        for b in bytes {
            h ^= u64::from(*b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    };
    for a in axes {
        eat(a.name.as_bytes());
        eat(&[0]);
        eat(a.transport.name().as_bytes());
        eat(&[0]);
        eat(&a.counts_per_unit.to_bits().to_le_bytes());
        eat(&a.counts_per_rev.to_bits().to_le_bytes());
        eat(&a.rated_speed.to_bits().to_le_bytes());
        eat(a.mode.name().as_bytes());
        if let cellrt_config::je_c_axis::JecMode::Indexer { stations } = a.mode {
            eat(&[stations]);
        }
        for t in &a.point_tables {
            for v in [t.position, t.velocity, t.acceleration, t.deceleration] {
                eat(&v.to_bits().to_le_bytes());
            }
            eat(&[t.m_code]);
        }
        eat(&[0]);
    }
    h
}

/// One command of an external planner for one MR-JE-C axis of the controller.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, ZeroCopySend)]
#[repr(C)]
#[type_name("cellrt::JecCommandSample")]
pub struct JecCommandSample {
    /// The planner's sequence number, from 1 (a gap: a command was lost on the way).
    pub seq: u64,
    /// The planner's [`je_c_shape`].
    pub shape: u64,
    /// The command's values in drive units (see [`JecCommandSample::command`]).
    pub values: [i64; 4],
    /// [`JE_C_LINK_VERSION`] of the planner.
    pub version: u32,
    /// Link of the MR-JE-C axis (`CellAxes::on_link`).
    pub axis: u16,
    /// The command: 1 power on, 2 power off, 3 move, 4 velocity, 5 torque, 6 home, 7 halt,
    /// 8 reset, 9 point table, 10 station, 11 jog, 12 override, 13 quick stop.
    pub kind: u8,
    /// Padding (0).
    pub reserved: u8,
}

impl JecCommandSample {
    /// The sample carrying `c` for axis `axis`.
    pub fn new(seq: u64, shape: u64, axis: u16, c: AxisCommand) -> Self {
        let (kind, values) = match c {
            AxisCommand::PowerOn => (1, [0; 4]),
            AxisCommand::PowerOff => (2, [0; 4]),
            AxisCommand::Move {
                target,
                velocity,
                acceleration_ms,
                deceleration_ms,
            } => (
                3,
                [
                    target.into(),
                    velocity.into(),
                    acceleration_ms.into(),
                    deceleration_ms.into(),
                ],
            ),
            AxisCommand::Velocity {
                velocity,
                acceleration_ms,
                deceleration_ms,
            } => (
                4,
                [
                    velocity.into(),
                    acceleration_ms.into(),
                    deceleration_ms.into(),
                    0,
                ],
            ),
            AxisCommand::Torque {
                torque,
                slope,
                velocity_limit,
            } => (5, [torque.into(), slope.into(), velocity_limit.into(), 0]),
            AxisCommand::Home => (6, [0; 4]),
            AxisCommand::Halt => (7, [0; 4]),
            AxisCommand::Reset => (8, [0; 4]),
            AxisCommand::PointTable { table } => (9, [table.into(), 0, 0, 0]),
            AxisCommand::Station {
                station,
                velocity,
                acceleration_ms,
                deceleration_ms,
            } => (
                10,
                [
                    station.into(),
                    velocity.into(),
                    acceleration_ms.into(),
                    deceleration_ms.into(),
                ],
            ),
            AxisCommand::Jog {
                velocity,
                reverse,
                acceleration_ms,
                deceleration_ms,
            } => (
                11,
                [
                    velocity.into(),
                    reverse.into(),
                    acceleration_ms.into(),
                    deceleration_ms.into(),
                ],
            ),
            AxisCommand::Override { permille } => (12, [permille.into(), 0, 0, 0]),
            AxisCommand::QuickStop => (13, [0; 4]),
        };
        JecCommandSample {
            seq,
            shape,
            values,
            version: JE_C_LINK_VERSION,
            axis,
            kind,
            reserved: 0,
        }
    }

    /// The command it carries; `None` for an unknown kind or a value outside its object's type.
    pub fn command(&self) -> Option<AxisCommand> {
        let [a, b, c, d] = self.values;
        Some(match self.kind {
            1 => AxisCommand::PowerOn,
            2 => AxisCommand::PowerOff,
            3 => AxisCommand::Move {
                target: a.try_into().ok()?,
                velocity: b.try_into().ok()?,
                acceleration_ms: c.try_into().ok()?,
                deceleration_ms: d.try_into().ok()?,
            },
            4 => AxisCommand::Velocity {
                velocity: a.try_into().ok()?,
                acceleration_ms: b.try_into().ok()?,
                deceleration_ms: c.try_into().ok()?,
            },
            5 => AxisCommand::Torque {
                torque: a.try_into().ok()?,
                slope: b.try_into().ok()?,
                velocity_limit: c.try_into().ok()?,
            },
            6 => AxisCommand::Home,
            7 => AxisCommand::Halt,
            8 => AxisCommand::Reset,
            9 => AxisCommand::PointTable {
                table: a.try_into().ok()?,
            },
            10 => AxisCommand::Station {
                station: a.try_into().ok()?,
                velocity: b.try_into().ok()?,
                acceleration_ms: c.try_into().ok()?,
                deceleration_ms: d.try_into().ok()?,
            },
            11 => AxisCommand::Jog {
                velocity: a.try_into().ok()?,
                reverse: match b {
                    0 => false,
                    1 => true,
                    _ => return None,
                },
                acceleration_ms: c.try_into().ok()?,
                deceleration_ms: d.try_into().ok()?,
            },
            12 => match u16::try_from(a).ok()? {
                p if p <= cellrt_fieldbus::mr_je_c::cell::control::FULL_FEED => {
                    AxisCommand::Override { permille: p }
                }
                _ => return None,
            },
            13 => AxisCommand::QuickStop,
            _ => return None,
        })
    }
}

/// One MR-JE-C axis' latest feedback from the controller to an external planner.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, ZeroCopySend)]
#[repr(C)]
#[type_name("cellrt::JecFeedbackSample")]
pub struct JecFeedbackSample {
    /// The controller's [`je_c_shape`].
    pub shape: u64,
    /// Exchanges run.
    pub cycles: u64,
    /// Exchanges without an answer, in all.
    pub missed: u64,
    /// Exchanges the drive refused.
    pub refused: u64,
    /// The last round trip, ns.
    pub round_trip_ns: u64,
    /// The longest round trip, ns.
    pub max_round_trip_ns: u64,
    /// Commands for the axis the controller could not take (undecodable, queue full).
    pub commands_dropped: u64,
    /// 6064h, pos units.
    pub position: i32,
    /// 606Ch, 0.01 r/min.
    pub velocity: i32,
    /// Jobs ended done.
    pub done: u32,
    /// Jobs ended failed.
    pub failed: u32,
    /// Misses in a row now.
    pub missed_in_row: u32,
    /// The stop's value (misses in a row, or the alarm).
    pub stopped_value: u32,
    /// [`JE_C_LINK_VERSION`] of the controller.
    pub version: u32,
    /// The controller's MR-JE-C axes.
    pub axis_count: u16,
    /// Index of the axis.
    pub axis: u16,
    /// 6041h.
    pub statusword: u16,
    /// 2A42h.
    pub alarm: u16,
    /// 1: Operation enabled.
    pub enabled: u8,
    /// 1: a job runs.
    pub busy: u8,
    /// The stop in force: 0 none, 1 communication lost, 2 drive alarm, 3 controller lost.
    pub stopped_kind: u8,
    /// Padding (0).
    pub reserved: u8,
}

impl JecFeedbackSample {
    /// The sample carrying axis `axis`' feedback `f` of a controller with `axis_count` axes of
    /// shape `shape`.
    pub fn new(
        shape: u64,
        axis_count: u16,
        axis: u16,
        f: &AxisFeedback,
        commands_dropped: u64,
    ) -> Self {
        let (stopped_kind, stopped_value) = match f.stopped {
            None => (0, 0),
            Some(Stopped::CommunicationLost(n)) => (1, n),
            Some(Stopped::DriveAlarm(a)) => (2, u32::from(a)),
            Some(Stopped::ControllerLost) => (3, 0),
        };
        JecFeedbackSample {
            shape,
            cycles: f.cycles,
            missed: f.missed,
            refused: f.refused,
            round_trip_ns: f.round_trip_ns,
            max_round_trip_ns: f.max_round_trip_ns,
            commands_dropped,
            position: f.inputs.position,
            velocity: f.inputs.velocity,
            done: f.done,
            failed: f.failed,
            missed_in_row: f.missed_in_row,
            stopped_value,
            version: JE_C_LINK_VERSION,
            axis_count,
            axis,
            statusword: f.inputs.statusword,
            alarm: f.inputs.alarm,
            enabled: u8::from(f.enabled),
            busy: u8::from(f.busy),
            stopped_kind,
            reserved: 0,
        }
    }

    /// The feedback it carries; `None` for a flag or stop that does not decode.
    pub fn feedback(&self) -> Option<AxisFeedback> {
        let flag = |v: u8| match v {
            0 => Some(false),
            1 => Some(true),
            _ => None,
        };
        let stopped = match self.stopped_kind {
            0 => None,
            1 => Some(Stopped::CommunicationLost(self.stopped_value)),
            2 => Some(Stopped::DriveAlarm(self.stopped_value.try_into().ok()?)),
            3 => Some(Stopped::ControllerLost),
            _ => return None,
        };
        Some(AxisFeedback {
            cycles: self.cycles,
            inputs: Inputs {
                statusword: self.statusword,
                position: self.position,
                velocity: self.velocity,
                alarm: self.alarm,
            },
            enabled: flag(self.enabled)?,
            busy: flag(self.busy)?,
            done: self.done,
            failed: self.failed,
            stopped,
            missed: self.missed,
            missed_in_row: self.missed_in_row,
            refused: self.refused,
            round_trip_ns: self.round_trip_ns,
            max_round_trip_ns: self.max_round_trip_ns,
        })
    }
}

/// The service carrying an external planner's MR-JE-C commands to the controller.
pub fn je_c_command_service_name(cell: &str) -> String {
    format!("cellrt/{cell}/je-c-commands")
}

/// The service carrying the MR-JE-C axes' feedback from the controller to an external planner.
pub fn je_c_feedback_service_name(cell: &str) -> String {
    format!("cellrt/{cell}/je-c-feedback")
}

/// Commands the controller's link thread can have waiting: each axis' command queue (16) for
/// the first 16 axes; the planner sends a step's commands at once and waits for their outcome.
const COMMAND_BUFFER: usize = 256;
/// Feedback samples a planner can have waiting: every axis twice (the controller sends each
/// axis at least every 20 ms, the planner takes them every millisecond; the latest counts).
const FEEDBACK_BUFFER: usize = 2 * MAX_AXES;
/// Ports of each side: a restarted planner while its dead predecessor's are not cleaned up.
const PORTS: usize = 4;

fn service<T: std::fmt::Debug + ZeroCopySend>(
    node: &Node<ipc::Service>,
    cell: &str,
    name: &str,
    buffer: usize,
) -> Result<publish_subscribe::PortFactory<ipc::Service, T, ()>, ServiceError> {
    let service_name =
        ServiceName::new(name).map_err(|e| service_error("service name", cell, e))?;
    node.service_builder(&service_name)
        .publish_subscribe::<T>()
        .max_publishers(PORTS)
        .max_subscribers(PORTS)
        .history_size(0)
        .subscriber_max_buffer_size(buffer)
        .enable_safe_overflow(true)
        .open_or_create()
        .map_err(|e| service_error("MR-JE-C link service", cell, e))
}

/// A publisher of `name` (never waits for a slow subscriber).
fn publisher<T: std::fmt::Debug + ZeroCopySend>(
    node: &Node<ipc::Service>,
    cell: &str,
    (name, buffer, what): (&str, usize, &'static str),
) -> Result<Publisher<ipc::Service, T, ()>, ServiceError> {
    service::<T>(node, cell, name, buffer)?
        .publisher_builder()
        .backpressure_strategy(BackpressureStrategy::DiscardData)
        .create()
        .map_err(|e| service_error(what, cell, e))
}

/// A subscriber of `name` holding `buffer` samples.
fn subscriber<T: std::fmt::Debug + ZeroCopySend>(
    node: &Node<ipc::Service>,
    cell: &str,
    (name, buffer, what): (&str, usize, &'static str),
) -> Result<Subscriber<ipc::Service, T, ()>, ServiceError> {
    service::<T>(node, cell, name, buffer)?
        .subscriber_builder()
        .buffer_size(buffer)
        .create()
        .map_err(|e| service_error(what, cell, e))
}

/// The external planner's publisher of MR-JE-C commands.
pub fn je_c_command_publisher(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<Publisher<ipc::Service, JecCommandSample, ()>, ServiceError> {
    let name = je_c_command_service_name(cell);
    publisher(
        node,
        cell,
        (&name, COMMAND_BUFFER, "MR-JE-C command publisher"),
    )
}

/// The controller's subscriber of MR-JE-C commands.
pub fn je_c_command_subscriber(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<Subscriber<ipc::Service, JecCommandSample, ()>, ServiceError> {
    let name = je_c_command_service_name(cell);
    subscriber(
        node,
        cell,
        (&name, COMMAND_BUFFER, "MR-JE-C command subscriber"),
    )
}

/// The controller's publisher of MR-JE-C feedback.
pub fn je_c_feedback_publisher(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<Publisher<ipc::Service, JecFeedbackSample, ()>, ServiceError> {
    let name = je_c_feedback_service_name(cell);
    publisher(
        node,
        cell,
        (&name, FEEDBACK_BUFFER, "MR-JE-C feedback publisher"),
    )
}

/// The external planner's subscriber of MR-JE-C feedback.
pub fn je_c_feedback_subscriber(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<Subscriber<ipc::Service, JecFeedbackSample, ()>, ServiceError> {
    let name = je_c_feedback_service_name(cell);
    subscriber(
        node,
        cell,
        (&name, FEEDBACK_BUFFER, "MR-JE-C feedback subscriber"),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every MR-JE-C command crosses the process boundary unchanged; a sample of an unknown
    /// kind or with a value outside its object's type is refused.
    #[test]
    fn a_je_c_command_round_trips_and_bad_samples_are_refused() {
        let commands = [
            AxisCommand::PowerOn,
            AxisCommand::PowerOff,
            AxisCommand::Move {
                target: i32::MIN,
                velocity: u32::MAX,
                acceleration_ms: 7,
                deceleration_ms: 9,
            },
            AxisCommand::Velocity {
                velocity: -300_000,
                acceleration_ms: 10,
                deceleration_ms: 20,
            },
            AxisCommand::Torque {
                torque: -200,
                slope: 1000,
                velocity_limit: 50_000,
            },
            AxisCommand::Home,
            AxisCommand::Halt,
            AxisCommand::Reset,
            AxisCommand::PointTable { table: 255 },
            AxisCommand::Station {
                station: 7,
                velocity: 12_000,
                acceleration_ms: 30,
                deceleration_ms: 40,
            },
            AxisCommand::Jog {
                velocity: 5000,
                reverse: true,
                acceleration_ms: 50,
                deceleration_ms: 60,
            },
            AxisCommand::Override { permille: 1000 },
            AxisCommand::QuickStop,
        ];
        for (k, c) in commands.into_iter().enumerate() {
            let s = JecCommandSample::new(k as u64 + 1, 42, k as u16, c);
            assert_eq!(s.command(), Some(c), "{s:?}");
            assert_eq!((s.axis, s.seq, s.shape), (k as u16, k as u64 + 1, 42));
        }
        let good = JecCommandSample::new(1, 0, 0, commands[2]);
        for bad in [
            JecCommandSample { kind: 0, ..good },
            JecCommandSample { kind: 14, ..good },
            JecCommandSample {
                kind: 11,
                values: [5000, 2, 50, 60],
                ..good
            },
            JecCommandSample {
                kind: 12,
                values: [1001, 0, 0, 0],
                ..good
            },
            JecCommandSample {
                values: [i64::from(i32::MAX) + 1, 0, 0, 0],
                ..good
            },
            JecCommandSample {
                values: [0, -1, 0, 0],
                ..good
            },
            JecCommandSample {
                kind: 5,
                values: [40_000, 0, 0, 0],
                ..good
            },
        ] {
            assert_eq!(bad.command(), None, "{bad:?}");
        }
    }

    /// An axis' feedback, stops included, crosses unchanged; a flag or stop that does not
    /// decode is refused.
    #[test]
    fn je_c_feedback_round_trips_and_bad_samples_are_refused() {
        let base = AxisFeedback {
            cycles: 1 << 40,
            inputs: Inputs {
                statusword: 0x1637,
                position: -123_456,
                velocity: 30_000,
                alarm: 0,
            },
            enabled: true,
            busy: true,
            done: 7,
            failed: 2,
            stopped: None,
            missed: 5,
            missed_in_row: 1,
            refused: 3,
            round_trip_ns: 1_000_000,
            max_round_trip_ns: 9_000_000,
        };
        for stopped in [
            None,
            Some(Stopped::CommunicationLost(5)),
            Some(Stopped::DriveAlarm(0x861)),
            Some(Stopped::ControllerLost),
        ] {
            let f = AxisFeedback { stopped, ..base };
            let s = JecFeedbackSample::new(9, 2, 1, &f, 4);
            assert_eq!(s.feedback(), Some(f));
            assert_eq!((s.shape, s.axis_count, s.axis), (9, 2, 1));
            assert_eq!(s.commands_dropped, 4);
        }
        let good = JecFeedbackSample::new(9, 2, 1, &base, 0);
        for bad in [
            JecFeedbackSample { enabled: 2, ..good },
            JecFeedbackSample { busy: 7, ..good },
            JecFeedbackSample {
                stopped_kind: 4,
                ..good
            },
            JecFeedbackSample {
                stopped_kind: 2,
                stopped_value: 0x1_0000,
                ..good
            },
        ] {
            assert_eq!(bad.feedback(), None, "{bad:?}");
        }
    }

    /// The shape tells apart configurations whose commands would reach another axis or be
    /// scaled otherwise.
    #[test]
    fn the_je_c_shape_follows_names_order_and_scaling() {
        let cell = cellrt_config::CellConfig::load(std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../configs/mixed-cell.toml"
        )))
        .expect("mixed cell");
        let axes = cell.axes.on_link().to_vec();
        assert_eq!(axes.len(), 2);
        let shape = je_c_shape(&axes);
        assert_eq!(shape, je_c_shape(cell.axes.on_link()));
        let swapped = vec![axes[1].clone(), axes[0].clone()];
        let mut renamed = axes.clone();
        renamed[0].name = "infeed2".into();
        let mut rescaled = axes.clone();
        rescaled[1].counts_per_unit *= 2.0;
        for other in [&swapped, &renamed, &rescaled, &axes[..1].to_vec()] {
            assert_ne!(je_c_shape(other), shape);
        }
    }
}
