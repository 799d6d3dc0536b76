//! The service manager's notification protocol (systemd, `sd_notify(3)`): `READY=1` once the
//! cell is brought up, `WATCHDOG=1` only while the RT loop's cycle counter advances, and
//! `STOPPING=1` at shutdown. Without `$NOTIFY_SOCKET` (not started by systemd) nothing is sent.

use std::time::{Duration, Instant};

use sd_notify::NotifyState;

/// How often the watchdog is fed against its timeout: systemd recommends half of
/// `WatchdogSec` (`sd_watchdog_enabled(3)`).
pub const FEEDS_PER_TIMEOUT: u32 = 2;

/// Feeds the service manager's watchdog while the RT loop lives: a feed is due when an
/// interval has passed and the RT loop's cycle counter moved since the last feed, so a stalled
/// or dead RT thread lets the watchdog expire (and systemd restart the cell).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WatchdogFeeder {
    interval: Duration,
    last_feed: Instant,
    last_cycle: u64,
}

impl WatchdogFeeder {
    /// A feeder for a watchdog of `timeout`, starting at `now` with the loop at `cycle`.
    pub fn new(timeout: Duration, now: Instant, cycle: u64) -> WatchdogFeeder {
        WatchdogFeeder {
            interval: timeout / FEEDS_PER_TIMEOUT,
            last_feed: now,
            last_cycle: cycle,
        }
    }

    /// The time between feeds.
    pub fn interval(&self) -> Duration {
        self.interval
    }

    /// Whether to feed now, with the RT loop at `cycle`; a `true` counts as fed.
    pub fn due(&mut self, cycle: u64, now: Instant) -> bool {
        if now.duration_since(self.last_feed) < self.interval || cycle == self.last_cycle {
            return false;
        }
        self.last_feed = now;
        self.last_cycle = cycle;
        true
    }
}

/// The cell's side of the notification protocol.
#[derive(Debug)]
pub struct ServiceNotifier {
    /// Whether a service manager listens (`$NOTIFY_SOCKET` set).
    managed: bool,
    watchdog: Option<WatchdogFeeder>,
}

impl ServiceNotifier {
    /// From the environment systemd gives a `Type=notify` service (`$NOTIFY_SOCKET`,
    /// `$WATCHDOG_USEC` and `$WATCHDOG_PID`); the loop is at `cycle` now.
    pub fn from_env(now: Instant, cycle: u64) -> ServiceNotifier {
        let managed = std::env::var_os("NOTIFY_SOCKET").is_some();
        ServiceNotifier {
            managed,
            watchdog: sd_notify::watchdog_enabled()
                .filter(|t| managed && !t.is_zero())
                .map(|t| WatchdogFeeder::new(t, now, cycle)),
        }
    }

    /// Whether a service manager listens.
    pub fn managed(&self) -> bool {
        self.managed
    }

    /// The watchdog's feed interval, when the service manager asked for one.
    pub fn watchdog_interval(&self) -> Option<Duration> {
        self.watchdog.as_ref().map(WatchdogFeeder::interval)
    }

    /// The cell is up (bus in OP, RT loop running): `READY=1` with a status line.
    pub fn ready(&self, status: &str) {
        self.send(&[NotifyState::Ready, NotifyState::Status(status)]);
    }

    /// Feeds the watchdog if one is asked for, its interval has passed and the RT loop moved on
    /// from the last feed's cycle.
    pub fn poll(&mut self, cycle: u64, now: Instant) {
        if self.watchdog.as_mut().is_some_and(|w| w.due(cycle, now)) {
            self.send(&[NotifyState::Watchdog]);
        }
    }

    /// The cell is shutting down: `STOPPING=1`.
    pub fn stopping(&self) {
        self.send(&[NotifyState::Stopping]);
    }

    fn send(&self, states: &[NotifyState]) {
        if !self.managed {
            return;
        }
        if let Err(e) = sd_notify::notify(states) {
            tracing::warn!("service manager notification failed: {e}");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_watchdog_is_fed_at_half_its_timeout_while_cycles_advance() {
        let t0 = Instant::now();
        let mut w = WatchdogFeeder::new(Duration::from_secs(2), t0, 10);
        assert_eq!(w.interval(), Duration::from_secs(1));
        assert!(!w.due(500, t0 + Duration::from_millis(999)), "too early");
        assert!(w.due(1000, t0 + Duration::from_secs(1)));
        assert!(
            !w.due(1100, t0 + Duration::from_millis(1500)),
            "fed 0.5 s ago"
        );
        assert!(w.due(2000, t0 + Duration::from_secs(2)));
    }

    #[test]
    fn a_stalled_rt_loop_is_not_fed_for() {
        let t0 = Instant::now();
        let mut w = WatchdogFeeder::new(Duration::from_secs(2), t0, 10);
        assert!(w.due(1000, t0 + Duration::from_secs(1)));
        // The cycle counter stands still: no feed however long it waits.
        for s in 2..10 {
            assert!(!w.due(1000, t0 + Duration::from_secs(s)), "{s} s");
        }
        // It moves again: fed at once.
        assert!(w.due(1001, t0 + Duration::from_secs(10)));
    }
}
