//! Reading a cell summary's event log.

/// The cycle of the first event line containing `what` (`cycle N ...`).
pub fn cycle_of(log: &[String], what: &str) -> Option<u64> {
    log.iter().find(|l| l.contains(what)).and_then(|l| {
        l.split_whitespace()
            .skip_while(|w| *w != "cycle")
            .nth(1)
            .and_then(|n| n.trim_end_matches(':').parse().ok())
    })
}
