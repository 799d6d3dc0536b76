//! One axis as the RT loop sees it: its CiA 402 master, its current setpoint, and the controlled
//! stop ramp the RT thread runs on its own.

use cellrt_axes::cia402::master::{AxisMaster, MasterParams};
use cellrt_axes::pdo::{PdoMap, TxPdo};
use cellrt_axes::Cycles;

use crate::config::{AxisConfig, CellConfig};

/// Per-axis limits converted to counts and cycles once, at start-up.
#[derive(Debug, Clone, Copy)]
pub struct AxisLimitsCounts {
    /// Lowest allowed setpoint, counts.
    pub position_min: f64,
    /// Highest allowed setpoint, counts.
    pub position_max: f64,
    /// Largest allowed setpoint change per cycle, counts (velocity limit × period, plus
    /// [`STEP_TOLERANCE`]).
    pub max_step: f64,
    /// Controlled-stop deceleration, counts/s².
    pub stop_deceleration: f64,
}

/// Relative slack on the per-cycle step check (numerical noise of the planner's sampling).
pub const STEP_TOLERANCE: f64 = 1e-6;

impl AxisLimitsCounts {
    /// Converts the configured limits of `axis` for a cycle of `period` seconds.
    pub fn new(axis: &AxisConfig, period: f64) -> Self {
        let s = axis.scaling.counts_per_unit();
        AxisLimitsCounts {
            position_min: axis.position.min * s,
            position_max: axis.position.max * s,
            max_step: axis.limits.velocity * s * period * (1.0 + STEP_TOLERANCE) + 1e-6,
            stop_deceleration: axis.stop_deceleration * s,
        }
    }
}

/// RT state of one axis.
#[derive(Debug)]
pub struct AxisChannel {
    /// The CiA 402 master driving this axis' controlword.
    pub master: AxisMaster,
    /// Limits in counts.
    pub limits: AxisLimitsCounts,
    /// Setpoint position of the current cycle, counts.
    pub setpoint: f64,
    /// Setpoint velocity of the current cycle, counts/s.
    pub velocity: f64,
    /// The latest decoded TxPDO.
    pub feedback: TxPdo,
    /// Whether the stop ramp of this axis has reached zero velocity.
    pub stopped: bool,
    /// The drive's RxPDO map (from its profile).
    pub rx_map: PdoMap,
    /// The drive's TxPDO map (from its profile).
    pub tx_map: PdoMap,
}

impl AxisChannel {
    /// Preallocates the channel of `axis` in `cell`.
    pub fn new(cell: &CellConfig, axis: &AxisConfig) -> Self {
        let hold = axis.profile.fault_reset_hold(cell.cycle_time);
        let timeout = cell
            .cycle_time
            .cycles_for(std::time::Duration::from_secs(2));
        AxisChannel {
            master: AxisMaster::new(MasterParams {
                fault_reset_hold: hold,
                transition_timeout: Cycles(timeout.0.max(10)),
            }),
            limits: AxisLimitsCounts::new(axis, cell.period()),
            setpoint: axis.scaling.to_counts(axis.sim.initial_position),
            velocity: 0.0,
            feedback: TxPdo::default(),
            stopped: true,
            rx_map: axis.profile.rx_pdo,
            tx_map: axis.profile.tx_pdo,
        }
    }

    /// Follows the drive's actual position (while not enabled: no jump at enable).
    pub fn track_actual(&mut self) {
        self.setpoint = f64::from(self.feedback.position_actual);
        self.velocity = 0.0;
    }

    /// Starts the controlled stop ramp from the current setpoint velocity.
    pub fn begin_stop(&mut self) {
        self.stopped = self.velocity == 0.0;
    }

    /// One cycle of the controlled stop ramp: constant deceleration to zero velocity.
    pub fn stop_step(&mut self, period: f64) {
        if self.stopped {
            return;
        }
        let dv = self.limits.stop_deceleration * period;
        if self.velocity.abs() <= dv {
            // Last partial cycle: cover the remaining distance v²/2a.
            self.setpoint +=
                self.velocity * self.velocity.abs() / (2.0 * self.limits.stop_deceleration);
            self.velocity = 0.0;
            self.stopped = true;
        } else {
            let v_next = self.velocity - dv * self.velocity.signum();
            self.setpoint += 0.5 * (self.velocity + v_next) * period;
            self.velocity = v_next;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn channel(v: f64, decel: f64) -> AxisChannel {
        AxisChannel {
            master: AxisMaster::new(MasterParams {
                fault_reset_hold: Cycles(10),
                transition_timeout: Cycles(100),
            }),
            limits: AxisLimitsCounts {
                position_min: -1e9,
                position_max: 1e9,
                max_step: 1e9,
                stop_deceleration: decel,
            },
            setpoint: 0.0,
            velocity: v,
            feedback: TxPdo::default(),
            stopped: false,
            rx_map: cellrt_axes::profiles::profile(cellrt_axes::profiles::DriveModel::MrJ5GN1)
                .rx_pdo,
            tx_map: cellrt_axes::profiles::profile(cellrt_axes::profiles::DriveModel::MrJ5GN1)
                .tx_pdo,
        }
    }

    #[test]
    fn stop_ramp_covers_v_squared_over_2a_and_never_reverses() {
        for v in [10_000.0, -10_000.0, 123.0] {
            let mut ch = channel(v, 100_000.0);
            ch.begin_stop();
            let mut last = ch.setpoint;
            for _ in 0..10_000 {
                ch.stop_step(1e-3);
                assert!((ch.setpoint - last) * v.signum() >= 0.0, "reversed");
                assert!(
                    (ch.setpoint - last).abs() <= v.abs() * 1e-3 + 1e-9,
                    "step too large"
                );
                last = ch.setpoint;
                if ch.stopped {
                    break;
                }
            }
            assert!(ch.stopped);
            let expect = v * v.abs() / (2.0 * 100_000.0);
            assert!(
                (ch.setpoint - expect).abs() < 1e-6,
                "{} vs {expect}",
                ch.setpoint
            );
        }
    }
}
