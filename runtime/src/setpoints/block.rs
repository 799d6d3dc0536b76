//! The setpoint block payload (`#[repr(C)]`, shared memory safe).

use iceoryx2::prelude::ZeroCopySend;

/// Most axes a cell (and so a block) carries.
pub const MAX_AXES: usize = 64;

/// Cycles covered by one block.
pub const BLOCK_CYCLES: usize = 16;

/// Block flag: the motion ends with this block; the axes hold its last setpoint afterwards.
pub const FLAG_LAST: u32 = 1;

/// One axis' setpoint for one cycle, in drive counts.
#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("cellrt::AxisSetpoint")]
pub struct AxisSetpoint {
    /// Position setpoint in counts (fractional; rounded at the PDO).
    pub position: f64,
    /// Velocity of the setpoint trajectory in counts/s (feed-forward, stop ramps).
    pub velocity: f64,
}

/// Setpoints of every axis of a cell for [`BLOCK_CYCLES`] consecutive cycles.
#[derive(Debug, Clone, Copy, ZeroCopySend)]
#[repr(C)]
#[type_name("cellrt::SetpointBlock")]
pub struct SetpointBlock {
    /// Identifies the motion; all blocks of one motion share it.
    pub motion_id: u32,
    /// [`FLAG_LAST`] and future flags.
    pub flags: u32,
    /// First cycle this block covers.
    pub start_cycle: u64,
    /// Valid cycles in this block (1..=BLOCK_CYCLES).
    pub cycles: u32,
    /// Valid axes per cycle (the cell's axis count).
    pub axis_count: u32,
    /// `setpoints[k][axis]` is for cycle `start_cycle + k`.
    pub setpoints: [[AxisSetpoint; MAX_AXES]; BLOCK_CYCLES],
}

impl Default for SetpointBlock {
    fn default() -> Self {
        SetpointBlock {
            motion_id: 0,
            flags: 0,
            start_cycle: 0,
            cycles: 0,
            axis_count: 0,
            setpoints: [[AxisSetpoint::default(); MAX_AXES]; BLOCK_CYCLES],
        }
    }
}

impl SetpointBlock {
    /// One past the last cycle this block covers.
    pub fn end_cycle(&self) -> u64 {
        self.start_cycle + u64::from(self.cycles)
    }

    /// Whether the motion ends with this block.
    pub fn is_last(&self) -> bool {
        self.flags & FLAG_LAST != 0
    }

    /// The setpoint of `axis` at `cycle`, if this block covers it.
    pub fn get(&self, cycle: u64, axis: usize) -> Option<&AxisSetpoint> {
        if cycle < self.start_cycle || cycle >= self.end_cycle() || axis >= self.axis_count as usize
        {
            return None;
        }
        self.setpoints
            .get((cycle - self.start_cycle) as usize)?
            .get(axis)
    }
}
