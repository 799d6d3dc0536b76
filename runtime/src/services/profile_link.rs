//! The profile axes' drive-side motions between an external planner and the controller: the
//! sample that carries one [`ProfileCommand`] and the `profile-commands` service.

use iceoryx2::node::Node;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::publish_subscribe;

use super::{service_error, ServiceError};
use crate::handoff::{ProfileCommand, ProfileMotion, SwitchableMode};
use crate::setpoints::MAX_AXES;

/// A profile axis' drive-side motion from an external planner to the controller: one
/// [`ProfileCommand`](crate::handoff::ProfileCommand) in a fixed layout (its encoding is here
/// and nowhere else).
#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("cellrt::ProfileLinkSample")]
pub struct ProfileLinkSample {
    /// The cycle it starts in (0: at once).
    pub start_cycle: u64,
    /// Move/jog: velocity, acceleration, deceleration (counts/s, counts/s²); torque: torque
    /// (%) and slope (%/s).
    pub values: [f64; 3],
    /// Move: 607Ah, counts.
    pub target: i32,
    /// Axis index.
    pub axis: u16,
    /// [`ProfileMotion::code`](crate::handoff::ProfileMotion::code).
    pub kind: u8,
    /// Move: 1 if the set-point replaces the running one at once (controlword bit 5).
    pub immediate: u8,
}

impl From<ProfileCommand> for ProfileLinkSample {
    fn from(c: ProfileCommand) -> Self {
        let mut s = ProfileLinkSample {
            start_cycle: c.start_cycle,
            axis: c.axis,
            kind: c.motion.code() as u8,
            ..ProfileLinkSample::default()
        };
        match c.motion {
            ProfileMotion::Move {
                target,
                velocity,
                acceleration,
                deceleration,
                immediate,
            } => {
                s.target = target;
                s.values = [velocity, acceleration, deceleration];
                s.immediate = u8::from(immediate);
            }
            ProfileMotion::Jog {
                velocity,
                acceleration,
                deceleration,
            } => s.values = [velocity, acceleration, deceleration],
            ProfileMotion::Torque { torque, slope } => s.values = [torque, slope, 0.0],
            ProfileMotion::Halt(_) | ProfileMotion::SwitchMode(_) => {}
        }
        s
    }
}

impl ProfileLinkSample {
    /// The command it carries; `None` for an unknown kind or a value that is not finite.
    pub fn command(&self) -> Option<ProfileCommand> {
        if self.values.iter().any(|v| !v.is_finite()) || self.immediate > 1 {
            return None;
        }
        let [a, b, c] = self.values;
        let motion = match self.kind {
            1 => ProfileMotion::Move {
                target: self.target,
                velocity: a,
                acceleration: b,
                deceleration: c,
                immediate: self.immediate == 1,
            },
            2 => ProfileMotion::Jog {
                velocity: a,
                acceleration: b,
                deceleration: c,
            },
            3 => ProfileMotion::Torque {
                torque: a,
                slope: b,
            },
            4 => ProfileMotion::Halt(true),
            5 => ProfileMotion::Halt(false),
            6 => ProfileMotion::SwitchMode(SwitchableMode::Pp),
            7 => ProfileMotion::SwitchMode(SwitchableMode::Csp),
            _ => return None,
        };
        Some(ProfileCommand {
            axis: self.axis,
            motion,
            start_cycle: self.start_cycle,
        })
    }
}

/// The service carrying profile axes' motions from an external planner to the controller.
pub fn profile_command_service_name(cell: &str) -> String {
    format!("cellrt/{cell}/profile-commands")
}

/// Profile commands the controller's link thread can have waiting: every profile axis of a
/// step twice over (the planner sends a step's commands at once and waits for their outcome).
const PROFILE_COMMAND_BUFFER: usize = 2 * MAX_AXES;

/// The external planner's publisher of profile commands.
pub fn profile_command_publisher(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<Publisher<ipc::Service, ProfileLinkSample, ()>, ServiceError> {
    profile_command_service(node, cell)?
        .publisher_builder()
        .create()
        .map_err(|e| service_error("profile command publisher", cell, e))
}

/// The controller's subscriber of profile commands.
pub fn profile_command_subscriber(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<Subscriber<ipc::Service, ProfileLinkSample, ()>, ServiceError> {
    profile_command_service(node, cell)?
        .subscriber_builder()
        .buffer_size(PROFILE_COMMAND_BUFFER)
        .create()
        .map_err(|e| service_error("profile command subscriber", cell, e))
}

fn profile_command_service(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<publish_subscribe::PortFactory<ipc::Service, ProfileLinkSample, ()>, ServiceError> {
    let name = profile_command_service_name(cell);
    let service_name =
        ServiceName::new(&name).map_err(|e| service_error("service name", cell, e))?;
    node.service_builder(&service_name)
        .publish_subscribe::<ProfileLinkSample>()
        .max_publishers(2)
        .max_subscribers(1)
        .history_size(0)
        .subscriber_max_buffer_size(PROFILE_COMMAND_BUFFER)
        .enable_safe_overflow(true)
        .open_or_create()
        .map_err(|e| service_error("service", cell, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every profile motion crosses the process boundary unchanged; a sample of an unknown
    /// kind or with a value that is not a number is refused.
    #[test]
    fn a_profile_command_round_trips_and_bad_samples_are_refused() {
        let motions = [
            ProfileMotion::Move {
                target: -123_456,
                velocity: 5000.5,
                acceleration: 1e5,
                deceleration: 2e5,
                immediate: true,
            },
            ProfileMotion::Jog {
                velocity: -300.0,
                acceleration: 10.0,
                deceleration: 20.0,
            },
            ProfileMotion::Torque {
                torque: -30.0,
                slope: 100.0,
            },
            ProfileMotion::Halt(true),
            ProfileMotion::Halt(false),
            ProfileMotion::SwitchMode(SwitchableMode::Pp),
            ProfileMotion::SwitchMode(SwitchableMode::Csp),
        ];
        for (k, motion) in motions.into_iter().enumerate() {
            let c = ProfileCommand {
                axis: k as u16 + 3,
                motion,
                start_cycle: 1 << 40,
            };
            assert_eq!(ProfileLinkSample::from(c).command(), Some(c));
        }
        let good = ProfileLinkSample::from(ProfileCommand {
            axis: 0,
            motion: motions[0],
            start_cycle: 0,
        });
        for bad in [
            ProfileLinkSample { kind: 0, ..good },
            ProfileLinkSample { kind: 8, ..good },
            ProfileLinkSample {
                values: [f64::NAN, 1.0, 1.0],
                ..good
            },
            ProfileLinkSample {
                values: [1.0, f64::INFINITY, 1.0],
                ..good
            },
            ProfileLinkSample {
                immediate: 2,
                ..good
            },
        ] {
            assert_eq!(bad.command(), None, "{bad:?}");
        }
    }
}
