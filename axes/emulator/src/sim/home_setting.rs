//! Home position setting in csp/csv by Controlword2 edges, without hm (MR-J3-T04 C_CR / C_CR2,
//! MR-J3-T04 manual §8.11.6, manual §8.11.6, TV-HOME-1), and the encoder Z phase it uses (S_ZPAS,
//! S_OP, the latched last Z position).

use cellrt_cia402::profiles::HomeSetting;

/// What C_CR2 before the first Z phase raises: the manual names both (MR-J3-T04 manual §7.1, §7.2, §3.7, §3.9, §5.1, §8.5.2
/// ambiguity); the home-setting procedures (§8.11.6.3/4) name the warning, the default.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BeforeZReaction {
    /// AL.96 warning: operation continues, home not set; clears when C_CR2 goes off (the
    /// manual says "automatic" without the moment).
    #[default]
    Warning,
    /// AL.26 alarm (dynamic-brake stop, cleared by a power cycle).
    Alarm,
}

/// The encoder's Z phase: once per revolution, at `position` within it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ZPhase {
    /// Encoder counts per revolution (MR-J3-T04 manual: 2^18 or 2^17).
    pub counts_per_rev: i64,
    /// Raw position of a Z pulse (any one; the others lie a whole revolution apart).
    pub position: i64,
}

/// What an edge did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HomeSettingOutcome {
    /// Home set: the new 607Ch.
    HomeOffset(i32),
    /// C_CR2 before the Z phase with [`BeforeZReaction::Alarm`]: this alarm.
    Alarm(u16),
}

/// State of the home setting and the Z phase of one drive.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct HomeSettingState {
    prev_clear: bool,
    prev_clear_z: bool,
    /// S_ZPAS: a Z phase has been passed since power-on.
    z_passed: bool,
    /// S_OP: the encoder is at (or passed in the last cycle) a Z phase.
    at_z: bool,
    /// Raw position of the last Z phase passed.
    last_z: i64,
    prev_position: Option<i64>,
    /// S_OSET.
    set: bool,
    /// AL.96 active.
    before_z_warning: bool,
}

impl HomeSettingState {
    /// Follows the encoder (every cycle, any state): latches the last Z phase crossed between
    /// the previous and this raw position.
    pub fn track_encoder(&mut self, position: i64, z: ZPhase) {
        let rev = |p: i64| (p - z.position).div_euclid(z.counts_per_rev);
        self.at_z = (position - z.position).rem_euclid(z.counts_per_rev) == 0;
        let arrived = self.prev_position != Some(position);
        if let Some(prev) = self.prev_position {
            let (a, b) = (rev(prev), rev(position));
            // Standing on a Z pulse is not passing it; arriving on one is.
            if a != b || (self.at_z && arrived) {
                // Each Z starts a revolution: moving up the last one crossed starts b, moving
                // down it starts b + 1 (or b itself when the motor stands on it).
                let k = if self.at_z || b > a { b } else { b + 1 };
                self.last_z = k * z.counts_per_rev + z.position;
                self.z_passed = true;
                self.at_z = true;
            }
        }
        self.prev_position = Some(position);
    }

    /// Controlword2 in csp/csv: a rising C_CR sets home at `position` (raw 6064h), a rising
    /// C_CR2 at the last Z phase (C_CR2 wins when both rise together; otherwise the later edge
    /// wins). S_OSET stays 1 while the bit that set it stays on and drops with both bits off
    /// (the manual does not say when it clears; this gives the master an edge per setting).
    pub fn controlword2(
        &mut self,
        cw2: u16,
        bits: &HomeSetting,
        position: i32,
        reaction: BeforeZReaction,
    ) -> Option<HomeSettingOutcome> {
        let clear = cw2 & (1 << bits.clear_bit) != 0;
        let clear_z = cw2 & (1 << bits.clear_z_bit) != 0;
        let (rise, rise_z) = (clear && !self.prev_clear, clear_z && !self.prev_clear_z);
        self.prev_clear = clear;
        self.prev_clear_z = clear_z;
        if !clear && !clear_z {
            self.set = false;
        }
        if !clear_z {
            self.before_z_warning = false;
        }
        if rise_z {
            if !self.z_passed {
                return match reaction {
                    BeforeZReaction::Warning => {
                        self.before_z_warning = true;
                        None
                    }
                    BeforeZReaction::Alarm => Some(HomeSettingOutcome::Alarm(bits.before_z_alarm)),
                };
            }
            self.set = true;
            return Some(HomeSettingOutcome::HomeOffset(
                (self.last_z as i32).wrapping_neg(),
            ));
        }
        if rise {
            self.set = true;
            return Some(HomeSettingOutcome::HomeOffset(position.wrapping_neg()));
        }
        None
    }

    /// Edges seen outside csp/csv are not acted on (the manual's table: "–" in hm), but are
    /// remembered so that an edge is not taken late after a mode change.
    pub fn ignore(&mut self, cw2: u16, bits: &HomeSetting) {
        self.prev_clear = cw2 & (1 << bits.clear_bit) != 0;
        self.prev_clear_z = cw2 & (1 << bits.clear_z_bit) != 0;
    }

    /// The warning C_CR2 before the Z phase raised, while active.
    pub fn warning(&self, bits: &HomeSetting) -> Option<u16> {
        self.before_z_warning.then_some(bits.before_z_warning)
    }

    /// Statusword2 bits S_ZPAS, S_OSET and S_OP.
    pub fn statusword2(&self, bits: &HomeSetting) -> u16 {
        (u16::from(self.z_passed) << bits.z_passed_bit)
            | (u16::from(self.set) << bits.set_bit)
            | (u16::from(self.at_z) << bits.z_pulse_bit)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cellrt_cia402::profiles::{profile, DriveModel};

    fn bits() -> HomeSetting {
        profile(DriveModel::MrJ3T04).homing.setting.unwrap()
    }

    const Z: ZPhase = ZPhase {
        counts_per_rev: 262_144,
        position: 262_100,
    };

    #[test]
    fn standing_on_the_z_phase_since_power_on_is_not_passing_it() {
        let mut h = HomeSettingState::default();
        for _ in 0..3 {
            h.track_encoder(262_100, Z);
        }
        assert!(!h.z_passed);
        assert_eq!(h.statusword2(&bits()), 1 << 9, "S_OP only");
    }

    #[test]
    fn the_last_z_phase_crossed_is_latched_in_either_direction() {
        let mut h = HomeSettingState::default();
        h.track_encoder(0, Z);
        assert_eq!(h.statusword2(&bits()) & (1 << 7), 0);
        h.track_encoder(200_000, Z);
        assert!(!h.z_passed);
        h.track_encoder(262_200, Z);
        assert!(h.z_passed && h.at_z);
        assert_eq!(h.last_z, 262_100);
        h.track_encoder(262_300, Z);
        assert!(!h.at_z);
        // Past the next one, then back down through it.
        h.track_encoder(262_100 + 262_144 + 5, Z);
        assert_eq!(h.last_z, 262_100 + 262_144);
        h.track_encoder(262_100 + 262_144 - 5, Z);
        assert_eq!(h.last_z, 262_100 + 262_144);
        h.track_encoder(-10, Z);
        assert_eq!(h.last_z, 262_100);
        // Down through two: the lower one is the last.
        h.track_encoder(-300_000, Z);
        assert_eq!(h.last_z, 262_100 - 2 * 262_144);
    }
}
