//! The alarm history 2A00h (newest) to 2A0Fh (oldest) (MR-JE-C manual §7.3), cleared by
//! writing 1EA5h to 2A40h.

use std::collections::VecDeque;

use cellrt_fieldbus::mr_je_c::alarm::Alarm;

/// Entries the history keeps.
pub const ENTRIES: usize = 16;

/// One alarm occurrence.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Occurrence {
    /// The alarm.
    pub alarm: Alarm,
    /// Power-on hours when it occurred (2A0xh:2).
    pub hour: u32,
}

/// The newest alarms first.
#[derive(Debug, Clone, Default)]
pub struct AlarmHistory {
    entries: VecDeque<Occurrence>,
}

impl AlarmHistory {
    /// Records `o` as the newest; the oldest beyond 16 is dropped.
    pub fn push(&mut self, o: Occurrence) {
        self.entries.push_front(o);
        self.entries.truncate(ENTRIES);
    }

    /// The occurrence at 2A00h + `age` (0 newest).
    pub fn get(&self, age: usize) -> Option<&Occurrence> {
        self.entries.get(age)
    }

    /// Empties the history (2A40h = 1EA5h).
    pub fn clear(&mut self) {
        self.entries.clear();
    }
}
