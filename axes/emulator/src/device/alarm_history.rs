//! The alarm history of an emulated drive, newest first, with the hours of operation of each
//! occurrence (MR-J3-T04 manual §8.9: 2030h–2035h, cleared by 1EA5h in 2040h; MR-JE-C manual
//! §7.3: 2A00h–2A0Fh, cleared by 1EA5h in 2A40h). The model names its alarms (`A`) and maps
//! the entries onto its objects. Held in a fixed array: recording allocates nothing.

/// Most entries any model keeps (MR-JE-C: 16, manual §7.3).
pub const ENTRIES: usize = 16;

/// One alarm occurrence.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Occurrence<A> {
    /// The alarm, as the model names it.
    pub alarm: A,
    /// Hours of operation (power-on hours) when it occurred.
    pub hours: u32,
}

/// The occurrences, newest first; the oldest beyond [`ENTRIES`] falls out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AlarmHistory<A> {
    entries: [Option<Occurrence<A>>; ENTRIES],
}

impl<A: Copy> Default for AlarmHistory<A> {
    fn default() -> Self {
        AlarmHistory {
            entries: [None; ENTRIES],
        }
    }
}

impl<A: Copy> AlarmHistory<A> {
    /// Records `alarm` at `hours` as the newest entry.
    pub fn record(&mut self, alarm: A, hours: u32) {
        self.entries.copy_within(..ENTRIES - 1, 1);
        self.entries[0] = Some(Occurrence { alarm, hours });
    }

    /// The occurrence `age` entries back (0 newest), if there is one.
    pub fn get(&self, age: usize) -> Option<&Occurrence<A>> {
        self.entries.get(age)?.as_ref()
    }

    /// Empties the history.
    pub fn clear(&mut self) {
        self.entries = [None; ENTRIES];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn newest_first_and_the_oldest_falls_out() {
        let mut h = AlarmHistory::default();
        (0..20u16).for_each(|n| h.record(n, 1));
        assert_eq!(h.get(0).map(|o| o.alarm), Some(19));
        assert_eq!(h.get(ENTRIES - 1).map(|o| o.alarm), Some(4));
        assert!(h.get(ENTRIES).is_none());
        h.clear();
        assert!(h.get(0).is_none());
    }
}
