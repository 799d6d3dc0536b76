//! The drive's alarm history (MR-J3-T04 manual §8.9: the newest alarm in 2030h and the five
//! before it in 2031h–2035h, each with its number, the hours of operation and a detail; cleared
//! by 1EA5h in 2040h), on the shared history of every emulated drive.

use cellrt_cia402::profiles::params::{history_sub, AlarmHistoryFacts};

/// The drive's history: the shared one (`device::alarm_history`) of 603Fh alarm numbers; it
/// survives a power cycle like the amplifier's non-volatile memory [inferred: the manual does
/// not say, Mitsubishi's history is kept in EEP-ROM].
pub type AlarmHistory = crate::device::alarm_history::AlarmHistory<u16>;

/// One recorded alarm as the history objects show it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct AlarmRecord {
    /// Alarm No. (the profile's code, e.g. 0052h for AL.52).
    pub number: u16,
    /// Hours of operation when it occurred.
    pub hours: u32,
    /// Alarm detail (0: the simulator models no detail numbers).
    pub detail: u16,
}

impl AlarmHistory {
    /// Entry `n` (0 = newest); an empty entry reads 0.
    pub fn entry(&self, n: usize) -> AlarmRecord {
        self.get(n)
            .map_or_else(AlarmRecord::default, |o| AlarmRecord {
                number: o.alarm,
                hours: o.hours,
                detail: 0,
            })
    }

    /// The value of history object `index:sub` under `facts`, if it is one.
    pub fn object_value(&self, facts: &AlarmHistoryFacts, index: u16, sub: u8) -> Option<i64> {
        let n = index.checked_sub(facts.first)?;
        if n >= u16::from(facts.entries) {
            return None;
        }
        let r = self.entry(usize::from(n));
        match sub {
            history_sub::NUMBER => Some(i64::from(r.number)),
            history_sub::TIME => Some(i64::from(r.hours)),
            history_sub::DETAIL => Some(i64::from(r.detail)),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_history_objects_read_the_entries_and_cleared_ones_read_0() {
        let facts = cellrt_cia402::profiles::params::MR_J3_T04
            .alarm_history
            .unwrap();
        let mut h = AlarmHistory::default();
        for n in 0..20u16 {
            h.record(n, u32::from(n) * 2);
        }
        assert_eq!(h.object_value(&facts, 0x2030, 1), Some(19));
        assert_eq!(h.object_value(&facts, 0x2030, 2), Some(38));
        assert_eq!(h.object_value(&facts, 0x2035, 1), Some(14));
        assert_eq!(h.object_value(&facts, 0x2036, 1), None);
        h.clear();
        assert_eq!(h.object_value(&facts, 0x2030, 1), Some(0));
    }
}
