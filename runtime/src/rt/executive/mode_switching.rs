//! Run-time switch of a csp axis to pp and back (`ProfileMotion::SwitchMode`), by the drive's
//! mode-switch rules (`cellrt_cia402::mode_switch`; MR-J5-G-N1 manual §7.4, MR-JET-G-N1
//! manual §7.4, MR-J4-TM manual §5.4.2): requested at zero speed with controlword bit 4 low,
//! entering csp with 607Ah = 6064h a cycle before 6060h = 8, confirmed by 6061h, withdrawn
//! after [`MODE_SWITCH_TIMEOUT`] or at a fault. The axis holds meanwhile and no motion starts.
//! Allocation-free: the switch and the profile channel it builds are plain copies.

use std::sync::atomic::Ordering;
use std::time::Duration;

use cellrt_cia402::bus::{AcyclicBus, CyclicBus};
use cellrt_cia402::mode_switch::{
    ModeSwitch, ModeSwitchError, ModeSwitchParams, ModeSwitchProgress,
};
use cellrt_cia402::pdo::RxPdo;

use super::profile_axis::ProfileChannel;
use super::Executive;
use crate::handoff::{CellState, EventKind, SwitchableMode};

/// How long 6061h may take to show the new mode (the drives state a switching delay but no
/// figure; MR-J5-G-N1 manual §7.4): a named choice, far above a drive's few cycles.
pub const MODE_SWITCH_TIMEOUT: Duration = Duration::from_secs(1);

/// The master requests a switch once |606Ch| is at most this share of the axis' velocity limit:
/// below the drives' own zero-speed gate ([Pr. PC07], 50 r/min by default) for any limit up to
/// 5000 r/min, and above a real drive's standstill noise.
pub const ZERO_SPEED_SHARE: f64 = 0.01;

/// [`EventKind::ModeSwitchFailed`] values.
const FAILED_TIMEOUT: i64 = 1;
const FAILED_FAULT: i64 = 2;

impl<B: CyclicBus + AcyclicBus> Executive<B> {
    /// Starts switching axis `i` to `to`; false (refused) unless the cell is idle, the axis is
    /// powered and enabled with no motion of its own, can switch (a csp axis whose drive runs
    /// pp, `config::profile_axis::pp_switch`) and is in the other mode.
    pub(super) fn start_mode_switch(&mut self, i: usize, to: SwitchableMode) -> bool {
        let idle = self.state == CellState::Idle
            && self.profile_pending.get(i).is_some_and(Option::is_none);
        let timeout = (MODE_SWITCH_TIMEOUT.as_nanos() / u128::from(self.period_ns.max(1))).max(1);
        let Some(ch) = self.axes.get_mut(i) else {
            return false;
        };
        let in_pp = ch.switched_to_pp();
        let ready = idle
            && ch.powered
            && ch.master.is_enabled()
            && ch.pp_switch.is_some()
            && ch.mode_switch.is_none()
            && !ch.homing.is_active()
            && ch.profile.as_ref().is_none_or(|p| !p.busy())
            && in_pp == (to == SwitchableMode::Csp);
        if !ready {
            return false;
        }
        let zero_speed = ch
            .drive_units
            .velocity_to_drive(ch.limits.velocity * ZERO_SPEED_SHARE)
            .map_or(0, |v| v.unsigned_abs());
        let params = ModeSwitchParams {
            timeout: cellrt_cia402::Cycles(u32::try_from(timeout).unwrap_or(u32::MAX)),
            zero_speed,
        };
        // 60B0h: the master leaves the drive's 0 (no RxPDO carries it).
        match ModeSwitch::new(to.mode(), 0, params) {
            Ok(s) => {
                ch.mode_switch = Some(s);
                true
            }
            Err(_) => false,
        }
    }

    /// True while an axis switches its mode (no motion or homing starts).
    pub(super) fn mode_switching(&self) -> bool {
        self.axes.iter().any(|ch| ch.mode_switch.is_some())
    }

    /// One cycle of axis `i`'s switch over `rx`, filled for the old mode: 6060h, 607Ah and
    /// controlword bit 4 as the switch needs them; at its end the axis runs in the new mode (a
    /// pp axis gets its profile channel, a csp axis its setpoint where the drive took 607Ah).
    pub(super) fn mode_switch_outputs(&mut self, i: usize, rx: &mut RxPdo) {
        let feed = f64::from(self.feed_permille) / 1000.0;
        let ch = &mut self.axes[i];
        if ch.mode_switch.is_none() {
            return;
        }
        // The switch works in the drive's coordinates (607Ah, 6064h raw).
        let mut tx = ch.feedback;
        tx.position_actual = ch.to_raw(tx.position_actual);
        let Some(switch) = ch.mode_switch.as_mut() else {
            return;
        };
        let outcome = switch.update(&tx, rx);
        let to = switch.target_mode();
        match outcome {
            Ok(ModeSwitchProgress::Pending(_)) => {}
            Ok(ModeSwitchProgress::Done { csp_target }) => {
                ch.mode_switch = None;
                ch.mode = to;
                match (csp_target, ch.pp_switch) {
                    (Some(target), _) => {
                        ch.profile = None;
                        ch.track_actual();
                        ch.setpoint = f64::from(ch.to_user(target));
                    }
                    (None, Some((objects, rated_speed))) => {
                        let mut p = ProfileChannel::new(objects, rated_speed, tx.position_actual);
                        p.set_feed(feed);
                        ch.profile = Some(p);
                    }
                    (None, None) => {}
                }
                if let Some(live) = self.handoff.status().live.get(i) {
                    live.mode.store(to.as_i8(), Ordering::Release);
                }
                self.event(EventKind::ModeSwitched, i as u16, i64::from(to.as_i8()));
                self.profile_finished(i, super::profile_commands::FINISHED_DONE);
            }
            Err(e) => {
                ch.mode_switch = None;
                let value = match e {
                    ModeSwitchError::Fault { .. } => FAILED_FAULT,
                    _ => FAILED_TIMEOUT,
                };
                self.event(EventKind::ModeSwitchFailed, i as u16, value);
                self.profile_finished(i, super::profile_commands::FINISHED_REFUSED);
            }
        }
    }
}
