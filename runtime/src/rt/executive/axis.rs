//! One axis as the RT loop sees it: its CiA 402 master, its current setpoint, and the controlled
//! stop ramp the RT thread runs on its own.

use cellrt_cia402::comm::IncrementalCounter;
use cellrt_cia402::drive_scaling::{DriveScaling, OutOfRange};
use cellrt_cia402::homing::{HomingParams, HomingSequencer};
use cellrt_cia402::master::AxisMaster;
use cellrt_cia402::mode::ModeOfOperation;
use cellrt_cia402::pdo::objects::{
    CONTROLWORD2, DEFAULT_TORQUE_LIMIT, ERROR_CODE, FOLLOWING_ERROR, MODES_OF_OPERATION,
    MODES_OF_OPERATION_DISPLAY, STATUSWORD2,
};
use cellrt_cia402::pdo::{PdoLayout, TxPdo};
use cellrt_cia402::profiles::{HomeReference, HomeSetting, TorqueLimitSelection};
use cellrt_cia402::Cycles;

use crate::handoff::RejectReason;
use cellrt_config::{AxisConfig, CellConfig};

/// Per-axis limits converted to counts and cycles once, at start-up.
#[derive(Debug, Clone, Copy)]
pub struct AxisLimitsCounts {
    /// Lowest allowed setpoint, counts.
    pub position_min: f64,
    /// Highest allowed setpoint, counts.
    pub position_max: f64,
    /// The axis' velocity limit, counts/s.
    pub velocity: f64,
    /// Largest allowed setpoint change per cycle, counts (velocity limit × period, plus
    /// [`STEP_TOLERANCE`]).
    pub max_step: f64,
    /// Controlled-stop deceleration, counts/s².
    pub stop_deceleration: f64,
    /// Controlled-stop jerk, counts/s³.
    pub stop_jerk: f64,
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
            velocity: axis.limits.velocity * s,
            max_step: axis.limits.velocity * s * period * (1.0 + STEP_TOLERANCE) + 1e-6,
            stop_deceleration: axis.stop_deceleration * s,
            stop_jerk: axis.stop_jerk * s,
        }
    }
}

/// RT state of one axis.
#[derive(Debug)]
pub struct AxisChannel {
    /// The CiA 402 master driving this axis' controlword.
    pub master: AxisMaster,
    /// The master side of the incremental counter, where the drive's PDO maps carry one
    /// (MR-J3-T04 2020h/2021h).
    pub counter: Option<IncrementalCounter>,
    /// The drive's communication check: which TxPDO object echoes the counter.
    pub comm_check: cellrt_cia402::profiles::CommCheck,
    /// A counter error was reported for this axis (once, until reset).
    pub comm_fault: bool,
    /// The link state of the axis' node last seen (EtherCAT: its SubDevice's AL status).
    pub link_state: Option<cellrt_cia402::bus::LinkState>,
    /// Limits in counts.
    pub limits: AxisLimitsCounts,
    /// Setpoint position of the current cycle, counts.
    pub setpoint: f64,
    /// Setpoint velocity of the current cycle, counts/s.
    pub velocity: f64,
    /// Setpoint acceleration of the current cycle, counts/s² (from the velocity change).
    pub acceleration: f64,
    /// The latest decoded TxPDO.
    pub feedback: TxPdo,
    /// Whether the stop ramp of this axis has reached zero velocity.
    pub stopped: bool,
    /// The drive's RxPDO map (from its profile), resolved for the cyclic codec.
    pub rx_map: PdoLayout,
    /// The drive's TxPDO map (from its profile), resolved for the cyclic codec.
    pub tx_map: PdoLayout,
    /// Whether the TxPDO carries the error code (603Fh); if not, it needs an SDO read.
    pub error_code_mapped: bool,
    /// Whether the TxPDO carries 60F4h; if not, the following error is computed
    /// ([`AxisChannel::computed_following_error`]).
    pub following_error_mapped: bool,
    /// The axis' configured cyclic mode (6060h).
    pub mode: ModeOfOperation,
    /// csv position-correction gain, 1/s (see `AxisConfig::csv_position_gain`).
    pub csv_position_gain: f64,
    /// Torque limits in 0.1 % units: (largest |6071h|, largest change per second).
    pub torque_limits: Option<(f64, f64)>,
    /// 60E0h/60E1h and Controlword2 sent every cycle: `limits.torque` where configured (and, on
    /// a drive that selects its limits by Controlword2, the bit that applies them).
    pub torque_limit_objects: (u16, u16, u16),
    /// cst: the torque setpoint of this cycle in 0.1 % units, while a torque motion runs.
    pub torque: Option<f64>,
    /// Braking in csv from the velocity a torque motion left the axis at.
    pub braking: bool,
    /// Homing in the drive's hm mode.
    pub homing: HomingSequencer,
    /// The homing objects written by SDO after 6098h (`[axes.homing]`).
    pub homing_objects: cellrt_config::homing::HomingObjects,
    /// Whether the TxPDO carries 6061h (else mode changes count as done after a settle time).
    pub mode_display_mapped: bool,
    /// Where the RxPDO lacks 6060h (MR-J3-T04, MR-J3-T04 manual §8.4.2): the mode last written by
    /// SDO (the drive starts in its parameter's mode, the cyclic one); `None` where mapped.
    pub sdo_mode: Option<ModeOfOperation>,
    /// 607Ch in counts where the drive does not shift 6064h by it (MR-J3-T04, MR-J3-T04 manual
    /// §8.2): the master works in user counts, user = raw + home offset; 0 elsewhere.
    pub home_offset: i32,
    /// Whether the drive reports its home as 607Ch instead of presetting 6064h.
    pub offset_home: bool,
    /// Home setting by Controlword2 where the model has it and the maps carry 2001h/2011h
    /// (MR-J3-T04 C_CR / C_CR2, MR-J3-T04 manual §8.11.6).
    pub home_setting: Option<HomeSetting>,
    /// Axis counts ↔ the drive's object units (60FFh/606Ch/2D20h, torque), precomputed.
    pub drive_units: DriveScaling,
    /// 2D20h sent every cycle: the axis' velocity limit in the drive's velocity unit (fits:
    /// checked at config load).
    pub speed_limit: u32,
    /// 60FFh of the previous cycle, kept when a new one cannot be represented.
    pub sent_velocity: i32,
    /// A profile axis (pp/pv/tq): its drive-side motion; `None` for a cyclic axis.
    pub profile: Option<super::profile_axis::ProfileChannel>,
    /// A csp axis that can be switched to pp at run time: the pp plan and the rated speed its
    /// time constants run from (`config::profile_axis::pp_switch`); `None` otherwise.
    pub pp_switch: Option<(cellrt_config::ProfileObjects, Option<f64>)>,
    /// A run-time mode switch in progress.
    pub mode_switch: Option<cellrt_cia402::mode_switch::ModeSwitch>,
    /// MC_Power of this axis: the operator wants it in Operation enabled. An axis without
    /// power follows its actual position and takes no motion.
    pub powered: bool,
}

/// Cycles after which a mode change counts as done on a drive whose TxPDO lacks 6061h (no
/// figure in the manuals; see `cellrt_cia402::homing`).
pub const HOMING_MODE_SETTLE: Cycles = Cycles(4);

/// (60E0h, 60E1h, Controlword2) for `axis`: its `limits.torque` in 0.1 % in both directions,
/// selected by C_TL on a drive that needs it (MR-J3-T04 §9.4); the no-limit default otherwise.
fn torque_limit_objects(axis: &AxisConfig) -> (u16, u16, u16) {
    let Some(t) = axis.torque else {
        return (DEFAULT_TORQUE_LIMIT, DEFAULT_TORQUE_LIMIT, 0);
    };
    // `limits.torque` ≤ MAX_TORQUE_PERCENT (checked at load) always fits 60E0h.
    let v = axis
        .drive_units
        .torque_limit_to_drive(t.max.0)
        .unwrap_or(DEFAULT_TORQUE_LIMIT);
    let cw2 = match axis.profile.limits.torque_limit_selection {
        TorqueLimitSelection::Objects | TorqueLimitSelection::TorqueLimit2 { .. } => 0,
        TorqueLimitSelection::Controlword2 { c_tl_bit, .. } => 1 << c_tl_bit,
    };
    (v, v, cw2)
}

/// What the RxPDO commands this cycle: the mode and the target for it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriveCommand {
    /// 6060h.
    pub mode: ModeOfOperation,
    /// 60FFh in the drive's velocity unit (csv).
    pub target_velocity: i32,
    /// 6071h, 0.1 % of rated torque (cst).
    pub target_torque: i16,
}

impl AxisChannel {
    /// Preallocates the channel of `axis` in `cell`.
    pub fn new(cell: &CellConfig, axis: &AxisConfig) -> Self {
        let timeout = cell
            .cycle_time
            .cycles_for(std::time::Duration::from_secs(2));
        AxisChannel {
            master: AxisMaster::for_profile(
                &axis.profile,
                cell.cycle_time,
                Cycles(timeout.0.max(10)),
            ),
            counter: axis
                .profile
                .comm
                .check
                .master_counter()
                .filter(|_| axis.profile.pdo.rx.has_counter())
                .map(|model| IncrementalCounter::new(cell.watchdogs.comm.counter_params(model), 0)),
            comm_check: axis.profile.comm.check,
            comm_fault: false,
            link_state: None,
            limits: AxisLimitsCounts::new(axis, cell.period()),
            setpoint: axis.scaling.to_counts(axis.sim.initial_position),
            velocity: 0.0,
            acceleration: 0.0,
            feedback: TxPdo::default(),
            stopped: true,
            rx_map: PdoLayout::new(&axis.profile.pdo.rx),
            tx_map: PdoLayout::new(&axis.profile.pdo.tx),
            error_code_mapped: axis
                .profile
                .pdo
                .tx
                .entries
                .iter()
                .any(|e| e.index == ERROR_CODE),
            following_error_mapped: axis.profile.pdo.tx.maps(FOLLOWING_ERROR),
            mode: axis.mode,
            csv_position_gain: axis.csv_position_gain,
            torque_limits: axis.torque.map(|t| (t.max.0 * 10.0, t.slope * 10.0)),
            torque_limit_objects: torque_limit_objects(axis),
            drive_units: axis.drive_units,
            // Fits: `limits.velocity` is checked against the drive's unit at config load.
            speed_limit: axis
                .drive_units
                .speed_limit_to_drive(axis.limits.velocity * axis.scaling.counts_per_unit())
                .unwrap_or(0),
            sent_velocity: 0,
            profile: axis
                .profile_objects
                .map(|o| super::profile_axis::ProfileChannel::new(o, axis.rated_speed, 0)),
            pp_switch: cellrt_config::profile_axis::pp_switch(axis)
                .ok()
                .map(|o| (o, axis.rated_speed)),
            mode_switch: None,
            torque: None,
            braking: false,
            homing: HomingSequencer::new(
                HomingParams {
                    timeout: cell.cycle_time.cycles_for(axis.homing.timeout),
                    mode_settle: HOMING_MODE_SETTLE,
                },
                // A cst axis idles in csv (`drive_command`).
                match axis.mode {
                    ModeOfOperation::CyclicSyncTorque => ModeOfOperation::CyclicSyncVelocity,
                    m => m,
                },
            ),
            homing_objects: axis.homing.objects,
            mode_display_mapped: axis.profile.pdo.tx.maps(MODES_OF_OPERATION_DISPLAY),
            home_offset: 0,
            offset_home: axis.profile.homing.reference == HomeReference::OffsetObject,
            home_setting: axis.profile.homing.setting.filter(|_| {
                axis.profile.pdo.rx.maps(CONTROLWORD2) && axis.profile.pdo.tx.maps(STATUSWORD2)
            }),
            powered: false,
            sdo_mode: (!axis.profile.pdo.rx.maps(MODES_OF_OPERATION)).then_some(match axis.mode {
                ModeOfOperation::CyclicSyncTorque => ModeOfOperation::CyclicSyncVelocity,
                m => m,
            }),
        }
    }

    /// A raw 6064h as the master's user counts: raw + 607Ch on a drive that reports home as an
    /// offset (MR-J3-T04 manual §8.11.4.2, §8.11.6, §9.1, TV-HOME-1), raw elsewhere (offset 0).
    pub fn to_user(&self, raw: i32) -> i32 {
        raw.wrapping_add(self.home_offset)
    }

    /// A user position as the raw 607Ah the drive expects: user − 607Ch (TV-HOME-1).
    pub fn to_raw(&self, user: i32) -> i32 {
        user.wrapping_sub(self.home_offset)
    }

    /// The following error where the drive does not map 60F4h: the setpoint it was sent
    /// minus `actual`, counts (CiA 402's definition of 60F4h, computed by the master; some
    /// drives never fill 60F4h). Saturates at the i32 range.
    pub fn computed_following_error(&self, actual: i32) -> i32 {
        (self.setpoint - f64::from(actual))
            .round()
            .clamp(f64::from(i32::MIN), f64::from(i32::MAX)) as i32
    }

    /// A csp axis a run-time mode switch left in pp (it has the pp plan and runs a profile).
    pub fn switched_to_pp(&self) -> bool {
        self.pp_switch.is_some() && self.profile.is_some()
    }

    /// Follows the drive's actual position (while not enabled: no jump at enable).
    pub fn track_actual(&mut self) {
        self.setpoint = f64::from(self.feedback.position_actual);
        self.velocity = 0.0;
        self.acceleration = 0.0;
        self.torque = None;
        self.braking = false;
    }

    /// cst: takes a torque setpoint (0.1 %); the position setpoint follows the motor, so a stop
    /// ramp or a later position motion starts from where and how fast it moves.
    pub fn apply_torque(&mut self, torque: f64) {
        self.torque = Some(torque);
        self.braking = false;
        self.setpoint = f64::from(self.feedback.position_actual);
        self.velocity = self
            .drive_units
            .velocity_from_drive(self.feedback.velocity_actual);
        self.acceleration = 0.0;
    }

    /// Checks a cst torque setpoint (0.1 %) against the axis' torque limit and slope over `dt`.
    pub fn check_torque(&self, torque: f64, dt: f64) -> Result<(), RejectReason> {
        let Some((max, slope)) = self.torque_limits else {
            return Err(RejectReason::TorqueLimit);
        };
        if !torque.is_finite() {
            return Err(RejectReason::Malformed);
        }
        if torque.abs() > max * (1.0 + STEP_TOLERANCE) {
            return Err(RejectReason::TorqueLimit);
        }
        let last = self.torque.unwrap_or(0.0);
        if (torque - last).abs() > slope * dt * (1.0 + STEP_TOLERANCE) + 1e-6 {
            return Err(RejectReason::TorqueStep);
        }
        Ok(())
    }

    /// The mode and target this cycle's RxPDO carries. csp: 607Ah only. csv: the setpoint
    /// velocity plus the master's position correction. cst: the torque setpoint while a torque
    /// motion runs; otherwise (idle, stop ramps, position motions) the axis runs in csv. pp, pv,
    /// tq: the axis' own mode, held.
    /// Targets in the drive's units; one the drive's object cannot represent is an error, never
    /// clamped.
    pub fn drive_command(&self) -> Result<DriveCommand, OutOfRange> {
        Ok(match (self.mode, self.torque) {
            (ModeOfOperation::CyclicSyncTorque, Some(t)) => DriveCommand {
                mode: ModeOfOperation::CyclicSyncTorque,
                target_velocity: 0,
                target_torque: self.drive_units.torque_to_drive(t / 10.0)?,
            },
            (ModeOfOperation::CyclicSyncVelocity | ModeOfOperation::CyclicSyncTorque, _) => {
                let error = self.setpoint - f64::from(self.feedback.position_actual);
                let v = self.velocity + self.csv_position_gain * error;
                DriveCommand {
                    mode: ModeOfOperation::CyclicSyncVelocity,
                    target_velocity: self.drive_units.velocity_to_drive(v)?,
                    target_torque: 0,
                }
            }
            // A profile axis (pp/pv/tq) stays in its mode with no velocity or torque target;
            // 607Ah holds the setpoint and no new set-point (bit 4) is given.
            (
                m @ (ModeOfOperation::ProfilePosition
                | ModeOfOperation::ProfileVelocity
                | ModeOfOperation::ProfileTorque),
                _,
            ) => DriveCommand {
                mode: m,
                target_velocity: 0,
                target_torque: 0,
            },
            _ => DriveCommand {
                mode: ModeOfOperation::CyclicSyncPosition,
                target_velocity: 0,
                target_torque: 0,
            },
        })
    }

    /// The speed limit for cst (2D20h) in the drive's velocity unit: the axis' velocity limit.
    pub fn velocity_limit(&self) -> u32 {
        self.speed_limit
    }

    /// Takes a new setpoint from the stream; `dt` is the time since the previous one.
    pub fn apply(&mut self, position: f64, velocity: f64, dt: f64) {
        self.acceleration = (velocity - self.velocity) / dt;
        self.setpoint = position;
        self.velocity = velocity;
    }

    /// Holds the current setpoint at rest. An axis a torque motion left moving brakes first,
    /// with the controlled-stop ramp, in csv.
    pub fn hold(&mut self, period: f64) {
        if self.torque.take().is_some() {
            self.braking = true;
            self.stopped = self.velocity == 0.0;
        }
        if self.braking {
            self.stop_step(period);
            self.braking = !self.stopped;
            return;
        }
        self.velocity = 0.0;
        self.acceleration = 0.0;
    }

    fn rest(&mut self) {
        self.velocity = 0.0;
        self.acceleration = 0.0;
    }

    /// Starts the controlled stop ramp from the current setpoint velocity.
    pub fn begin_stop(&mut self) {
        self.torque = None;
        self.braking = false;
        self.stopped = self.velocity == 0.0;
    }

    /// One cycle of the controlled stop: jerk-limited braking from the current velocity and
    /// acceleration to rest. The acceleration is steered towards
    /// `-sign(v) · min(deceleration, sqrt(2 · jerk · |v|))` — the most braking that can still be
    /// ramped out at the stop jerk exactly when the velocity reaches zero — changing by at most
    /// `jerk · dt` per cycle.
    pub fn stop_step(&mut self, period: f64) {
        if self.stopped {
            return;
        }
        let (d, j) = (self.limits.stop_deceleration, self.limits.stop_jerk);
        let (v, a) = (self.velocity, self.acceleration);
        let dir = v.signum();
        if v == 0.0 {
            self.rest();
            self.stopped = true;
            return;
        }
        let a_target = -dir * d.min((2.0 * j * v.abs()).sqrt());
        let a_next = a + (a_target - a).clamp(-j * period, j * period);
        let v_next = v + 0.5 * (a + a_next) * period;
        if v_next * dir <= 0.0 {
            // Rest is reached within this cycle: cover the remaining distance under the
            // current braking and stop.
            let a_brake = a_next.abs().max(f64::MIN_POSITIVE);
            self.setpoint += v * v.abs() / (2.0 * a_brake.max(v.abs() / period));
            self.rest();
            self.stopped = true;
        } else {
            self.setpoint += 0.5 * (v + v_next) * period;
            self.velocity = v_next;
            self.acceleration = a_next;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cellrt_cia402::master::MasterParams;

    fn channel(v: f64, a: f64, decel: f64, jerk: f64) -> AxisChannel {
        AxisChannel {
            master: AxisMaster::new(MasterParams {
                fault_reset_hold: Cycles(10),
                transition_timeout: Cycles(100),
            }),
            counter: None,
            comm_check: cellrt_cia402::profiles::CommCheck::SyncErrorCounter { alarm: 0 },
            comm_fault: false,
            link_state: None,
            limits: AxisLimitsCounts {
                position_min: -1e12,
                position_max: 1e12,
                velocity: 1e12,
                max_step: 1e12,
                stop_deceleration: decel,
                stop_jerk: jerk,
            },
            setpoint: 0.0,
            velocity: v,
            acceleration: a,
            feedback: TxPdo::default(),
            stopped: false,
            rx_map: PdoLayout::new(
                &cellrt_cia402::profiles::profile(cellrt_cia402::profiles::DriveModel::MrJ5GN1)
                    .pdo
                    .rx,
            ),
            tx_map: PdoLayout::new(
                &cellrt_cia402::profiles::profile(cellrt_cia402::profiles::DriveModel::MrJ5GN1)
                    .pdo
                    .tx,
            ),
            error_code_mapped: false,
            following_error_mapped: true,
            mode: ModeOfOperation::CyclicSyncPosition,
            csv_position_gain: 0.0,
            torque_limits: None,
            torque_limit_objects: (DEFAULT_TORQUE_LIMIT, DEFAULT_TORQUE_LIMIT, 0),
            drive_units: DriveScaling::new(
                &cellrt_cia402::profiles::generic_cia402::UNITS,
                cellrt_cia402::profiles::VelocityUnit::CountsPerSecond,
                None,
            )
            .expect("counts/s needs no resolution"),
            speed_limit: 0,
            sent_velocity: 0,
            profile: None,
            pp_switch: None,
            mode_switch: None,
            torque: None,
            braking: false,
            homing: HomingSequencer::new(
                HomingParams {
                    timeout: Cycles(100),
                    mode_settle: HOMING_MODE_SETTLE,
                },
                ModeOfOperation::CyclicSyncPosition,
            ),
            homing_objects: Default::default(),
            mode_display_mapped: true,
            sdo_mode: None,
            home_setting: None,
            powered: true,
            home_offset: 0,
            offset_home: false,
        }
    }

    /// MR-J3-T04 TV-HOME-1 (docs/test-vectors.md): home at raw 10000 → 607Ch = −10000; user target 5000 goes out
    /// as 607Ah = 15000, user 0 as 10000; raw 15000 reads as user 5000.
    #[test]
    fn tv_home_1_master_converts_user_and_raw_counts() {
        let mut ch = channel(0.0, 0.0, 1.0, 1.0);
        assert_eq!((ch.to_raw(5000), ch.to_user(10000)), (5000, 10000));
        ch.home_offset = -10000;
        assert_eq!(ch.to_raw(5000), 15000);
        assert_eq!(ch.to_raw(0), 10000);
        assert_eq!(ch.to_user(15000), 5000);
        assert_eq!(ch.to_user(10000), 0);
        // The wire is a wrapping 32-bit position.
        assert_eq!(ch.to_raw(i32::MIN), i32::MIN.wrapping_add(10000));
    }

    /// Runs a stop to the end; returns (cycles, distance, max |Δv|/dt, max |Δa|/dt before the
    /// last cycle).
    fn run_stop(ch: &mut AxisChannel, dt: f64) -> (usize, f64, f64, f64) {
        let v0 = ch.velocity;
        ch.begin_stop();
        let (mut dec, mut jerk) = (0.0f64, 0.0f64);
        for n in 1..1_000_000 {
            let (p, v, a) = (ch.setpoint, ch.velocity, ch.acceleration);
            ch.stop_step(dt);
            assert!(
                (ch.setpoint - p) * v0.signum() >= -1e-9,
                "reversed at cycle {n}"
            );
            let vmax = v0.abs().max(v.abs()).max(ch.velocity.abs());
            assert!((ch.setpoint - p).abs() <= vmax * dt + 1e-9);
            dec = dec.max((ch.velocity - v).abs() / dt);
            if ch.stopped {
                return (n, ch.setpoint, dec, jerk);
            }
            jerk = jerk.max((ch.acceleration - a).abs() / dt);
        }
        panic!("never stopped");
    }

    #[test]
    fn stop_respects_deceleration_and_jerk_and_ends_at_rest() {
        let (d, j, dt) = (100_000.0, 1_000_000.0, 1e-3);
        for (v, a) in [
            (10_000.0, 0.0),
            (-10_000.0, 0.0),
            (5_000.0, 50_000.0),
            (123.0, -3_000.0),
        ] {
            let mut ch = channel(v, a, d, j);
            let (n, dist, dec, jerk) = run_stop(&mut ch, dt);
            assert!(dec <= d * (1.0 + 1e-9), "v {v}: decel {dec}");
            assert!(jerk <= j * (1.0 + 1e-9), "v {v}: jerk {jerk}");
            assert_eq!(ch.velocity, 0.0);
            assert_eq!(ch.acceleration, 0.0);
            // No faster than the constant-deceleration stop, and not absurdly longer.
            assert!(
                dist.abs() >= v * v / (2.0 * d) * 0.99 - 1.0,
                "v {v}: {dist}"
            );
            let bound = v.abs() / d + a.abs() / j + 2.0 * d / j + 0.01;
            assert!((n as f64) * dt <= bound, "v {v}: {n} cycles");
        }
    }

    #[test]
    fn a_high_stop_jerk_approaches_the_constant_deceleration_distance() {
        let mut ch = channel(10_000.0, 0.0, 100_000.0, 1e12);
        let (_, dist, _, _) = run_stop(&mut ch, 1e-4);
        let ideal = 10_000.0f64.powi(2) / (2.0 * 100_000.0);
        assert!((dist - ideal).abs() / ideal < 0.01, "{dist} vs {ideal}");
    }

    #[test]
    fn the_computed_following_error_is_setpoint_minus_actual_and_saturates() {
        let mut ch = channel(0.0, 0.0, 1.0, 1.0);
        ch.setpoint = 1000.4;
        assert_eq!(ch.computed_following_error(990), 10);
        assert_eq!(ch.computed_following_error(1010), -10);
        ch.setpoint = 1e12;
        assert_eq!(ch.computed_following_error(0), i32::MAX);
    }
}
