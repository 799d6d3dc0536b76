//! Master-side change of the mode of operation (6060h), cycle by cycle and allocation-free.
//!
//! The rules it follows (MR-J5-G-N1 manual §7.4, MR-JET-G-N1 manual §7.4, MR-J4-TM manual §5.4.2):
//!
//! 1. Switches into or out of a position mode, and between a cyclic and a profile mode, happen
//!    only at zero speed (S_ZSP; otherwise the drive keeps 6061h). The procedure does not
//!    request such a switch before |606Ch| ≤ [`ModeSwitchParams::zero_speed`], so the csp target
//!    it computes is not stale by the time the drive switches.
//! 2. Entering **csp**: 607Ah is set to 6064h − 60B0h (MR-J5 TV-10: "607Ah + 60B0h follow
//!    6064h"; MR-JET TV-7 uses 60B0h = 0, 607Ah = 6064h) at least one cycle **before** 6060h = 8
//!    is written, and kept following 6064h until 6061h = 8, so the motor does not jump. The
//!    MR-J3-T04 takes 607Ah = 6062h instead, and the switch waits until 6062h has stopped
//!    changing ([`CspEntry::PositionDemand`], MR-J3-T04 manual §8.4.2 ① and Note 1).
//! 3. The old mode's commands are kept until 6061h shows the new mode: the caller fills the
//!    RxPDO as for the old mode every cycle and [`ModeSwitch::update`] overrides only 6060h, 607Ah
//!    (csp) and controlword bit 4, which it holds at 0 ("switch only while the start command is
//!    off", MR-JET-G-N1 manual §7.4 rule 2; OMS bits are ignored until the switch has finished).
//! 4. A switch that 6061h has not confirmed within [`ModeSwitchParams::timeout`] cycles fails
//!    with [`ModeSwitchError::Timeout`] and the request is withdrawn (6060h = the old mode); a
//!    fault (statusword bit 3) fails it at once.
//!
//! Not covered: MR-JET's "switch to a profile mode with the servo off" (§4.3 rule 1) is left to
//! the caller; PC76.1 (zero-speed check disabled) is a drive parameter the master cannot see.

use super::mode::ModeOfOperation;
use crate::cycles::Cycles;
use crate::pdo::objects::POSITION_DEMAND;
use crate::pdo::{RxPdo, TxPdo};

/// Controlword bit 4: new set-point (pp) / homing start (hm); held at 0 during a switch.
const START_BIT: u16 = 1 << 4;

/// True if a switch between `from` and `to` waits for zero speed (S_ZSP): a position mode on
/// either side, or cyclic ↔ profile (MR-J5-G-N1 manual §7.4 rules 4–5, MR-JET-G-N1 manual §7.4 rule 5,
/// MR-J4-TM manual §5.4.2).
pub const fn switch_needs_zero_speed(from: ModeOfOperation, to: ModeOfOperation) -> bool {
    from.is_position() || to.is_position() || from.is_cyclic() != to.is_cyclic()
}

/// Where 607Ah comes from while a drive enters csp: a drive fact (`CycleFacts::csp_entry`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CspEntry {
    /// 607Ah = 6064h − 60B0h, following 6064h until 6061h = 8 (MR-J5-G-N1 TV-10, MR-JET-G-N1
    /// TV-7, MR-J4-TM manual §5.4.2).
    ActualPosition,
    /// 607Ah = 6062h Position demand value, and 6060h = 8 only once 6062h has stopped changing
    /// and the motor has stopped (MR-J3-T04 manual §8.4.2 ① "set the position demand value to
    /// position command" and Note 1; TV-MODE-1). The TxPDO must carry 6062h.
    PositionDemand,
}

/// Configuration of a [`ModeSwitch`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ModeSwitchParams {
    /// Cycles, from the first [`ModeSwitch::update`], within which 6061h must show the new mode
    /// (the drives state a switching delay but no figure, so a named parameter). At least 1.
    pub timeout: Cycles,
    /// |606Ch| (drive velocity units) at or below which the master treats the motor as stopped
    /// before requesting a gated switch. Keep it at or below the drive's zero speed [Pr. PC07].
    pub zero_speed: u32,
}

impl Default for ModeSwitchParams {
    /// 1000 cycles, zero speed 0.
    fn default() -> Self {
        ModeSwitchParams {
            timeout: Cycles(1000),
            zero_speed: 0,
        }
    }
}

/// Why a mode switch could not be started or did not finish.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum ModeSwitchError {
    /// The drive profile does not list the requested mode.
    #[error("the drive does not support mode {to} (6060h = {})", to.as_i8())]
    Unsupported {
        /// The requested mode.
        to: ModeOfOperation,
    },
    /// [`ModeSwitchParams::timeout`] is 0.
    #[error("mode switch timeout must be at least one cycle")]
    ZeroTimeout,
    /// 6061h did not show the new mode in time; the request has been withdrawn.
    #[error(
        "mode switch to {to} not confirmed within {cycles} cycles (6061h = {display}, {phase:?})"
    )]
    Timeout {
        /// The requested mode.
        to: ModeOfOperation,
        /// 6061h at the timeout.
        display: i8,
        /// Cycles waited.
        cycles: u32,
        /// Where the procedure was waiting.
        phase: ModeSwitchPhase,
    },
    /// The drive reported a fault (statusword bit 3) during the switch.
    #[error("drive fault during the mode switch to {to}")]
    Fault {
        /// The requested mode.
        to: ModeOfOperation,
    },
    /// The drive enters csp from 6062h ([`CspEntry::PositionDemand`]) but the TxPDO does not
    /// carry 6062h; the request has been withdrawn.
    #[error("entering csp on this drive takes 607Ah from 6062h (position demand value), which the TxPDO does not carry: map 6062h (MR-J3-T04 manual §8.4.2)")]
    PositionDemandNotMapped,
}

/// Where a [`ModeSwitch`] is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModeSwitchPhase {
    /// Waiting for |606Ch| ≤ zero speed (gated switches only); 6060h = old mode.
    WaitZeroSpeed,
    /// 607Ah set for csp, 6060h still the old mode (one cycle).
    Prepare,
    /// 6060h = new mode, waiting for 6061h.
    Requested,
    /// 6061h shows the new mode.
    Done,
    /// Failed (timeout or fault); 6060h = old mode.
    Failed,
}

/// The outcome of one [`ModeSwitch::update`] that did not fail.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModeSwitchProgress {
    /// Still switching; keep calling `update` every cycle with the old mode's commands.
    Pending(ModeSwitchPhase),
    /// 6061h shows the new mode. For csp, `csp_target` is the 607Ah the drive took over: the
    /// caller's csp setpoints continue from it.
    Done {
        /// The csp target handed over (csp only).
        csp_target: Option<i32>,
    },
}

/// A mode change in progress for one axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ModeSwitch {
    to: ModeOfOperation,
    /// 6061h at the first update (the old mode); `None` until then or if not a known mode.
    from: Option<i8>,
    position_offset: i32,
    params: ModeSwitchParams,
    phase: ModeSwitchPhase,
    elapsed: u32,
    csp_target: i32,
    csp_entry: CspEntry,
    /// 6062h of the previous cycle ([`CspEntry::PositionDemand`]).
    last_demand: Option<i32>,
    failure: Option<ModeSwitchError>,
}

impl ModeSwitch {
    /// A switch to `to`. `position_offset` is the 60B0h the drive holds (0 where it is not used).
    pub fn new(
        to: ModeOfOperation,
        position_offset: i32,
        params: ModeSwitchParams,
    ) -> Result<Self, ModeSwitchError> {
        if params.timeout.0 == 0 {
            return Err(ModeSwitchError::ZeroTimeout);
        }
        Ok(ModeSwitch {
            to,
            from: None,
            position_offset,
            params,
            phase: ModeSwitchPhase::WaitZeroSpeed,
            elapsed: 0,
            csp_target: 0,
            csp_entry: CspEntry::ActualPosition,
            last_demand: None,
            failure: None,
        })
    }

    /// This switch with 607Ah taken as `entry` says when entering csp (the default is
    /// [`CspEntry::ActualPosition`]; `ModeSwitch::for_profile` takes the drive's).
    pub fn with_csp_entry(mut self, entry: CspEntry) -> Self {
        self.csp_entry = entry;
        self
    }

    /// [`ModeSwitch::new`], refusing a mode not in `supported` (the modes the drive accepts in
    /// 6060h; `ModeSwitch::for_profile` takes them from a drive profile).
    pub fn for_modes(
        supported: &[ModeOfOperation],
        to: ModeOfOperation,
        position_offset: i32,
        params: ModeSwitchParams,
    ) -> Result<Self, ModeSwitchError> {
        if !supported.contains(&to) {
            return Err(ModeSwitchError::Unsupported { to });
        }
        Self::new(to, position_offset, params)
    }

    /// The requested mode.
    pub fn target_mode(&self) -> ModeOfOperation {
        self.to
    }

    /// The current phase.
    pub fn phase(&self) -> ModeSwitchPhase {
        self.phase
    }

    /// One cycle: `tx` is the drive's last TxPDO, `rx` the RxPDO the caller has filled with the
    /// old mode's commands; 6060h, 607Ah (entering csp) and controlword bit 4 are overridden.
    pub fn update(
        &mut self,
        tx: &TxPdo,
        rx: &mut RxPdo,
    ) -> Result<ModeSwitchProgress, ModeSwitchError> {
        let from = *self.from.get_or_insert(tx.mode_display);
        match self.phase {
            ModeSwitchPhase::Failed => {
                rx.mode = from;
                return Err(self.failure.unwrap_or(self.timeout_error(tx)));
            }
            ModeSwitchPhase::Done => return Ok(self.done(rx)),
            _ => {}
        }
        if tx.mode_display == self.to.as_i8() {
            self.phase = ModeSwitchPhase::Done;
            return Ok(self.done(rx));
        }
        if tx.statusword.fault() {
            return Err(self.fail(ModeSwitchError::Fault { to: self.to }, from, rx));
        }
        self.elapsed = self.elapsed.saturating_add(1);
        if self.elapsed > self.params.timeout.0 {
            return Err(self.fail(self.timeout_error(tx), from, rx));
        }
        rx.controlword.0 &= !START_BIT;
        let entering_csp = self.to == ModeOfOperation::CyclicSyncPosition;
        let demand = match (entering_csp, self.csp_entry) {
            (true, CspEntry::PositionDemand) => match tx.extra(POSITION_DEMAND) {
                Some(raw) => Some(raw as u32 as i32),
                None => return Err(self.fail(ModeSwitchError::PositionDemandNotMapped, from, rx)),
            },
            _ => None,
        };
        if self.phase == ModeSwitchPhase::WaitZeroSpeed {
            let gated = demand.is_some()
                || ModeOfOperation::from_i8(from)
                    .is_none_or(|f| switch_needs_zero_speed(f, self.to));
            let settled = demand.is_none() || demand == self.last_demand;
            self.last_demand = demand;
            if gated && (tx.velocity_actual.unsigned_abs() > self.params.zero_speed || !settled) {
                rx.mode = from;
                if let Some(d) = demand {
                    rx.target_position = d;
                }
                return Ok(ModeSwitchProgress::Pending(self.phase));
            }
            self.phase = ModeSwitchPhase::Prepare;
        }
        if entering_csp {
            // 607Ah + 60B0h = 6064h (or 607Ah = 6062h), recomputed until the drive takes it.
            self.csp_target =
                demand.unwrap_or(tx.position_actual.wrapping_sub(self.position_offset));
            rx.target_position = self.csp_target;
        }
        if self.phase == ModeSwitchPhase::Prepare {
            rx.mode = from;
            self.phase = ModeSwitchPhase::Requested;
            return Ok(ModeSwitchProgress::Pending(ModeSwitchPhase::Prepare));
        }
        rx.mode = self.to.as_i8();
        Ok(ModeSwitchProgress::Pending(self.phase))
    }

    /// Ends the switch with `e`, the request withdrawn (6060h = the old mode `from`).
    fn fail(&mut self, e: ModeSwitchError, from: i8, rx: &mut RxPdo) -> ModeSwitchError {
        self.failure = Some(e);
        self.phase = ModeSwitchPhase::Failed;
        rx.mode = from;
        e
    }

    fn done(&self, rx: &mut RxPdo) -> ModeSwitchProgress {
        rx.mode = self.to.as_i8();
        if self.to == ModeOfOperation::CyclicSyncPosition {
            rx.target_position = self.csp_target;
            ModeSwitchProgress::Done {
                csp_target: Some(self.csp_target),
            }
        } else {
            ModeSwitchProgress::Done { csp_target: None }
        }
    }

    fn timeout_error(&self, tx: &TxPdo) -> ModeSwitchError {
        ModeSwitchError::Timeout {
            to: self.to,
            display: tx.mode_display,
            cycles: self.elapsed,
            phase: self.phase,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::statusword::Statusword;

    fn tx(mode: i8, pos: i32, vel: i32) -> TxPdo {
        TxPdo {
            mode_display: mode,
            statusword: Statusword(0x0237),
            position_actual: pos,
            velocity_actual: vel,
            ..TxPdo::default()
        }
    }

    #[test]
    fn csp_target_is_set_a_cycle_before_6060h() {
        let mut s = ModeSwitch::new(
            ModeOfOperation::CyclicSyncPosition,
            300,
            ModeSwitchParams::default(),
        )
        .unwrap();
        let mut rx = RxPdo {
            mode: 1,
            controlword: crate::Controlword(0x1F),
            target_position: 99_999,
            ..RxPdo::default()
        };
        let p = s.update(&tx(1, 1_000, 0), &mut rx).unwrap();
        assert_eq!(p, ModeSwitchProgress::Pending(ModeSwitchPhase::Prepare));
        assert_eq!((rx.mode, rx.target_position), (1, 700));
        assert_eq!(rx.controlword.0 & START_BIT, 0);
        s.update(&tx(1, 1_000, 0), &mut rx).unwrap();
        assert_eq!((rx.mode, rx.target_position), (8, 700));
        let p = s.update(&tx(8, 1_001, 0), &mut rx).unwrap();
        assert_eq!(
            p,
            ModeSwitchProgress::Done {
                csp_target: Some(700)
            }
        );
    }

    #[test]
    fn position_demand_entry_sends_6062h_and_waits_for_it_to_stand() {
        let mut s = ModeSwitch::new(
            ModeOfOperation::CyclicSyncPosition,
            0,
            ModeSwitchParams::default(),
        )
        .unwrap()
        .with_csp_entry(CspEntry::PositionDemand);
        let with_demand = |demand: i32| {
            let mut t = tx(9, 1_000, 0);
            t.extras
                .set(POSITION_DEMAND, 0, u64::from(demand as u32))
                .unwrap();
            t
        };
        let mut rx = RxPdo {
            mode: 9,
            ..RxPdo::default()
        };
        // 6062h still moving: 607Ah = 6062h, 6060h stays csv.
        for demand in [-500, -400, -300] {
            let p = s.update(&with_demand(demand), &mut rx).unwrap();
            assert_eq!(
                p,
                ModeSwitchProgress::Pending(ModeSwitchPhase::WaitZeroSpeed)
            );
            assert_eq!((rx.mode, rx.target_position), (9, demand));
        }
        // Unchanged for a cycle: prepared with 607Ah = 6062h (not 6064h = 1000), then requested.
        s.update(&with_demand(-300), &mut rx).unwrap();
        assert_eq!((rx.mode, rx.target_position), (9, -300));
        s.update(&with_demand(-300), &mut rx).unwrap();
        assert_eq!((rx.mode, rx.target_position), (8, -300));
        let mut done = with_demand(-300);
        done.mode_display = 8;
        assert_eq!(
            s.update(&done, &mut rx).unwrap(),
            ModeSwitchProgress::Done {
                csp_target: Some(-300)
            }
        );
    }

    #[test]
    fn waits_for_zero_speed_and_times_out() {
        let params = ModeSwitchParams {
            timeout: Cycles(5),
            zero_speed: 10,
        };
        let mut s = ModeSwitch::new(ModeOfOperation::CyclicSyncPosition, 0, params).unwrap();
        let mut rx = RxPdo::default();
        for _ in 0..5 {
            let p = s.update(&tx(1, 0, 500), &mut rx).unwrap();
            assert_eq!(
                p,
                ModeSwitchProgress::Pending(ModeSwitchPhase::WaitZeroSpeed)
            );
            assert_eq!(rx.mode, 1);
        }
        let e = s.update(&tx(1, 0, 500), &mut rx).unwrap_err();
        assert!(
            matches!(e, ModeSwitchError::Timeout { cycles: 6, .. }),
            "{e}"
        );
        assert_eq!(rx.mode, 1, "request withdrawn");
        assert!(e.to_string().contains("not confirmed"));
        assert_eq!(
            ModeSwitch::new(
                ModeOfOperation::CyclicSyncPosition,
                0,
                ModeSwitchParams {
                    timeout: Cycles(0),
                    zero_speed: 0
                }
            ),
            Err(ModeSwitchError::ZeroTimeout)
        );
    }

    #[test]
    fn velocity_modes_switch_without_the_gate() {
        assert!(!switch_needs_zero_speed(
            ModeOfOperation::CyclicSyncVelocity,
            ModeOfOperation::CyclicSyncTorque
        ));
        assert!(switch_needs_zero_speed(
            ModeOfOperation::CyclicSyncVelocity,
            ModeOfOperation::ProfileVelocity
        ));
        let mut s = ModeSwitch::new(
            ModeOfOperation::CyclicSyncTorque,
            0,
            ModeSwitchParams::default(),
        )
        .unwrap();
        let mut rx = RxPdo::default();
        s.update(&tx(9, 0, 5_000), &mut rx).unwrap();
        s.update(&tx(9, 0, 5_000), &mut rx).unwrap();
        assert_eq!(rx.mode, 10, "csv → cst is requested while moving");
    }
}
