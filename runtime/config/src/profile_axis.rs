//! Profile axes: an axis whose `mode` is pp, pv or tq moves by the drive's own profile
//! (MR-J4-TM manual §5.4.6–§5.4.8) instead of streamed setpoints. What such an axis needs in
//! its RxPDO, and which of its profile objects go by SDO instead, decided once at load from
//! the axis' PDO map.

use cellrt_cia402::mode::ModeOfOperation;
use cellrt_cia402::pdo::objects::{
    PROFILE_ACCELERATION, PROFILE_DECELERATION, PROFILE_VELOCITY, TARGET_POSITION, TARGET_TORQUE,
    TARGET_VELOCITY, TORQUE_SLOPE,
};
use cellrt_cia402::profiles::DriveProfile;
use cellrt_cia402::PdoMap;

/// The drive-side modes an axis may run in (`mode = "pp" | "pv" | "tq"`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ProfileMode {
    /// Profile position: the drive positions to 607Ah with 6081h/6083h/6084h.
    Position,
    /// Profile velocity: the drive ramps to 60FFh with 6083h/6084h.
    Velocity,
    /// Profile torque: the drive ramps to 6071h at 6087h.
    Torque,
}

impl ProfileMode {
    /// The profile mode of `mode`, `None` for the cyclic and homing modes.
    pub const fn of(mode: ModeOfOperation) -> Option<ProfileMode> {
        match mode {
            ModeOfOperation::ProfilePosition => Some(ProfileMode::Position),
            ModeOfOperation::ProfileVelocity => Some(ProfileMode::Velocity),
            ModeOfOperation::ProfileTorque => Some(ProfileMode::Torque),
            _ => None,
        }
    }

    /// The mode of operation (6060h).
    pub const fn mode(self) -> ModeOfOperation {
        match self {
            ProfileMode::Position => ModeOfOperation::ProfilePosition,
            ProfileMode::Velocity => ModeOfOperation::ProfileVelocity,
            ProfileMode::Torque => ModeOfOperation::ProfileTorque,
        }
    }

    /// The target object the RxPDO must carry: the MR-JET-G-N1 manual §4.5 marks it "mapping
    /// required" (⊙) per mode (607Ah pp, 60FFh pv, 6071h tq).
    pub const fn target(self) -> u16 {
        match self {
            ProfileMode::Position => TARGET_POSITION,
            ProfileMode::Velocity => TARGET_VELOCITY,
            ProfileMode::Torque => TARGET_TORQUE,
        }
    }

    /// The profile objects of the mode the manual marks "recommended" (○) for the RxPDO
    /// (MR-JET-G-N1 manual §4.5; the MR-J4-TM 1601h carries them all, MR-J4-TM manual §3.3).
    pub const fn profile_objects(self) -> &'static [u16] {
        match self {
            ProfileMode::Position => {
                &[PROFILE_VELOCITY, PROFILE_ACCELERATION, PROFILE_DECELERATION]
            }
            ProfileMode::Velocity => &[PROFILE_ACCELERATION, PROFILE_DECELERATION],
            ProfileMode::Torque => &[TORQUE_SLOPE],
        }
    }
}

/// Where a profile axis' objects travel: the mode's profile objects in its RxPDO are written
/// every cycle, the others once by SDO before a motion that changes them (the drive keeps an
/// SDO-written value: CiA 402 [background]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ProfileObjects {
    /// The axis' mode.
    pub mode: ProfileMode,
    /// Bit i set: `mode.profile_objects()[i]` is in the RxPDO.
    mapped: u8,
}

impl ProfileObjects {
    /// The plan for `mode` over the RxPDO map `rx`.
    pub fn new(mode: ProfileMode, rx: &PdoMap) -> ProfileObjects {
        let mapped = mode
            .profile_objects()
            .iter()
            .enumerate()
            .filter(|(_, index)| rx.maps(**index))
            .fold(0u8, |bits, (i, _)| bits | 1 << i);
        ProfileObjects { mode, mapped }
    }

    /// The plan for `mode` on `profile`'s RxPDO.
    pub fn of_profile(mode: ProfileMode, profile: &DriveProfile) -> ProfileObjects {
        ProfileObjects::new(mode, &profile.pdo.rx)
    }

    /// Whether `index` (one of the mode's profile objects) is in the RxPDO.
    pub fn is_cyclic(&self, index: u16) -> bool {
        self.mode
            .profile_objects()
            .iter()
            .position(|i| *i == index)
            .is_some_and(|i| self.mapped & (1 << i) != 0)
    }

    /// The mode's profile objects written by SDO, in the manual's order.
    pub fn by_sdo(&self) -> impl Iterator<Item = u16> + '_ {
        self.mode
            .profile_objects()
            .iter()
            .copied()
            .filter(|i| !self.is_cyclic(*i))
    }
}

/// Why a csp axis cannot be switched to pp at run time.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PpSwitchError {
    /// The axis does not run csp.
    #[error("axis '{axis}' runs in {mode}: only a csp axis switches to pp and back")]
    NotCsp {
        /// The axis.
        axis: String,
        /// Its mode.
        mode: &'static str,
    },
    /// The drive's profile has no pp.
    #[error("axis '{axis}': the {drive} does not support pp (its modes: {modes})")]
    NoPp {
        /// The axis.
        axis: String,
        /// Its drive.
        drive: &'static str,
        /// The modes its profile lists.
        modes: String,
    },
    /// The drive's PDOs do not map 6060h and 6061h.
    #[error("axis '{axis}': the {drive}'s PDOs do not carry 6060h and 6061h, which a run-time mode switch writes and follows")]
    NoModeObjects {
        /// The axis.
        axis: String,
        /// Its drive.
        drive: &'static str,
    },
    /// pp's ramps are time constants and `motor.rated_speed` is not given.
    #[error("axis '{axis}': pp needs motor.rated_speed (the drive's 6083h/6084h are time constants from 0 to the rated speed)")]
    NoRatedSpeed {
        /// The axis.
        axis: String,
    },
}

/// The profile-position plan of a csp axis that can be switched to pp at run time (and back),
/// or why it cannot: the drive's profile lists pp, its PDOs carry 6060h and 6061h (the
/// mode-switch rules follow 6061h, `cellrt_cia402::mode_switch`), and pp's time-constant
/// ramps have `motor.rated_speed` to run from where the drive needs it.
pub fn pp_switch(a: &super::AxisConfig) -> Result<ProfileObjects, PpSwitchError> {
    use cellrt_cia402::pdo::objects::{MODES_OF_OPERATION, MODES_OF_OPERATION_DISPLAY};
    let axis = || a.name.clone();
    if a.mode != ModeOfOperation::CyclicSyncPosition {
        return Err(PpSwitchError::NotCsp {
            axis: axis(),
            mode: a.mode.as_str(),
        });
    }
    if !a.profile.supports_mode(ModeOfOperation::ProfilePosition) {
        return Err(PpSwitchError::NoPp {
            axis: axis(),
            drive: a.drive.as_str(),
            modes: a.profile.modes_text(),
        });
    }
    if !(a.profile.pdo.rx.maps(MODES_OF_OPERATION)
        && a.profile.pdo.tx.maps(MODES_OF_OPERATION_DISPLAY))
    {
        return Err(PpSwitchError::NoModeObjects {
            axis: axis(),
            drive: a.drive.as_str(),
        });
    }
    let time_constants = a.profile.units.acceleration.value()
        == cellrt_cia402::profiles::AccelerationUnit::TimeConstantMs;
    if time_constants && a.rated_speed.is_none() {
        return Err(PpSwitchError::NoRatedSpeed { axis: axis() });
    }
    Ok(ProfileObjects::of_profile(
        ProfileMode::Position,
        &a.profile,
    ))
}

/// `motor.rated_speed` of a profile axis as counts/s: required where the mode ramps on the
/// drive's acceleration objects (pp, pv) and they are time constants to the rated speed
/// (MR-J4-TM manual §4.2; assumed on MR-JET / MR-J5, see "Units"); `scaling` gives the motor.
pub(super) fn rated_speed(
    mode: Option<ProfileMode>,
    profile: &DriveProfile,
    rated: Option<f64>,
    scaling: &cellrt_cia402::drive_scaling::DriveScaling,
) -> Result<Option<f64>, (&'static str, String)> {
    use cellrt_cia402::profiles::AccelerationUnit;
    const KEY: &str = "motor.rated_speed";
    let ramps = matches!(mode, Some(ProfileMode::Position | ProfileMode::Velocity));
    let time_constants = profile.units.acceleration.value() == AccelerationUnit::TimeConstantMs;
    let Some(speed) = rated else {
        return if ramps && time_constants {
            Err((
                KEY,
                "is required for a pp or pv axis: the drive's 6083h/6084h are time constants \
                 from 0 to the rated speed (r/min, or mm/s for a linear motor)"
                    .into(),
            ))
        } else {
            Ok(None)
        };
    };
    let speed = crate::plausible::MOTOR_SPEED
        .check(speed)
        .map_err(|m| (KEY, m))?;
    match scaling.counts_per_s(speed) {
        Some(c) => Ok(Some(c)),
        None => Err((
            KEY,
            "needs the motor's resolution (motor.counts_per_rev or counts_per_mm)".into(),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cellrt_cia402::profiles::{mr_j4_tm, profile, DriveModel};

    fn by_sdo(p: &ProfileObjects) -> Vec<u16> {
        p.by_sdo().collect()
    }

    /// A one-axis cell of `drive` with `extra` lines in the axis table, rated speed 3000 r/min.
    fn cell(drive: &str, extra: &str) -> Result<crate::CellConfig, crate::ConfigError> {
        cell_with_motor(drive, "counts_per_rev = 10000, rated_speed = 3000", extra)
    }

    fn cell_with_motor(
        drive: &str,
        motor: &str,
        extra: &str,
    ) -> Result<crate::CellConfig, crate::ConfigError> {
        let text = format!(
            r#"
[cell]
name = "p"
cycle_time_us = 1000
[recording]
path = "r.mcap"
[[axes]]
name = "x"
drive = "{drive}"
motor = {{ {motor} }}
unit = "mm"
counts_per_unit = 1000
limits = {{ position = [0.0, 100.0], velocity = 100.0, acceleration = 1000.0, jerk = 10000.0 }}
{extra}
"#
        );
        crate::CellConfig::parse(std::path::Path::new("cell.toml"), &text)
    }

    #[test]
    fn profile_modes_load_where_the_model_and_its_mode_group_have_them() {
        for (drive, group) in [
            ("mr-j4-tm", "mode_group = \"profile\""),
            ("mr-jet-g-n1", ""),
            ("mr-j5-g-n1", ""),
        ] {
            for (mode, m) in [
                ("pp", ProfileMode::Position),
                ("pv", ProfileMode::Velocity),
                ("tq", ProfileMode::Torque),
            ] {
                let c = cell(drive, &format!("mode = \"{mode}\"\n{group}")).unwrap();
                let a = &c.axes.on_loop()[0];
                assert_eq!(a.mode.as_str(), mode, "{drive}");
                assert_eq!(a.profile_objects.map(|p| p.mode), Some(m), "{drive}");
                assert!(a.profile.supports_mode(a.mode), "{drive} {mode}");
            }
        }
        // The cyclic axes are no profile axes.
        let c = cell("mr-j5-g-n1", "mode = \"csp\"").unwrap();
        assert!(c.axes.on_loop()[0].profile_objects.is_none());
    }

    #[test]
    fn a_mode_the_model_or_its_group_lacks_is_refused_naming_the_key() {
        // MR-J4-TM in its default PA01 group: no pp; the message says how to get it.
        let e = cell("mr-j4-tm", "mode = \"pp\"").unwrap_err();
        assert_eq!(e.key, "axes[0].mode");
        assert!(e.message.contains("mode_group = \"profile\""), "{e}");
        // The profile group has no csp.
        let e = cell("mr-j4-tm", "mode = \"csp\"\nmode_group = \"profile\"").unwrap_err();
        assert_eq!(e.key, "axes[0].mode");
        // MR-J3-T04 has no profile modes; the MR-J5 multi-axis units no pv / tq.
        let e = cell("mr-j3-t04", "mode = \"pp\"").unwrap_err();
        assert_eq!(e.key, "axes[0].mode", "{e}");
        let e = cell("mr-j5w2-g-n1", "mode = \"pv\"").unwrap_err();
        assert_eq!(e.key, "axes[0].mode", "{e}");
        // hm is no axis mode; mode_group only on the MR-J4-TM, with a known value.
        let e = cell("mr-j5-g-n1", "mode = \"hm\"").unwrap_err();
        assert_eq!(e.key, "axes[0].mode");
        let e = cell("mr-j5-g-n1", "mode_group = \"profile\"").unwrap_err();
        assert_eq!(e.key, "axes[0].mode_group");
        let e = cell("mr-j4-tm", "mode_group = \"pp\"").unwrap_err();
        assert_eq!(e.key, "axes[0].mode_group");
        assert!(e.message.contains("cyclic, profile"), "{e}");
    }

    #[test]
    fn pp_and_pv_need_the_rated_speed_of_their_time_constants() {
        for mode in ["pp", "pv"] {
            let e = cell_with_motor(
                "mr-jet-g-n1",
                "counts_per_rev = 10000",
                &format!("mode = \"{mode}\""),
            )
            .unwrap_err();
            assert_eq!(e.key, "axes[0].motor.rated_speed", "{e}");
        }
        let e = cell_with_motor(
            "mr-jet-g-n1",
            "counts_per_rev = 10000, rated_speed = -1",
            "mode = \"pv\"",
        )
        .unwrap_err();
        assert_eq!(e.key, "axes[0].motor.rated_speed", "{e}");
        // tq ramps on 6087h only; 3000 r/min at 10000 counts/rev is 500000 counts/s.
        let tq = cell_with_motor("mr-jet-g-n1", "counts_per_rev = 10000", "mode = \"tq\"").unwrap();
        assert_eq!(tq.axes.on_loop()[0].rated_speed, None);
        let pp = cell("mr-jet-g-n1", "mode = \"pp\"").unwrap();
        assert_eq!(pp.axes.on_loop()[0].rated_speed, Some(500_000.0));
    }

    #[test]
    fn a_pdo_map_without_the_mode_target_is_refused() {
        // MR-JET 1600h without 60FFh: pv has no target (manual §4.5: mapping required).
        let rx = "pdo = { rx = [0x60400010, 0x60600008, 0x607A0020] }";
        let e = cell("mr-jet-g-n1", &format!("mode = \"pv\"\n{rx}")).unwrap_err();
        assert_eq!(e.key, "axes[0].pdo.rx", "{e}");
        assert!(e.message.contains("60FFh"), "{e}");
        assert!(cell("mr-jet-g-n1", &format!("mode = \"pp\"\n{rx}")).is_ok());
    }

    #[test]
    fn the_default_maps_decide_cyclic_or_sdo_per_model() {
        // MR-J4-TM PA01 ___2, 1601h: 6081h/6083h/6084h/6087h are all in the RxPDO (§3.3).
        let j4 = mr_j4_tm::ModeGroup::Profile.profile();
        for mode in [
            ProfileMode::Position,
            ProfileMode::Velocity,
            ProfileMode::Torque,
        ] {
            let p = ProfileObjects::of_profile(mode, j4);
            assert!(by_sdo(&p).is_empty(), "{mode:?}");
            assert!(j4.pdo.rx.maps(mode.target()), "{mode:?}");
        }
        // MR-JET / MR-J5 1600h: the targets are mapped, the profile objects go by SDO.
        for model in [DriveModel::MrJetGN1, DriveModel::MrJ5GN1] {
            let p = profile(model);
            let pp = ProfileObjects::of_profile(ProfileMode::Position, p);
            assert_eq!(by_sdo(&pp), [0x6081, 0x6083, 0x6084], "{model}");
            let pv = ProfileObjects::of_profile(ProfileMode::Velocity, p);
            assert_eq!(by_sdo(&pv), [0x6083, 0x6084], "{model}");
            let tq = ProfileObjects::of_profile(ProfileMode::Torque, p);
            assert_eq!(by_sdo(&tq), [0x6087], "{model}");
            assert!(!tq.is_cyclic(0x6087));
        }
    }
}
