//! One cycle's RxPDO of an axis, built in one place for the live loop and `cellrt replay`:
//! what the loop decides cycle by cycle, plus what the axis' configuration fixes (2D20h speed
//! limit, 60E0h/60E1h torque limits), so that a replay sends what the loop sent.

use cellrt_cia402::controlword::Controlword;
use cellrt_cia402::pdo::RxPdo;

use super::AxisChannel;

/// What an axis sends in one cycle that changes cycle by cycle (all as sent, raw).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CycleCommand {
    /// 6060h.
    pub mode: i8,
    /// 6040h.
    pub controlword: Controlword,
    /// 607Ah, counts as the drive counts them.
    pub target_position: i32,
    /// 60FFh in the drive's velocity unit.
    pub target_velocity: i32,
    /// 6071h, 0.1 % of rated torque.
    pub target_torque: i16,
    /// 2001h / 2D01h Controlword2: torque-limit selection and home-setting bits.
    pub controlword2: u16,
    /// The incremental counter.
    pub counter: u8,
}

impl AxisChannel {
    /// The RxPDO of one cycle: `cmd` with the axis' configured speed and torque limits.
    pub fn rx_pdo(&self, cmd: &CycleCommand) -> RxPdo {
        RxPdo {
            mode: cmd.mode,
            controlword: cmd.controlword,
            target_position: cmd.target_position,
            target_velocity: cmd.target_velocity,
            target_torque: cmd.target_torque,
            velocity_limit: self.velocity_limit(),
            torque_limit_positive: self.torque_limit_objects.0,
            torque_limit_negative: self.torque_limit_objects.1,
            controlword2: cmd.controlword2,
            counter: cmd.counter,
            ..RxPdo::default()
        }
    }

    /// Controlword2's bits that the configuration fixes (the torque-limit selection).
    pub fn static_controlword2(&self) -> u16 {
        self.torque_limit_objects.2
    }
}
