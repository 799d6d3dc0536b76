//! Slow stops: the stroke-end inputs LSP/LSN in csv and the csp manual stop C_MSTOP.

use super::SimDrive;
use cellrt_cia402::pdo::RxPdo;

/// The csp manual stop of MR-J3-T04 manual §8.13 (TV-STROKE-2).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(super) struct ManualStop {
    /// C_MSTOP is on: 607Ah is discarded.
    pub(super) active: bool,
    /// Velocity of the linear PC02 ramp of the demand, counts/s.
    pub(super) ramp_velocity: f64,
    /// The internal command has been fully output: S_FLW (statusword bit 14).
    pub(super) done: bool,
}

/// LSP/LSN inputs (ON = may run in that direction) and the stroke-end slow stop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct StrokeState {
    /// LSP: CCW (positive) motion allowed.
    pub(super) lsp: bool,
    /// LSN: CW (negative) motion allowed.
    pub(super) lsn: bool,
    /// The slow stop runs: commands are discarded until the motor has stopped once.
    pub(super) stopping: bool,
    /// Velocity of the slow-stop ramp, counts/s.
    pub(super) ramp_velocity: f64,
    /// AL.99 active: an input is OFF or its slow stop still runs.
    pub(super) warning: bool,
}

impl Default for StrokeState {
    fn default() -> Self {
        StrokeState {
            lsp: true,
            lsn: true,
            stopping: false,
            ramp_velocity: 0.0,
            warning: false,
        }
    }
}

impl SimDrive {
    /// Sets the stroke-end inputs LSP (CCW allowed) and LSN (CW allowed); ON = may run. On a
    /// model with a stroke-end warning an input OFF raises it (MR-J3-T04 AL.99, §9.1); it
    /// clears by itself once both are ON again and the slow stop is over.
    pub fn set_stroke_end_inputs(&mut self, lsp: bool, lsn: bool) {
        self.stroke.lsp = lsp;
        self.stroke.lsn = lsn;
    }

    /// csv under the stroke-end rules (MR-J3-T04 manual §3.9, §8.11.7, TV-STROKE-1): moving into an OFF
    /// input starts a PC02 slow stop during which 60FFh is discarded; after the stop the
    /// blocked direction stays refused and the other one is accepted.
    pub(super) fn stroke_limited_velocity(&mut self, v: f64, dt: f64) -> f64 {
        if self.profile.limits.stroke_end_warning.is_none() {
            return v;
        }
        let moving = self.plant.velocity();
        let blocked = |dir: f64, s: &StrokeState| (dir > 0.0 && !s.lsp) || (dir < 0.0 && !s.lsn);
        if !self.stroke.stopping
            && blocked(moving, &self.stroke)
            && moving.abs() > self.params.zero_speed
        {
            self.stroke.stopping = true;
            self.stroke.ramp_velocity = moving;
        }
        self.stroke.warning = !(self.stroke.lsp && self.stroke.lsn) || self.stroke.stopping;
        if self.stroke.stopping {
            let decel = self.slow_stop_deceleration();
            let r = self.stroke.ramp_velocity;
            let next = r - r.signum() * decel * dt;
            self.stroke.ramp_velocity = if next * r <= 0.0 { 0.0 } else { next };
            // "Until the motor has stopped once": the motor, not only the ramp (at or below
            // `zero_speed`, and never above 1 count/s).
            if self.stroke.ramp_velocity == 0.0 && self.at_zero_speed() {
                self.stroke.stopping = false;
            }
            return self.stroke.ramp_velocity;
        }
        if blocked(v, &self.stroke) {
            0.0
        } else {
            v
        }
    }

    /// The PC02 deceleration of slow stops (stroke end, manual stop), counts/s².
    pub(super) fn slow_stop_deceleration(&self) -> f64 {
        let amax = self.params.plant.max_acceleration.abs();
        let ms = i64::from(self.params.slow_stop_time_ms);
        crate::motion::ramp::time_constant_rate(self.params.plant.max_velocity.abs(), ms)
            .map_or(amax, |rate| rate.min(amax))
    }

    /// csp with C_MSTOP (MR-J3-T04 manual §8.13): while it is on, 607Ah is discarded and the demand
    /// ramps linearly to rest with PC02; S_FLW = 1 once it has been fully output. Cleared, the
    /// drive tracks 607Ah again from where it stopped (the master copies 6062h into 607Ah
    /// first, or the motor jumps to the old target). True while the manual stop owns the demand.
    pub(super) fn manual_stop(&mut self, cmd: &RxPdo, dt: f64) -> bool {
        let Some(bit) = self.profile.limits.manual_stop_bit else {
            return false;
        };
        let on = cmd.controlword2 & (1 << bit) != 0;
        if on && !self.mstop.active {
            self.mstop = ManualStop {
                active: true,
                ramp_velocity: self.plant.velocity(),
                done: false,
            };
        }
        if !on {
            if self.mstop.active {
                // The command resumes from the stop point: a 607Ah left far away is one big
                // step (TV-STROKE-2's negative case), checked like any other (AL.35).
                self.mstop = ManualStop::default();
                self.prev_target = self.position_demand().wrapping_sub(self.position_offset());
            }
            return false;
        }
        let r = self.mstop.ramp_velocity;
        let next = r - r.signum() * self.slow_stop_deceleration() * dt;
        self.mstop.ramp_velocity = if next * r <= 0.0 { 0.0 } else { next };
        self.demand += 0.5 * (r + self.mstop.ramp_velocity) * dt;
        self.mstop.done = self.mstop.ramp_velocity == 0.0;
        self.prev_target = cmd.target_position;
        true
    }
}
