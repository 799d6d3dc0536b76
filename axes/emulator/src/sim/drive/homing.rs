//! Homing (hm): the data-set methods, the searching methods on the axis' switches
//! (`motion::homing_search`), and the Controlword2 home setting with the Z phase.

use super::SimDrive;
use crate::motion::homing::{HomingMethods, HomingStart};
use crate::motion::homing_search::{HomingSearch, SearchEnd, SearchProfile, ZPulses};
use crate::sim::home_setting::{HomeSettingOutcome, ZPhase};
use cellrt_cia402::controlword::Controlword;
use cellrt_cia402::fsa::FsaState;
use cellrt_cia402::mode::ModeOfOperation;
use cellrt_cia402::pdo::RxPdo;
use cellrt_cia402::profiles::homing_methods::{homing_model, SearchTarget};
use cellrt_cia402::profiles::HomeReference;

/// 6099h Homing speeds (sub 1 switch search, sub 2 creep).
const HOMING_SPEEDS: u16 = 0x6099;
/// 609Ah Homing acceleration.
const HOMING_ACCELERATION: u16 = 0x609A;

/// What homing has done to this drive.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(super) struct HomingState {
    /// 607Ch Home offset.
    pub(super) home_offset: i32,
    /// Added to the motor position to give 6064h ([`HomeReference::PositionPreset`]).
    pub(super) position_shift: i64,
    /// Statusword bit 12 in hm: homing attained (cleared at power-on and at homing start).
    pub(super) attained: bool,
    /// Statusword bit 13 in hm: homing error.
    pub(super) error: bool,
    /// Controlword bit 4 (HOS) of the previous cycle.
    pub(super) hos: bool,
    /// The searching method running, if any.
    pub(super) search: Option<HomingSearch>,
    /// The search's generator has ended: the motor settles on this raw position; true if it
    /// is the home (false: a failed search stopping).
    pub(super) settling: Option<(f64, bool)>,
    /// HOS dropped during the search: it stops without an error.
    pub(super) interrupted: bool,
    /// The model's warning of the last failed search (MR-J3-T04 AL.90, MR-J4-TM AL. 90),
    /// cleared by the next start.
    pub(super) warning: Option<u16>,
}

impl SimDrive {
    /// hm (6060h = 6): a rising controlword bit 4 (HOS) starts the method in 6098h. The
    /// data-set methods set home at the current position at once, without motion (also outside
    /// Operation enabled, MR-J3-T04 manual §8.11.3, §8.11.6); the searching methods run on the
    /// axis' switches (`motion::homing_search`) in Operation enabled; a method the manual does not
    /// list, one cellrt does not emulate, or 0 ends in a homing error (bit 13). Leaving hm or
    /// dropping HOS ends a search (interrupted).
    pub(super) fn run_homing(&mut self, cw: Controlword) {
        let hos = cw.0 & (1 << 4) != 0;
        let start = hos && !self.homing.hos;
        self.homing.hos = hos;
        let enabled = self.state == FsaState::OperationEnabled;
        if self.mode_display != ModeOfOperation::Homing || !enabled {
            self.homing.search = None;
            self.homing.settling = None;
        }
        if let Some(search) = self.homing.search.as_mut().filter(|s| !hos && !s.failing()) {
            // HOS dropped: interrupted, the motor stops (no error).
            search.interrupt();
            self.homing.interrupted = true;
        }
        if self.mode_display != ModeOfOperation::Homing || !start {
            return;
        }
        if matches!(self.state, FsaState::Fault | FsaState::FaultReactionActive) {
            return;
        }
        let method = self
            .sdo_value(0x6098, 0)
            .or_else(|| self.object(0x6098, 0).and_then(|o| o.default))
            .unwrap_or(0) as i8;
        let methods = HomingMethods {
            listed: self.profile.homing.methods,
            data_set: self.profile.homing.data_set_methods,
        };
        // Homing start clears bit 12 (MR-J4-TM manual §5.4.9 retention rules).
        self.homing.attained = false;
        self.homing.error = false;
        self.homing.warning = None;
        self.homing.interrupted = false;
        match methods.start(i64::from(method), enabled) {
            HomingStart::SetHome => {
                let raw = self.plant.position().round();
                self.set_home(raw);
            }
            HomingStart::Search(recipe) => {
                let p = self.search_profile();
                let s = &self.params.homing_switches;
                self.homing.search = Some(HomingSearch::start(recipe, p, self.demand, s));
            }
            HomingStart::Error => self.homing.error = true,
        }
    }

    /// Home at raw motor position `raw`: 607Ch or the 6064h preset, and bit 12.
    fn set_home(&mut self, raw: f64) {
        let raw = (raw as i64) as i32;
        match self.profile.homing.reference {
            HomeReference::OffsetObject => self.homing.home_offset = raw.wrapping_neg(),
            HomeReference::PositionPreset => {
                self.homing.position_shift =
                    i64::from(self.params.home_position_address) - i64::from(raw);
                // Re-reference the held command so the motor does not move.
                self.demand = self.plant.position();
                self.plant.set_last_command(self.demand);
                self.prev_target = self.position_actual();
            }
        }
        self.homing.attained = true;
    }

    /// 6099h:1/2, 609Ah and the shift (MR-J3-T04 2080h) in counts: the written values, else
    /// the model's defaults.
    fn search_profile(&self) -> SearchProfile {
        let value = |index: u16, sub: u8| {
            self.sdo_value(index, sub)
                .or_else(|| self.object(index, sub).and_then(|o| o.default))
        };
        let speed = |sub: u8| {
            self.commanded_counts_per_s(value(HOMING_SPEEDS, sub).unwrap_or(0))
                .abs()
        };
        let shift = homing_model(self.profile.model)
            .shift_object
            .and_then(|i| value(i, 0))
            .unwrap_or(0);
        let h = self.params.homing;
        SearchProfile {
            fast: speed(1),
            creep: speed(2),
            acceleration: self.time_constant_rate(value(HOMING_ACCELERATION, 0)),
            emergency_deceleration: self.params.plant.max_acceleration.abs(),
            shift: shift as f64,
            travel: f64::from(h.travel_after_dog),
            stopper_time: f64::from(h.stopper_time_ms) / 1e3,
        }
    }

    /// The torque limits (% rated; positive, negative) while a search runs: the stopper type
    /// −4/−36 limits the search direction's (60E0h for −4, 60E1h for −36) to at most
    /// [Pr. PT11] (MR-J4-TM manual §5.4.9(6)(d), [`crate::sim::drive::HomingParams`]).
    pub(super) fn homing_torque_limits(&self, (pos, neg): (f64, f64)) -> (f64, f64) {
        let Some(recipe) = self
            .homing
            .search
            .map(|s| s.recipe())
            .filter(|r| r.target == SearchTarget::Stopper)
        else {
            return (pos, neg);
        };
        let pt11 = self.params.homing.stopper_torque_limit;
        if recipe.direction > 0 {
            (pos.min(pt11), neg)
        } else {
            (pos, neg.min(pt11))
        }
    }

    /// hm in Operation enabled: the search's generator drives the plant like pv; at its end
    /// home is set on the Z phase (+ shift) or the homing error and the model's warning come.
    /// True while a search owns the motion.
    pub(super) fn follow_homing_search(&mut self, dt: f64) -> bool {
        if let Some((target, home)) = self.homing.settling {
            self.settle_homing(target, home, dt);
            return true;
        }
        let Some(mut search) = self.homing.search else {
            return false;
        };
        let z = ZPulses {
            counts_per_rev: self.motor_resolution(),
            position: f64::from(self.params.z_phase_position),
        };
        // Standing at the torque limit (S_TLC at the encoder's standstill): against a stopper.
        let pressing = (self.plant.at_torque_limit() && self.plant.velocity().abs() < 1.0)
            .then(|| self.plant.position());
        let (pos, vel, end) = search.step(&self.params.homing_switches, z, pressing, dt);
        self.homing.search = Some(search);
        self.homing.error |= search.failing() && !self.homing.interrupted;
        self.demand = pos;
        self.plant.step(self.demand, vel, dt);
        let settle = match end {
            Some(SearchEnd::Home(raw)) => Some((raw, true)),
            Some(SearchEnd::Failed) => Some((pos, false)),
            None => None,
        };
        if settle.is_some() {
            self.homing.search = None;
            self.homing.settling = settle;
        }
        true
    }

    /// After the generator: the motor settles on `target` within the in-position range and
    /// below one count/s (the encoder's standstill), then home is set (`home`) or the failed
    /// search reports its warning.
    fn settle_homing(&mut self, target: f64, home: bool, dt: f64) {
        self.demand = target;
        self.plant.step(target, 0.0, dt);
        let in_position =
            (self.plant.position() - target).abs() <= f64::from(self.params.in_position_range);
        if !(in_position && self.plant.velocity().abs() < 1.0) {
            return;
        }
        // At rest where it stands (within the in-position range): no residual creep.
        self.plant.come_to_rest();
        self.demand = self.plant.position();
        self.plant.set_last_command(self.demand);
        self.homing.settling = None;
        if home {
            self.set_home(target);
        } else if !self.homing.interrupted {
            self.homing.error = true;
            self.homing.warning = homing_model(self.profile.model).warning;
        }
    }

    /// 60FDh Digital inputs at the motor's position (`sim::homing_switches`).
    pub fn digital_inputs(&self) -> u32 {
        self.params
            .homing_switches
            .digital_inputs(self.plant.position())
    }

    /// Statusword bits 13 / 12 / 10 in hm (MR-J4-TM manual §5.4.9, MR-J3-T04 manual §8.5.2):
    /// in progress 0/0/0, not started 0/0/1, attained 0/1/1, error 1/0/0 while moving, 1/0/1
    /// at rest.
    pub(super) fn homing_status_bits(&self) -> u16 {
        let at_rest =
            self.homing.search.is_none() && self.homing.settling.is_none() && self.stopped();
        (u16::from(self.homing.error) << 13)
            | (u16::from(self.homing.attained && !self.homing.error) << 12)
            | (u16::from(at_rest) << 10)
    }

    /// Controlword2 home setting and the Z phase, on models that have them (MR-J3-T04 §8.3).
    pub(super) fn run_home_setting(&mut self, cmd: &RxPdo) {
        let Some(bits) = self.profile.homing.setting else {
            return;
        };
        let raw = self.plant.position().round() as i64;
        if let Some(cpr) = self.profile.units.counts_per_rev {
            let z = ZPhase {
                counts_per_rev: i64::from(cpr),
                position: i64::from(self.params.z_phase_position),
            };
            self.home_set.track_encoder(raw, z);
        }
        let cyclic_position_or_velocity = matches!(
            self.mode_display,
            ModeOfOperation::CyclicSyncPosition | ModeOfOperation::CyclicSyncVelocity
        );
        if !(self.op && cyclic_position_or_velocity) {
            self.home_set.ignore(cmd.controlword2, &bits);
            return;
        }
        let position = self.position_actual();
        match self.home_set.controlword2(
            cmd.controlword2,
            &bits,
            position,
            self.params.before_z_reaction,
        ) {
            Some(HomeSettingOutcome::HomeOffset(v)) => {
                self.homing.home_offset = v;
                // PD22 note: the CR rising edge also clears the droop pulses.
                self.demand = self.plant.position();
            }
            Some(HomeSettingOutcome::Alarm(code)) => self.raise(code),
            None => {}
        }
    }

    /// 607Ch Home offset.
    pub fn home_offset(&self) -> i32 {
        self.homing.home_offset
    }
}
