//! An axis' homing settings (`[axes.homing]`): the method `home` uses when it names none and
//! the homing objects written by SDO at each homing start after 6098h (6099h:1/2, 609Ah, the
//! home position shift where the model has its object), in the drive's units.

use std::time::Duration;

/// Default `homing.timeout_s`: how long a homing may take before the master fails it (the
/// manuals give no figure).
pub const DEFAULT_HOMING_TIMEOUT: Duration = Duration::from_secs(10);

/// Largest `homing.timeout_s`.
pub const MAX_HOMING_TIMEOUT_S: f64 = 3600.0;

/// Most homing objects written after 6098h: 6099h:1, 6099h:2, 609Ah and the shift.
pub const MAX_HOMING_OBJECTS: usize = 4;

/// The homing objects of an axis, in the order they are written; a fixed array so the RT
/// thread copies it without allocating.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct HomingObjects {
    entries: [(u16, u8, u32); MAX_HOMING_OBJECTS],
    len: u8,
}

impl HomingObjects {
    /// Appends `index:sub` = `value` (ignored past [`MAX_HOMING_OBJECTS`]).
    pub fn push(&mut self, index: u16, sub: u8, value: u32) {
        if let Some(e) = self.entries.get_mut(usize::from(self.len)) {
            *e = (index, sub, value);
            self.len += 1;
        }
    }

    /// The `k`-th object to write, if any.
    pub fn get(&self, k: usize) -> Option<(u16, u8, u32)> {
        self.entries[..usize::from(self.len)].get(k).copied()
    }
}

/// `[axes.homing]` after validation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AxisHoming {
    /// `homing.method`: the 6098h method of a `home` that names none (`None`: the model's
    /// data-set method, as before).
    pub method: Option<i8>,
    /// Written by SDO at homing start, after 6098h.
    pub objects: HomingObjects,
    /// `homing.timeout_s`: how long the whole sequence may take.
    pub timeout: Duration,
}

impl Default for AxisHoming {
    fn default() -> Self {
        AxisHoming {
            method: None,
            objects: HomingObjects::default(),
            timeout: DEFAULT_HOMING_TIMEOUT,
        }
    }
}
