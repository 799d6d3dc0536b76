//! CLOCK_MONOTONIC in integer nanoseconds and the absolute-deadline sleep.

use nix::errno::Errno;
use nix::sys::time::TimeSpec;
use nix::time::{clock_gettime, clock_nanosleep, ClockId, ClockNanosleepFlags};

/// A point on CLOCK_MONOTONIC, in nanoseconds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default)]
pub struct MonoTime(pub u64);

impl MonoTime {
    /// The current monotonic time.
    pub fn now() -> MonoTime {
        // CLOCK_MONOTONIC cannot fail on Linux; a zero time is a safe fallback.
        let ts = clock_gettime(ClockId::CLOCK_MONOTONIC).unwrap_or(TimeSpec::new(0, 0));
        MonoTime(ts.tv_sec() as u64 * 1_000_000_000 + ts.tv_nsec() as u64)
    }

    /// Nanoseconds from `earlier` to `self`, zero if `earlier` is later.
    pub fn since(self, earlier: MonoTime) -> u64 {
        self.0.saturating_sub(earlier.0)
    }

    /// This time moved by `ns` nanoseconds (negative: earlier), never below zero.
    pub fn shifted(self, ns: i64) -> MonoTime {
        MonoTime(self.0.saturating_add_signed(ns))
    }

    /// This time plus `ns` nanoseconds.
    pub fn plus(self, ns: u64) -> MonoTime {
        MonoTime(self.0 + ns)
    }
}

/// Sleeps until the absolute `deadline` (`clock_nanosleep(TIMER_ABSTIME)`), resuming after
/// signals (EINTR).
pub fn sleep_until(deadline: MonoTime) {
    let ts = TimeSpec::new(
        (deadline.0 / 1_000_000_000) as i64,
        (deadline.0 % 1_000_000_000) as i64,
    );
    loop {
        match clock_nanosleep(
            ClockId::CLOCK_MONOTONIC,
            ClockNanosleepFlags::TIMER_ABSTIME,
            &ts,
        ) {
            Err(Errno::EINTR) => continue,
            _ => return,
        }
    }
}

/// Offset to add to a [`MonoTime`] to get Unix-epoch nanoseconds (for recording timestamps).
pub fn realtime_offset_ns() -> i128 {
    let mono = MonoTime::now().0 as i128;
    let real = clock_gettime(ClockId::CLOCK_REALTIME)
        .map(|t| t.tv_sec() as i128 * 1_000_000_000 + t.tv_nsec() as i128)
        .unwrap_or(0);
    real - mono
}
