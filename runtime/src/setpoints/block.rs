//! The setpoint block: an iceoryx2 user header plus a slice of per-cycle, per-axis setpoints,
//! sized per cell (`BLOCK_CYCLES × axes`). Both are `#[repr(C)]` and shared-memory safe.

use iceoryx2::prelude::ZeroCopySend;

pub use cellrt_config::{BLOCK_CYCLES, MAX_AXES};

/// Latest first cycle a block may claim (2^62: far beyond any run), so that the RT thread's
/// sums of a block's cycles (its end, its start plus the allowed start slip) cannot overflow.
pub const MAX_START_CYCLE: u64 = 1 << 62;

/// Block flag: the motion ends with this block; the axes hold its last setpoint afterwards.
pub const FLAG_LAST: u32 = 1;

/// Block flag: a torque motion. Axes in cst take [`AxisSetpoint::torque`] (their position and
/// velocity are ignored); the other axes hold as usual. Without it cst axes follow the position
/// and velocity setpoints in csv.
pub const FLAG_TORQUE: u32 = 2;

/// One axis' setpoint for one cycle, in drive counts.
#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("cellrt::AxisSetpoint.v2")]
pub struct AxisSetpoint {
    /// Position setpoint in counts (fractional; rounded at the PDO).
    pub position: f64,
    /// Velocity of the setpoint trajectory in counts/s (csv target, feed-forward, stop ramps).
    pub velocity: f64,
    /// Torque setpoint in % of rated torque (cst axes in a [`FLAG_TORQUE`] block; else 0).
    pub torque: f64,
}

/// Header of a setpoint block (the iceoryx2 user header of each sample).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, ZeroCopySend)]
#[repr(C)]
#[type_name("cellrt::SetpointHeader")]
pub struct SetpointHeader {
    /// Identifies the motion; all blocks of one motion share it.
    pub motion_id: u32,
    /// [`FLAG_LAST`] and future flags.
    pub flags: u32,
    /// First cycle this block covers.
    pub start_cycle: u64,
    /// Valid cycles in this block (1..=BLOCK_CYCLES).
    pub cycles: u32,
    /// Axes per cycle (the cell's axis count).
    pub axis_count: u32,
}

/// A received block: its header and its setpoints, `setpoints[k * axis_count + axis]` being
/// for cycle `start_cycle + k`.
#[derive(Debug, Clone, Copy)]
pub struct SetpointBlock<'a> {
    /// The header.
    pub header: &'a SetpointHeader,
    /// Row-major setpoints.
    pub setpoints: &'a [AxisSetpoint],
}

impl SetpointBlock<'_> {
    /// One past the last cycle this block covers.
    pub fn end_cycle(&self) -> u64 {
        self.header.start_cycle + u64::from(self.header.cycles)
    }

    /// Whether this block belongs to a torque motion ([`FLAG_TORQUE`]).
    pub fn is_torque(&self) -> bool {
        self.header.flags & FLAG_TORQUE != 0
    }

    /// Whether the motion ends with this block.
    pub fn is_last(&self) -> bool {
        self.header.flags & FLAG_LAST != 0
    }

    /// Whether the header fits a cell of `axes` axes, starts no later than
    /// [`MAX_START_CYCLE`], and the slice holds what it announces.
    pub fn is_well_formed(&self, axes: usize) -> bool {
        let h = self.header;
        h.axis_count as usize == axes
            && h.start_cycle <= MAX_START_CYCLE
            && h.cycles >= 1
            && h.cycles as usize <= BLOCK_CYCLES
            && self.setpoints.len() == h.cycles as usize * axes
    }

    /// The setpoint of `axis` at `cycle`, if this block covers it.
    pub fn get(&self, cycle: u64, axis: usize) -> Option<&AxisSetpoint> {
        let h = self.header;
        if cycle < h.start_cycle || cycle >= self.end_cycle() || axis >= h.axis_count as usize {
            return None;
        }
        let row = (cycle - h.start_cycle) as usize;
        self.setpoints.get(row * h.axis_count as usize + axis)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lookup_covers_exactly_the_announced_cycles_and_axes() {
        let header = SetpointHeader {
            motion_id: 1,
            flags: FLAG_LAST,
            start_cycle: 100,
            cycles: 2,
            axis_count: 3,
        };
        let sp: Vec<AxisSetpoint> = (0..6)
            .map(|i| AxisSetpoint {
                position: f64::from(i),
                velocity: 0.0,
                torque: 0.0,
            })
            .collect();
        let b = SetpointBlock {
            header: &header,
            setpoints: &sp,
        };
        assert!(b.is_well_formed(3));
        assert!(!b.is_well_formed(4));
        assert_eq!(b.get(100, 0).unwrap().position, 0.0);
        assert_eq!(b.get(101, 2).unwrap().position, 5.0);
        assert!(b.get(99, 0).is_none());
        assert!(b.get(102, 0).is_none());
        assert!(b.get(100, 3).is_none());
        assert_eq!(b.end_cycle(), 102);
        assert!(b.is_last());
        let short = SetpointBlock {
            header: &header,
            setpoints: &sp[..5],
        };
        assert!(!short.is_well_formed(3));
    }

    #[test]
    fn a_block_starting_past_the_last_start_cycle_is_malformed() {
        // The RT thread sums a block's start with its cycles and with the allowed start slip;
        // a start near 2^64 (from the setpoint_block fuzz target) overflowed both.
        let sp = [AxisSetpoint::default(); 16];
        let header = |start_cycle| SetpointHeader {
            motion_id: 1,
            flags: 0,
            start_cycle,
            cycles: 16,
            axis_count: 1,
        };
        for (start, ok) in [
            (MAX_START_CYCLE, true),
            (MAX_START_CYCLE + 1, false),
            (u64::MAX - 3, false),
        ] {
            let h = header(start);
            let b = SetpointBlock {
                header: &h,
                setpoints: &sp,
            };
            assert_eq!(b.is_well_formed(1), ok, "start {start}");
            if ok {
                assert_eq!(b.end_cycle(), MAX_START_CYCLE + 16);
                assert!(start.checked_add(u64::from(u32::MAX)).is_some());
            }
        }
    }
}
