//! The simulated MR-JE-C's motor in the profile modes (MR-JE-C manual §7.6.3 pp, §7.6.4 pv):
//! pp takes 607Ah at a New set-point edge (Controlword bit 4) and answers Set-point
//! acknowledge (Statusword bit 12) while bit 4 stays on; pv follows 60FFh. Speeds are limited
//! by 6081h (pp) and 607Fh, acceleration and deceleration are time constants from 0 to the
//! rated speed (6083h, 6084h; 0 steps at once), Halt (bit 8) decelerates with 6084h. Target
//! reached (bit 10): pp at the target within the position window 6067h, pv at the speed within
//! the velocity window 606Dh. The profile is trapezoidal (the drive's S-pattern smoothing is
//! not emulated) and a new set-point replaces the running one at once (the
//! "change immediately" behaviour); the position unit is 6092h:1 feed per motor revolution.

use std::time::Duration;

/// 6060h/6061h values of the profile modes.
pub const PROFILE_POSITION: i64 = 1;
/// Profile velocity mode.
pub const PROFILE_VELOCITY: i64 = 3;

/// The objects a step of the motion reads, in the drive's units.
#[derive(Debug, Clone, Copy)]
pub struct Profile {
    /// 6061h.
    pub mode: i64,
    /// 607Ah, pos units.
    pub target_position: i64,
    /// 60FFh, 0.01 r/min.
    pub target_velocity: i64,
    /// min(6081h, 607Fh), 0.01 r/min.
    pub profile_velocity: i64,
    /// 6083h, ms from 0 to rated speed.
    pub acceleration_ms: i64,
    /// 6084h, ms from rated speed to 0.
    pub deceleration_ms: i64,
    /// Rated speed, 0.01 r/min.
    pub rated_speed: i64,
    /// Pos units per motor revolution (6092h:1).
    pub units_per_rev: i64,
    /// 6067h, pos units.
    pub position_window: i64,
    /// 606Dh, 0.01 r/min.
    pub velocity_window: i64,
}

impl Profile {
    /// 0.01 r/min → pos units/s.
    fn units_per_s(&self, speed: i64) -> f64 {
        speed as f64 / 100.0 / 60.0 * self.units_per_rev as f64
    }

    /// A ramp of `ms` from 0 to the rated speed as pos units/s² (`None`: a step).
    fn rate(&self, ms: i64) -> Option<f64> {
        (ms > 0).then(|| self.units_per_s(self.rated_speed) / (ms as f64 / 1000.0))
    }
}

/// The motor's state.
#[derive(Debug, Clone, Default)]
pub struct Motion {
    /// Position, pos units.
    position: f64,
    /// Velocity, pos units/s.
    velocity: f64,
    /// The pp set-point being run.
    set_point: Option<i64>,
    /// Statusword bit 12 in pp.
    acknowledged: bool,
}

impl Motion {
    /// Position actual value (6064h).
    pub fn position(&self) -> i64 {
        self.position.round() as i64
    }

    /// Velocity actual value (606Ch), 0.01 r/min.
    pub fn velocity(&self, p: &Profile) -> i64 {
        (self.velocity / p.units_per_rev as f64 * 60.0 * 100.0).round() as i64
    }

    /// A controlword `bit4` edge in Operation enabled: pp takes 607Ah on the rising edge;
    /// the acknowledge follows bit 4.
    pub fn new_set_point(&mut self, bit4: bool, prev_bit4: bool, p: &Profile) {
        if p.mode != PROFILE_POSITION {
            return;
        }
        if bit4 && !prev_bit4 {
            self.set_point = Some(p.target_position);
        }
        self.acknowledged = bit4;
    }

    /// Statusword bits 10 and 12 in Operation enabled.
    pub fn status_bits(&self, p: &Profile, halted: bool) -> u16 {
        let reached = match p.mode {
            PROFILE_POSITION => {
                self.set_point.is_none()
                    && (self.position - p.target_position as f64).abs() <= p.position_window as f64
            }
            PROFILE_VELOCITY => {
                let want = if halted { 0 } else { p.target_velocity };
                (self.velocity(p) - want).abs() <= p.velocity_window
            }
            _ => self.velocity == 0.0,
        };
        let reached = reached || (halted && self.velocity == 0.0);
        let ack = p.mode == PROFILE_POSITION && self.acknowledged;
        (u16::from(reached) << 10) | (u16::from(ack) << 12)
    }

    /// The servo is off (or the drive stopped): the motor stands (dynamic brake) and a
    /// set-point is forgotten.
    pub fn stand(&mut self) {
        self.velocity = 0.0;
        self.set_point = None;
    }

    /// Advances the motor by `dt` with servo on; `halted`: Controlword bit 8.
    pub fn advance(&mut self, dt: Duration, p: &Profile, halted: bool) {
        let dt = dt.as_secs_f64();
        if dt <= 0.0 {
            return;
        }
        let vmax = p.units_per_s(p.profile_velocity).abs();
        let want = match p.mode {
            _ if halted => 0.0,
            PROFILE_POSITION => match self.set_point {
                Some(t) => self.pp_speed(t as f64, vmax, p),
                None => 0.0,
            },
            PROFILE_VELOCITY => p.units_per_s(p.target_velocity),
            _ => 0.0,
        };
        let speeding_up = want.abs() > self.velocity.abs() && want * self.velocity >= 0.0;
        let rate = if speeding_up {
            p.rate(p.acceleration_ms)
        } else {
            p.rate(p.deceleration_ms)
        };
        let dv = want - self.velocity;
        self.velocity = match rate {
            Some(r) if dv.abs() > r * dt => self.velocity + r * dt * dv.signum(),
            _ => want,
        };
        let step = self.velocity * dt;
        if let (Some(t), false) = (self.set_point, halted) {
            let left = t as f64 - self.position;
            if p.mode == PROFILE_POSITION && (left.abs() <= step.abs() || left == 0.0) {
                self.position = t as f64;
                self.velocity = 0.0;
                self.set_point = None;
                return;
            }
        }
        self.position += step;
    }

    /// The pp speed toward `target`: the profile speed, or less where the deceleration must
    /// start (v² = 2·d·s).
    fn pp_speed(&self, target: f64, vmax: f64, p: &Profile) -> f64 {
        let left = target - self.position;
        let braking = p
            .rate(p.deceleration_ms)
            .map_or(vmax, |d| (2.0 * d * left.abs()).sqrt());
        left.signum() * vmax.min(braking)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pp() -> Profile {
        Profile {
            mode: PROFILE_POSITION,
            target_position: 131_072,
            target_velocity: 0,
            profile_velocity: 60_000, // 600 r/min = 10 rev/s
            acceleration_ms: 100,
            deceleration_ms: 100,
            rated_speed: 300_000,
            units_per_rev: 131_072,
            position_window: 100,
            velocity_window: 2000,
        }
    }

    fn run(m: &mut Motion, p: &Profile, ms: u64) -> f64 {
        let mut peak: f64 = 0.0;
        for _ in 0..ms {
            m.advance(Duration::from_millis(1), p, false);
            peak = peak.max(m.velocity.abs());
        }
        peak
    }

    #[test]
    fn pp_reaches_the_target_at_the_profile_velocity() {
        let p = pp();
        let mut m = Motion::default();
        m.new_set_point(true, false, &p);
        assert_eq!(
            m.status_bits(&p, false),
            1 << 12,
            "acknowledged, not reached"
        );
        let peak = run(&mut m, &p, 60);
        // 600 r/min = 10 rev/s; the 100 ms time constant to 3000 r/min reaches it in 20 ms.
        assert!((peak - 10.0 * 131_072.0).abs() < 1.0, "peak {peak}");
        assert!(
            m.position() < 131_072 * 6 / 10,
            "one revolution takes > 100 ms"
        );
        let peak = run(&mut m, &p, 200).max(peak);
        assert!(peak <= 10.0 * 131_072.0 + 1.0, "peak {peak}");
        assert_eq!(m.position(), 131_072);
        m.new_set_point(false, true, &p);
        assert_eq!(m.status_bits(&p, false), 1 << 10);
    }

    #[test]
    fn pv_follows_the_target_velocity_and_halt_stops() {
        let mut p = pp();
        p.mode = PROFILE_VELOCITY;
        p.target_velocity = -30_000;
        let mut m = Motion::default();
        run(&mut m, &p, 50);
        assert_eq!(m.velocity(&p), -30_000);
        assert!(m.status_bits(&p, false) & (1 << 10) != 0);
        for _ in 0..50 {
            m.advance(Duration::from_millis(1), &p, true);
        }
        assert_eq!(m.velocity(&p), 0);
        assert!(m.position() < 0);
    }
}
