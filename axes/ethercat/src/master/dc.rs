//! The RT loop's deadline aligned to the distributed clocks' SYNC0 grid.

use super::error::{step, EthercatError};
use super::group::OpGroup;
use super::pump::Wire;
use super::segment::SegmentStation;
use crate::register as reg;
use ethercrab::MainDevice;

/// Where in the SYNC0 cycle the cyclic frame should pass the DC reference clock: this fraction
/// of a cycle after a SYNC0 edge, so the drives take its outputs at the next edge and the frame
/// may be late by the rest of the cycle (wakeup latency is one-sided) before it misses it.
pub const SYNC0_FRAME_PHASE_DIVISOR: u64 = 8;
/// Share of the DC phase error corrected per cycle once locked (1/16: the wakeup jitter of a
/// non-RT kernel averages out; a step of the reference clock is followed in about 50 cycles).
const DC_PHASE_GAIN_DIVISOR: i64 = 16;
/// Largest deadline correction per cycle once locked, as a share of the cycle (1/50 = 2 %).
const DC_MAX_STEP_DIVISOR: i64 = 50;

/// The RT loop's deadline aligned to the DC system time: each cyclic frame carries an FRMW of
/// the reference clock's system time (0910h, which also keeps the other clocks on it), whose
/// phase in the SYNC0 grid (start 0990h, cycle 09A0h) gives how far the master's cycle is off
/// [`SYNC0_FRAME_PHASE_DIVISOR`]; the next deadline is moved by the correction
/// (the bus' `deadline_correction_ns`): at once on the first frame, then by a share of the error.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct DcAlignment {
    /// Configured address of the reference clock (the first SubDevice).
    pub(super) reference: u16,
    /// SYNC0 start time in DC system time, ns.
    pub(super) start: u64,
    /// SYNC0 cycle, ns.
    pub(super) cycle: u64,
    /// The correction not yet taken by the RT loop, ns.
    pub(super) pending: i64,
    /// The last phase error, ns (frame phase − target, in (−cycle/2, cycle/2]).
    pub(super) error: i64,
    /// A first phase has been measured.
    pub(super) locked: bool,
}

impl DcAlignment {
    /// Reads the SYNC0 grid of the first SubDevice that runs SYNC0; the frame reads the
    /// system time of the reference clock (the first SubDevice with distributed clocks,
    /// ethercrab's choice). Without SYNC0 anywhere (every SubDevice free-run) there is no grid
    /// (cycle 0) and the RT loop keeps its own clock.
    pub(super) fn read_back(
        group: &OpGroup,
        maindevice: &MainDevice<'static>,
        wire: &mut Wire<'_>,
        plans: &[SegmentStation],
    ) -> Result<Self, EthercatError> {
        let mut reference = None;
        for position in 0..plans.len() {
            let sd = step("SubDevice lookup", group.subdevice(maindevice, position))?;
            if sd.dc_support().any() {
                reference = Some(sd.configured_address());
                break;
            }
        }
        let Some(synced) = plans.iter().position(|p| p.distributed_clocks) else {
            return Ok(DcAlignment {
                reference: reference.unwrap_or(0),
                ..DcAlignment::default()
            });
        };
        let sd = step("SubDevice lookup", group.subdevice(maindevice, synced))?;
        let read = async {
            let start: u64 = sd.register_read(reg::DC_SYNC_START_TIME).await?;
            let cycle: u32 = sd.register_read(reg::DC_SYNC0_CYCLE).await?;
            Ok::<_, ethercrab::error::Error>((start, cycle))
        };
        let (start, cycle) = wire.run("DC SYNC0 read-back", read)?;
        Ok(DcAlignment {
            reference: reference.unwrap_or_else(|| sd.configured_address()),
            start,
            cycle: u64::from(cycle),
            ..DcAlignment::default()
        })
    }

    /// Takes the reference clock's system time `t` seen by this cycle's frame.
    pub(super) fn observe(&mut self, t: u64) {
        if self.cycle == 0 || t < self.start {
            return;
        }
        let cycle = self.cycle as i64;
        let phase = ((t - self.start) % self.cycle) as i64;
        let mut error = phase - cycle / SYNC0_FRAME_PHASE_DIVISOR as i64;
        if error > cycle / 2 {
            error -= cycle;
        } else if error <= -cycle / 2 {
            error += cycle;
        }
        self.error = error;
        let step = if self.locked {
            let max = cycle / DC_MAX_STEP_DIVISOR;
            (-error / DC_PHASE_GAIN_DIVISOR).clamp(-max, max)
        } else {
            self.locked = true;
            -error
        };
        self.pending += step;
    }
}
