//! The drive's alarm history (MR-J3-T04 manual §8.9: the newest alarm in 2030h and the five
//! before it in 2031h–2035h, each with its number, the hours of operation and a detail; cleared
//! by 1EA5h in 2040h). Held in a fixed array: recording an alarm allocates nothing.

use cellrt_cia402::profiles::params::{history_sub, AlarmHistoryFacts};

/// Most entries any model keeps (MR-JE-C: 16, manual §7).
const MAX_ENTRIES: usize = 16;

/// One recorded alarm.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct AlarmRecord {
    /// Alarm No. (the profile's code, e.g. 0052h for AL.52).
    pub number: u16,
    /// Hours of operation when it occurred.
    pub hours: u32,
    /// Alarm detail (0: the simulator models no detail numbers).
    pub detail: u16,
}

/// The history, newest first; it survives a power cycle like the amplifier's non-volatile
/// memory [inferred: the manual does not say, Mitsubishi's history is kept in EEP-ROM].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct AlarmHistory {
    records: [AlarmRecord; MAX_ENTRIES],
}

impl AlarmHistory {
    /// Records `number` at `hours` as the newest entry; the oldest falls out.
    pub fn record(&mut self, number: u16, hours: u32) {
        self.records.copy_within(..MAX_ENTRIES - 1, 1);
        self.records[0] = AlarmRecord {
            number,
            hours,
            detail: 0,
        };
    }

    /// Empties the history (every entry reads 0).
    pub fn clear(&mut self) {
        self.records = [AlarmRecord::default(); MAX_ENTRIES];
    }

    /// Entry `n` (0 = newest).
    pub fn entry(&self, n: usize) -> AlarmRecord {
        self.records.get(n).copied().unwrap_or_default()
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
    fn newest_first_and_the_oldest_falls_out() {
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
