//! Jog mode (jg, 6060h = −100, SW A4+; MR-JE-C manual §7.3 607Fh, §7.6.3, Table 2.3): the
//! motor runs at Profile velocity 6081h (limited by 607Fh) while New set-point (Controlword
//! bit 4) is on, accelerating with 6083h and decelerating with 6084h, both taken when bit 4
//! turns on (§7.6.3). Halt (bit 8) decelerates with 6084h; releasing it restarts the jog at
//! once (§7.6.3). The manual does not say how jg picks the direction: see [`REVERSE`].

use super::profile::{Command, Profile, Ramp};
use cellrt_cia402::controlword::Controlword;

/// Controlword bit 6 on at the New set-point edge jogs in reverse (see
/// [`cellrt_fieldbus::mr_je_c::JOG_REVERSE`]: the manual is silent on the jog direction).
pub use cellrt_fieldbus::mr_je_c::JOG_REVERSE as REVERSE;

/// jg's state.
#[derive(Debug, Clone, Copy, Default)]
pub struct Jog {
    /// Bit 4 is on.
    running: bool,
    /// The direction taken at the bit 4 edge.
    reverse: bool,
    /// 6083h/6084h taken at the bit 4 edge.
    ramp: Option<Ramp>,
}

impl Jog {
    /// A controlword write: the jog runs while bit 4 is on; its rising edge takes the
    /// direction and the ramps.
    pub fn controlword(&mut self, cw: Controlword, rising: bool, p: &Profile) {
        self.running = cw.0 & (1 << 4) != 0;
        if rising {
            self.reverse = cw.0 & REVERSE != 0;
            self.ramp = Some(Ramp {
                acceleration_ms: p.acceleration_ms,
                deceleration_ms: p.deceleration_ms,
            });
        }
    }

    /// What the motor does in jg.
    pub fn command(&self, p: &Profile, halted: bool) -> Command {
        let ramp = self.ramp.unwrap_or(Ramp {
            acceleration_ms: p.acceleration_ms,
            deceleration_ms: p.deceleration_ms,
        });
        let speed = if self.running && !halted {
            let v = p.units_per_s(p.profile_velocity).abs();
            if self.reverse {
                -v
            } else {
                v
            }
        } else {
            0.0
        };
        Command::Speed { speed, ramp }
    }

    /// Target reached (bit 10, §7.3 6067h): the jog has ended and the command stands (the
    /// droop within 6067h is judged by the motor, `motion`).
    pub fn reached(&self, standing: bool) -> bool {
        !self.running && standing
    }
}
