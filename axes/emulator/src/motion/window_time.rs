//! The window times of the operation-mode-specific status bits, one timer for every emulated
//! drive: how long a condition has held, judged against 606Eh Velocity window time and 6070h
//! Velocity threshold time (pv bits 10 and 12, `motion::profile_velocity`; MR-J4-TM manual
//! §5.4.7, MR-JE-C manual §7.3 6067h–6070h), 6068h Position window time (bit 10 in pp,
//! `motion::profile_position`, and the MR-JE-C's jg, pt and idx) and the MR-JE-C's 6066h
//! Following error time out (bit 13).
//!
//! Where the models differ, the difference is a named parameter: when the held time starts
//! ([`HeldFrom`]) and how the velocity threshold time is compared ([`ThresholdTime`]).
//! Times are in s (f64); allocation-free.

/// Slack (s) on the comparisons, against float sums of step times: half the MR-JE-C clock's
/// 1 ns, so a sum of whole nanoseconds compares as the nanoseconds do.
const TIME_SLACK_S: f64 = 0.5e-9;

/// Where the time a condition has held starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HeldFrom {
    /// The whole cycle at whose end the condition is first seen counts: the simulated
    /// EtherCAT drives judge a cycle by its end (an emulator choice; the manuals give the
    /// times, not the sampling).
    WholeCycle,
    /// The instant the condition is first seen, at the end of a step: the MR-JE-C's steps run
    /// between message arrivals of any length, so only what was seen counts (an emulator
    /// choice of the same kind).
    Seen,
}

/// How 6070h Velocity threshold time is compared with the time |606Ch| has exceeded 606Fh
/// (statusword bit 12 "speed" in pv).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ThresholdTime {
    /// "|606Ch| above 606Fh for at least 6070h" (MR-J4-TM manual §5.4.7 bit 12).
    AtLeast,
    /// "exceeds Velocity threshold 606Fh for longer than 6070h" (MR-JE-C manual §7.3 6070h).
    LongerThan,
}

/// How long a condition has held: the timer of one window (6068h, 606Eh, 6070h, 6066h).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Held {
    /// Seconds the condition has held; `None`: it did not hold at the last step.
    held_s: Option<f64>,
}

impl Held {
    /// A condition that has held all along (a motor standing since before the servo came on
    /// is within every window, MR-JE-C): any window time is met.
    pub fn always() -> Held {
        Held {
            held_s: Some(f64::INFINITY),
        }
    }

    /// The condition after a step of `dt` s: `holds` at its end, counted from `from`.
    pub fn update(&mut self, holds: bool, dt: f64, from: HeldFrom) {
        let dt = if dt.is_finite() { dt.max(0.0) } else { 0.0 };
        self.held_s = holds.then_some(match (self.held_s, from) {
            (Some(t), _) => t + dt,
            (None, HeldFrom::WholeCycle) => dt,
            (None, HeldFrom::Seen) => 0.0,
        });
    }

    /// The condition stops holding (between two steps, or a HALT that judges otherwise).
    pub fn clear(&mut self) {
        self.held_s = None;
    }

    /// The condition has held for at least `time_s`.
    pub fn at_least(&self, time_s: f64) -> bool {
        self.held_s.is_some_and(|t| t + TIME_SLACK_S >= time_s)
    }

    /// The condition has held for longer than `time_s`.
    pub fn longer_than(&self, time_s: f64) -> bool {
        self.held_s.is_some_and(|t| t > time_s + TIME_SLACK_S)
    }

    /// The condition has held for 6070h as `rule` compares it.
    pub fn exceeds(&self, time_s: f64, rule: ThresholdTime) -> bool {
        match rule {
            ThresholdTime::AtLeast => self.at_least(time_s),
            ThresholdTime::LongerThan => self.longer_than(time_s),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_condition_counts_from_the_whole_cycle_or_from_when_it_was_seen() {
        let mut cycle = Held::default();
        let mut seen = Held::default();
        for _ in 0..10 {
            cycle.update(true, 1e-3, HeldFrom::WholeCycle);
            seen.update(true, 1e-3, HeldFrom::Seen);
        }
        assert!(cycle.at_least(0.010) && !cycle.longer_than(0.010));
        assert!(seen.at_least(0.009) && !seen.at_least(0.010));
        seen.update(true, 1e-9, HeldFrom::Seen);
        assert!(
            seen.at_least(0.009 + 1e-9) && !seen.at_least(0.009 + 2e-9),
            "to the ns"
        );
        assert!(seen.longer_than(0.009) && !seen.longer_than(0.009 + 1e-9));
        seen.update(false, 1e-3, HeldFrom::Seen);
        assert!(!seen.at_least(0.0));
        assert!(Held::always().at_least(1e9));
    }
}
