//! One-touch tuning via the network (MR-JE-C manual §6.2; OV-20): 2D50h = 1–3 starts it, 2D51h
//! reports its progress and reads 100 % at the end "regardless of whether one-touch tuning is
//! properly completed or not", 2D50h returns to 0, 2D54h gives the result, and 2D52h = 1EA5h
//! stops it. The emulator changes no gains: a tuning completes after
//! [`MrJeCParams::one_touch_tuning_time`](super::MrJeCParams) of motor motion (the manual gives
//! no duration; the real tuning measures the motion the controller commands meanwhile).

use std::time::Duration;

/// 2D54h: finished normally.
pub const FINISHED: u16 = 0x0000;
/// 2D54h: tuning canceled (2D52h = 1EA5h).
pub const CANCELED: u16 = 0xC000;
/// 2D54h: servo-off during tuning. Also the emulator's answer to a start outside Operation
/// enabled (the manual names no code for it).
pub const SERVO_OFF: u16 = 0xC002;
/// 2D54h: control mode error, given for a start in profile torque mode (tq): the companion
/// instruction manual's one-touch tuning is for position and speed control [INFER].
pub const CONTROL_MODE: u16 = 0xC003;

/// The tuning's state.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct OneTouchTuning {
    /// The running tuning's 2D50h (1 basic, 2 high, 3 low); 0 when none runs.
    mode: u8,
    /// Motor motion seen since the start.
    moved: Duration,
    /// 2D51h, %.
    progress: u8,
    /// 2D54h.
    error: u16,
}

impl OneTouchTuning {
    /// 2D50h written with `mode` (1–3): starts unless the servo is off or the drive runs tq,
    /// which end it at once with [`SERVO_OFF`] / [`CONTROL_MODE`].
    pub fn start(&mut self, mode: u8, servo_on: bool, torque_mode: bool) {
        *self = OneTouchTuning {
            mode,
            ..OneTouchTuning::default()
        };
        if !servo_on {
            self.end(SERVO_OFF);
        } else if torque_mode {
            self.end(CONTROL_MODE);
        }
    }

    /// `dt` of drive time in Operation enabled (`moving`: the motor turned); completes after
    /// `time` of motion.
    pub fn advance(&mut self, dt: Duration, moving: bool, time: Duration) {
        if self.mode == 0 || !moving {
            return;
        }
        self.moved += dt;
        if self.moved >= time {
            self.end(FINISHED);
        } else {
            let share = self.moved.as_secs_f64() / time.as_secs_f64().max(f64::MIN_POSITIVE);
            self.progress = (share * 100.0).floor().min(99.0) as u8;
        }
    }

    /// The servo went off: a running tuning ends with [`SERVO_OFF`].
    pub fn servo_off(&mut self) {
        if self.mode != 0 {
            self.end(SERVO_OFF);
        }
    }

    /// 2D52h = 1EA5h: a running tuning ends with [`CANCELED`].
    pub fn stop(&mut self) {
        if self.mode != 0 {
            self.end(CANCELED);
        }
    }

    fn end(&mut self, error: u16) {
        self.mode = 0;
        self.progress = 100;
        self.error = error;
    }

    /// 2D50h as read: the running tuning's mode, 0 when none runs.
    pub fn mode(&self) -> u8 {
        self.mode
    }

    /// 2D51h, %.
    pub fn progress(&self) -> u8 {
        self.progress
    }

    /// 2D54h.
    pub fn error(&self) -> u16 {
        self.error
    }
}
