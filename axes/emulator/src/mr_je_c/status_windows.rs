//! The time conditions of the operation-mode-specific status bits (MR-JE-C manual §7.3
//! 6067h–6070h): Target reached (bit 10) comes on in pp, jg, pt and idx once the position has
//! been within Position window 6067h for Position window time 6068h, in pv once the speed has
//! been within Velocity window 606Dh for 606Eh; in pv bit 12 goes off once the speed has
//! exceeded Velocity threshold 606Fh for longer than 6070h (a speed-zero indication). A
//! positioning's window condition is its completion with the droop within 6067h (the motor
//! model's position loop, `motion`); 6067h = 4294967295 ("the Position window is disabled")
//! is taken as "every droop is within it": Target reached follows the completion alone (the
//! manual gives no more). Bit 13 comes on in pp, jg, pt and idx once the droop has exceeded
//! Following error window 6065h for Following error time out 6066h ("has elapsed": at least
//! that long, as for 6068h).

use std::time::Duration;

/// Since when the window condition holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum InWindow {
    /// Not at the last step.
    No,
    /// Since this time.
    Since(Duration),
    /// All along: the motor has stood since before the servo came on.
    Always,
}

/// When each raw condition last became true.
#[derive(Debug, Clone, Copy)]
pub struct StatusWindows {
    in_window: InWindow,
    /// `None`: not over the threshold at the last step.
    over_threshold_since: Option<Duration>,
    /// `None`: the droop within 6065h at the last step.
    following_since: Option<Duration>,
}

impl Default for StatusWindows {
    fn default() -> Self {
        StatusWindows {
            in_window: InWindow::Always,
            over_threshold_since: None,
            following_since: None,
        }
    }
}

impl StatusWindows {
    /// The conditions after a motor step at `now`: within the mode's window, and the speed
    /// over 606Fh.
    pub fn update(&mut self, now: Duration, in_window: bool, over_threshold: bool) {
        self.in_window = match (in_window, self.in_window) {
            (false, _) => InWindow::No,
            (true, InWindow::No) => InWindow::Since(now),
            (true, was) => was,
        };
        self.over_threshold_since =
            over_threshold.then(|| self.over_threshold_since.unwrap_or(now));
    }

    /// Whether the droop is over 6065h after a motor step at `now`.
    pub fn following(&mut self, now: Duration, over: bool) {
        self.following_since = over.then(|| self.following_since.unwrap_or(now));
    }

    /// Bit 13: the droop over 6065h for at least `time` at `now`.
    pub fn following_error(&self, now: Duration, time: Duration) -> bool {
        self.following_since
            .is_some_and(|t| now.saturating_sub(t) >= time)
    }

    /// Servo off: the motor stands where it is, so it is within every window all along (the
    /// drive answers Target reached at once when enabled) and under the threshold.
    pub fn standing(&mut self) {
        *self = StatusWindows::default();
    }

    /// A command took the motor out of the window (a new set-point or start) between two
    /// steps.
    pub fn leave_window(&mut self) {
        self.in_window = InWindow::No;
    }

    /// Within the window for at least `time` at `now`.
    pub fn reached(&self, now: Duration, time: Duration) -> bool {
        match self.in_window {
            InWindow::No => false,
            InWindow::Since(t) => now.saturating_sub(t) >= time,
            InWindow::Always => true,
        }
    }

    /// pv's bit 12: off once the speed has been over 606Fh for longer than `time`.
    pub fn speed_zero(&self, now: Duration, time: Duration) -> bool {
        self.over_threshold_since
            .is_none_or(|t| now.saturating_sub(t) <= time)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ms(v: u64) -> Duration {
        Duration::from_millis(v)
    }

    #[test]
    fn a_condition_counts_from_when_it_became_true() {
        let mut w = StatusWindows::default();
        assert!(
            w.reached(ms(0), ms(10)),
            "a standing motor is within the window"
        );
        w.update(ms(0), false, false);
        w.update(ms(5), true, true);
        w.update(ms(10), true, true);
        assert!(!w.reached(ms(14), ms(10)));
        assert!(w.reached(ms(15), ms(10)));
        assert!(
            w.speed_zero(ms(15), ms(10)),
            "10 ms over: not longer than 6070h"
        );
        assert!(!w.speed_zero(ms(16), ms(10)));
        w.update(ms(20), false, false);
        assert!(!w.reached(ms(40), ms(10)));
        assert!(w.speed_zero(ms(40), ms(10)));
    }
}
