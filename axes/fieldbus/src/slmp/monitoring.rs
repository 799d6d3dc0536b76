//! The request's monitoring timer (MR-JE-C manual §2.4.2): 0000h waits until the drive has
//! processed the request; 0001h–FFFFh is the time the requester waits, in 0.25 s units, after
//! which the drive discards its answer.

use std::time::Duration;

/// One unit of the monitoring timer.
pub const MONITORING_TIMER_UNIT: Duration = Duration::from_millis(250);

/// The monitoring timer for a requester that waits `timeout` for an answer: the whole units
/// that fit (so the drive gives up no later than the requester), at least one unit.
pub fn monitoring_timer_for(timeout: Duration) -> u16 {
    let units = timeout.as_millis() / MONITORING_TIMER_UNIT.as_millis();
    units.clamp(1, u128::from(u16::MAX)) as u16
}

/// True if a request with monitoring timer `timer` is discarded by a drive that takes
/// `processing` to answer it (0000h never expires).
pub fn monitoring_timer_expires(timer: u16, processing: Duration) -> bool {
    timer != 0 && processing > MONITORING_TIMER_UNIT * u32::from(timer)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_timer_counts_quarter_seconds() {
        // The spec's vector SL-3: 0010h = 4 s.
        assert_eq!(monitoring_timer_for(Duration::from_secs(4)), 0x0010);
        assert_eq!(monitoring_timer_for(Duration::from_millis(999)), 3);
        assert_eq!(monitoring_timer_for(Duration::from_millis(100)), 1);
        assert_eq!(monitoring_timer_for(Duration::from_secs(100_000)), u16::MAX);
        assert!(!monitoring_timer_expires(0, Duration::from_secs(3600)));
        assert!(!monitoring_timer_expires(2, Duration::from_millis(500)));
        assert!(monitoring_timer_expires(2, Duration::from_millis(501)));
    }
}
