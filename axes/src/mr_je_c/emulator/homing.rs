//! Homing mode (hm, 6060h = 6; MR-JE-C manual §7.3 6098h–609Ah, 60E3h, §7.6.3): a rising edge
//! of Controlword bit 4 (Homing Operation Start) runs the method in 6098h. Only method 37 is
//! emulated: the current position becomes the home position 607Ch and the homing completes at
//! once. The manual lists no method beyond the default 37 (it refers to the Profile Mode
//! manual), so every other method ends in a homing error (Statusword bit 13) without motion.
//! The motor in hm decelerates with 609Ah, and Halt (bit 8) blocks a start until bit 4 has
//! gone 0 → 1 again with the halt off (§7.6.3).

use super::motion::Profile;

/// 6098h: homing on the current position (CiA 402 method 37, the drive's default).
pub const CURRENT_POSITION: i64 = 37;

/// The outcome of the last homing start.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum HomingStatus {
    /// No homing started since power-on (or since it was interrupted).
    #[default]
    NotStarted,
    /// The home position is set.
    Attained,
    /// The method is not emulated: homing error.
    Error,
}

/// hm's state.
#[derive(Debug, Clone, Default)]
pub struct Homing {
    status: HomingStatus,
    homed: bool,
    /// 609Ah as taken at the last Homing Operation Start (§7.6.3).
    acceleration_ms: Option<i64>,
}

impl Homing {
    /// Homing Operation Start (bit 4 rising edge, halt off): the home position 6064h now
    /// reads, or `None` after a homing error.
    pub fn start(&mut self, p: &Profile) -> Option<i64> {
        self.acceleration_ms = Some(p.homing_acceleration_ms);
        if p.homing_method == CURRENT_POSITION {
            self.status = HomingStatus::Attained;
            self.homed = true;
            Some(p.home_offset)
        } else {
            self.status = HomingStatus::Error;
            None
        }
    }

    /// A home position return has completed since power-on (the emulator is an incremental
    /// system: power-off loses the home).
    pub fn homed(&self) -> bool {
        self.homed
    }

    /// The last start's outcome.
    pub fn status(&self) -> HomingStatus {
        self.status
    }

    /// The deceleration in hm, including Halt: 609Ah as taken at the last start, else as set.
    pub fn deceleration_ms(&self, p: &Profile) -> i64 {
        self.acceleration_ms.unwrap_or(p.homing_acceleration_ms)
    }

    /// Statusword bits 10 (target reached), 12 (homing attained) and 13 (homing error) as
    /// CiA 402 gives them [EXT: CiA 402; MR-JE-C manual §7.3 names the bits only "operation
    /// mode specific"]: bit 10 on with the motor standing.
    pub fn status_bits(&self, standing: bool) -> u16 {
        let attained = self.status == HomingStatus::Attained;
        let error = self.status == HomingStatus::Error;
        (u16::from(standing) << 10) | (u16::from(attained) << 12) | (u16::from(error) << 13)
    }
}

#[cfg(test)]
mod tests {
    use super::super::fixture::{cw, pp, run, run_halted};
    use super::super::motion::{Motion, HOMING, PROFILE_VELOCITY};
    use super::*;

    fn hm() -> Profile {
        Profile {
            mode: HOMING,
            ..pp()
        }
    }

    #[test]
    fn method_37_makes_the_current_position_home_at_once() {
        let mut p = pp();
        let mut m = Motion::default();
        m.controlword(cw(0x1F), cw(0x0F), &p);
        run(&mut m, &p, 300);
        assert_eq!(m.position(), 131_072);
        p = hm();
        p.home_offset = 500;
        m.mode_changed();
        m.controlword(cw(0x0F), cw(0x1F), &p);
        assert_eq!(m.status_bits(&p, false), 1 << 10, "not started");
        m.controlword(cw(0x1F), cw(0x0F), &p);
        assert_eq!(m.position(), 500, "6064h reads the home position 607Ch");
        assert!(m.homed());
        assert_eq!(m.status_bits(&p, false), (1 << 10) | (1 << 12));
        run(&mut m, &p, 10);
        assert_eq!(m.position(), 500, "no motion");
    }

    #[test]
    fn a_method_not_emulated_is_a_homing_error_without_motion() {
        let mut p = hm();
        p.homing_method = 35;
        let mut m = Motion::default();
        m.controlword(cw(0x1F), cw(0x0F), &p);
        assert!(!m.homed());
        assert_eq!(m.status_bits(&p, false), (1 << 10) | (1 << 13));
        run(&mut m, &p, 10);
        assert_eq!(m.position(), 0);
        p.homing_method = -1;
        m.controlword(cw(0x0F), cw(0x1F), &p);
        m.controlword(cw(0x1F), cw(0x0F), &p);
        assert_eq!(m.status_bits(&p, false) & (1 << 13), 1 << 13);
    }

    #[test]
    fn halt_blocks_the_start_until_bit_4_rises_again_with_halt_off() {
        let p = hm();
        let mut m = Motion::default();
        m.controlword(cw(0x11F), cw(0x10F), &p);
        assert!(!m.homed(), "a start with the halt on does nothing");
        m.controlword(cw(0x1F), cw(0x11F), &p);
        assert!(!m.homed(), "halt off with bit 4 still on does not start");
        m.controlword(cw(0x0F), cw(0x1F), &p);
        m.controlword(cw(0x1F), cw(0x0F), &p);
        assert!(m.homed());
    }

    #[test]
    fn the_motor_in_hm_decelerates_with_609ah() {
        let mut p = pp();
        p.mode = PROFILE_VELOCITY;
        p.target_velocity = 300_000; // the rated speed, 50 rev/s
        p.acceleration_ms = 0;
        p.deceleration_ms = 0;
        let mut m = Motion::default();
        run(&mut m, &p, 1);
        assert_eq!(m.velocity(&p), 300_000);
        p.mode = HOMING;
        p.homing_acceleration_ms = 200;
        m.mode_changed();
        run_halted(&mut m, &p, 100, true);
        // 200 ms from the rated speed to 0: half of it after 100 ms.
        assert_eq!(m.velocity(&p), 150_000);
        run_halted(&mut m, &p, 100, true);
        assert_eq!(m.velocity(&p), 0);
        assert_eq!(m.status_bits(&p, true), 1 << 10);
    }
}
