//! Homing mode (hm, 6060h = 6; MR-JE-C manual §7.3 6098h–609Ah, 60E3h, §7.6.3): a rising edge
//! of Controlword bit 4 (Homing Operation Start) runs the method in 6098h. Only method 37 is
//! emulated (the shared homing start, `motion::homing`): the current position becomes the home
//! position 607Ch and the homing completes at once. The manual lists no method beyond the default 37 (it refers to the Profile Mode
//! manual), so every other method ends in a homing error (Statusword bit 13) without motion.
//! The motor in hm decelerates with 609Ah, and Halt (bit 8) blocks a start until bit 4 has
//! gone 0 → 1 again with the halt off (§7.6.3).

use super::profile::Profile;
use crate::motion::homing::{self, HomingMethods, HomingStart};

/// 6098h: homing on the current position (CiA 402 method 37, the drive's default).
pub const CURRENT_POSITION: i64 = homing::CURRENT_POSITION as i64;

/// The MR-JE-C's homing methods: 37 only, a data-set method (§7.3 6098h).
pub const METHODS: HomingMethods<'static> = HomingMethods {
    listed: &[homing::CURRENT_POSITION],
    data_set: &[homing::CURRENT_POSITION],
};

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
        // The emulated MR-JE-C runs no search: a searching method would be an error too.
        match METHODS.start(p.homing_method, false) {
            HomingStart::SetHome => {
                self.status = HomingStatus::Attained;
                self.homed = true;
                Some(p.home_offset)
            }
            HomingStart::Search(_) | HomingStart::Error => {
                self.status = HomingStatus::Error;
                None
            }
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
