//! Drive profiles: what the controller and the simulator need to know about one drive model.
//!
//! One module per model; adding a model is a new [`DriveModel`] variant, a module with its
//! `PROFILE` constant and one arm in [`profile`].

use std::fmt;
use std::str::FromStr;
use std::sync::Arc;
use std::time::Duration;

use serde::Deserialize;

use crate::cycles::{CycleTime, Cycles};
use crate::fsa::FsaQuirks;
use crate::mode::ModeOfOperation;
use crate::pdo::PdoMap;
use crate::shared_slice::SharedSlice;

pub mod bring_up_causes;
pub use bring_up_causes::{bring_up_causes, BringUpCause};
mod cia402_facts;
pub mod facts;
pub mod generic_cia402;
pub mod homing_methods;
pub mod mapping;
pub mod matrix;
pub mod mr_j3_t04;
pub mod mr_j4_tm;
pub mod mr_j5_g_n1;
pub mod mr_jet_g_n1;
pub mod params;
pub mod status_do;
pub mod units;

pub use facts::{
    Access, AlarmInfo, AlarmKind, AlarmRegister, AlarmText, Clearing, CommCheck, DataType,
    EmergencyFacts, FsoeCommandBits, FsoeFacts, FsoeFrameLayout, FsoeStatusBits, HomeReference,
    HomeSetting, Identity, InvalidAxisSwitch, OdEntry, Pdo, PdoAssignment, PdoRules, SafeBit,
    SdoInfoFacts, StopBehaviour, TorqueLimitSelection, UnitPdoLimit, EMERGENCY_LAYOUT,
};
pub use units::{
    AccelerationUnit, MotorKind, PositionUnit, Quantity, Stated, TorqueUnit, Units, VelocityUnit,
};

/// Mitsubishi Electric's EtherCAT vendor ID (MR-J3-T04 manual §8.1(4), §1.4.1(3): "A1Eh";
/// the MR-J4-TM manual [EXT] gives the same value).
pub const MITSUBISHI_VENDOR_ID: u32 = 0x0000_0A1E;

/// A supported drive model, named in configuration by its kebab-case part number.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize)]
pub enum DriveModel {
    /// Mitsubishi MR-J5-G-N1, 1-axis EtherCAT amplifier (MR-J5-G-N1 manual, docs/manuals.md).
    #[serde(rename = "mr-j5-g-n1")]
    MrJ5GN1,
    /// Mitsubishi MR-J5W2-G-N1, 2-axis EtherCAT amplifier (MR-J5-G-N1 manual, docs/manuals.md).
    #[serde(rename = "mr-j5w2-g-n1")]
    MrJ5W2GN1,
    /// Mitsubishi MR-J5W3-G-N1, 3-axis EtherCAT amplifier (MR-J5-G-N1 manual, docs/manuals.md).
    #[serde(rename = "mr-j5w3-g-n1")]
    MrJ5W3GN1,
    /// Mitsubishi MR-J3-□A-RJ158 with the MR-J3-T04 EtherCAT option (MR-J3-T04 manual, docs/manuals.md).
    #[serde(rename = "mr-j3-t04")]
    MrJ3T04,
    /// Mitsubishi MR-J4-_TM_ with the ABCC-M40-ECT EtherCAT module (MR-J4-TM manual, docs/manuals.md).
    #[serde(rename = "mr-j4-tm")]
    MrJ4TM,
    /// Mitsubishi MR-JET-G-N1 (MR-JET-G-N1 manual, docs/manuals.md).
    #[serde(rename = "mr-jet-g-n1")]
    MrJetGN1,
    /// Any CoE SubDevice with the CiA 402 drive profile (CiA 402 / ETG.6010, no vendor
    /// specifics); identity from the cell config (`generic_cia402.rs`).
    #[serde(rename = "cia402")]
    GenericCia402,
}

/// A model name that is not supported.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "unknown drive model {text:?}; supported models: {}",
    DriveModel::names()
)]
pub struct ParseModelError {
    /// The rejected text.
    pub text: String,
}

impl DriveModel {
    /// Every supported model.
    pub const ALL: &'static [DriveModel] = &[
        DriveModel::MrJ5GN1,
        DriveModel::MrJ5W2GN1,
        DriveModel::MrJ5W3GN1,
        DriveModel::MrJ3T04,
        DriveModel::MrJ4TM,
        DriveModel::MrJetGN1,
        DriveModel::GenericCia402,
    ];

    /// The configuration name, e.g. "mr-j5-g-n1".
    pub const fn as_str(self) -> &'static str {
        match self {
            DriveModel::MrJ5GN1 => "mr-j5-g-n1",
            DriveModel::MrJ5W2GN1 => "mr-j5w2-g-n1",
            DriveModel::MrJ5W3GN1 => "mr-j5w3-g-n1",
            DriveModel::MrJ3T04 => "mr-j3-t04",
            DriveModel::MrJ4TM => "mr-j4-tm",
            DriveModel::MrJetGN1 => "mr-jet-g-n1",
            DriveModel::GenericCia402 => "cia402",
        }
    }

    /// Every supported model's configuration name, comma-separated.
    pub fn names() -> String {
        let v: Vec<&str> = Self::ALL.iter().map(|m| m.as_str()).collect();
        v.join(", ")
    }
}

impl fmt::Display for DriveModel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl FromStr for DriveModel {
    type Err = ParseModelError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .iter()
            .copied()
            .find(|m| m.as_str() == s)
            .ok_or_else(|| ParseModelError { text: s.to_owned() })
    }
}

/// A drive profile shared by whoever needs it: built once per axis when the cell's
/// configuration is read (a built-in profile, or one derived from it by a remap, an identity or
/// an ESI file).
pub type SharedProfile = Arc<DriveProfile>;

/// A shared copy of a profile (its tables are shared, not copied), e.g. of a built-in one.
impl From<&DriveProfile> for SharedProfile {
    fn from(profile: &DriveProfile) -> Self {
        Arc::new(profile.clone())
    }
}

/// Everything cellrt knows about one drive model: compile-time data for the built-in models,
/// owned tables where a profile is derived at run time.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DriveProfile {
    /// The model this profile describes.
    pub model: DriveModel,
    /// Human-readable product name.
    pub name: &'static str,
    /// EtherCAT identity (1018h), with the gaps cited.
    pub identity: Identity,
    /// The modes and cycle times the drive runs.
    pub cycle: CycleFacts,
    /// The default PDO maps and the rules for changing them.
    pub pdo: PdoFacts,
    /// PDS deviations from plain CiA 402.
    pub quirks: FsaQuirks,
    /// The alarms and how a Fault Reset clears them.
    pub faults: FaultFacts,
    /// Axes per amplifier (1, or 2/3 for MR-J5W2/W3).
    pub axes_per_unit: u8,
    /// Encoder resolution and object units.
    pub units: Units,
    /// The object-dictionary entries the runtime and the simulator use.
    pub objects: &'static [OdEntry],
    /// The cyclic communication check and what leaving OP does.
    pub comm: CommFacts,
    /// The limits the drive watches and the alarms and warnings they raise.
    pub limits: LimitFacts,
    /// SDO downloads the model refuses with a specific abort code: (index, sub, code).
    pub sdo_write_refusals: &'static [(u16, u8, u32)],
    /// The homing methods and what a homing changes.
    pub homing: HomingSetup,
    /// Store/restore objects (1010h/1011h) the SDO surface serves besides `objects`.
    pub store_restore_objects: &'static [OdEntry],
    /// The axis-selection switch setting the amplifier refuses at power-on (MR-J5-G-N1 1-axis:
    /// SW3-1 OFF / SW3-2 ON → AL.011.2, MR-J5-G-N1 manual §2.2, §3.1, §4.3, §4.4, TV-14); `None`: no such rule stated.
    pub invalid_axis_switch: Option<InvalidAxisSwitch>,
    /// The drive parameter that selects which of the model's profiles the drive runs (MR-J4-TM
    /// [Pr. PA01]: the control-mode group); `None` where one profile is all there is.
    pub profile_selector: Option<ProfileSelector>,
    /// FSoE (safety over EtherCAT) as the manual states it (MR-JET-G-N1, MR-JET-G-N1 manual §9.3);
    /// `None`: the model has no FSoE.
    pub fsoe: Option<FsoeFacts>,
    /// The servo parameters by their manual names, the parameter save and the alarm history.
    pub parameters: &'static params::ParameterFacts,
}

/// A drive parameter whose value selects the profile the drive runs ([`DriveProfile::profile_selector`]).
#[derive(Debug, Clone, Copy)]
pub struct ProfileSelector {
    /// The parameter's object.
    pub index: u16,
    /// Its sub-index.
    pub sub: u8,
    /// The profile a value selects and the mode 6061h shows when the drive starts in it;
    /// `None` for a value that selects no profile cellrt has.
    pub select: fn(i64) -> Option<(&'static DriveProfile, crate::mode::ModeOfOperation)>,
    /// Where the rule comes from.
    pub source: &'static str,
}

/// Two selectors are the same parameter with the same rule (the rule is compared by where it
/// comes from: function addresses are not comparable).
impl PartialEq for ProfileSelector {
    fn eq(&self, other: &Self) -> bool {
        (self.index, self.sub, self.source) == (other.index, other.sub, other.source)
    }
}

impl Eq for ProfileSelector {}

/// The modes and cycle times a drive runs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CycleFacts {
    /// Modes of operation the drive accepts in 6060h.
    pub modes: SharedSlice<ModeOfOperation>,
    /// Supported PDO cycle times in µs.
    pub cycle_times_us: &'static [u32],
    /// True if controlword bit 8 HALT acts in csp/csv/cst (false: hm/profile modes only).
    pub halt_in_cyclic_modes: bool,
    /// Where 607Ah comes from while the drive enters csp.
    pub csp_entry: crate::mode_switch::CspEntry,
}

/// A drive's default PDO maps and the rules for changing them.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PdoFacts {
    /// The default RxPDO map (master → drive).
    pub rx: PdoMap,
    /// The default TxPDO map (drive → master).
    pub tx: PdoMap,
    /// The amplifier's PDO byte limits over all its axes, per cycle-time range (MR-J5-G-N1
    /// manual §4.4); empty where the manual states none.
    pub unit_limits: &'static [UnitPdoLimit],
    /// How the PDO mapping may be changed by SDO, with the abort codes.
    pub rules: PdoRules,
}

/// A drive's alarms and how a Fault Reset clears them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FaultFacts {
    /// Minimum Fault Reset hold in ms for cycles up to `long_cycle_from_us` (exclusive).
    pub reset_hold_ms: u32,
    /// Minimum Fault Reset hold in ms for cycles of `long_cycle_from_us` and longer.
    pub reset_hold_long_cycle_ms: u32,
    /// The cycle time (µs) from which `reset_hold_long_cycle_ms` applies.
    pub long_cycle_from_us: u32,
    /// The alarms and warnings the manual names, with their stop behaviour.
    pub alarms: &'static [AlarmInfo],
}

/// A drive's cyclic communication check and what leaving OP does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CommFacts {
    /// The cyclic communication check.
    pub check: CommCheck,
    /// Alarm raised when the AL state leaves OP while the PDS is switched on or enabled
    /// (spec README "Leaving OP").
    pub leave_op_alarm: u16,
    /// True if leaving OP re-initialises the drive (PDS back to Switch on disabled; MR-JET/MR-J5
    /// §2.2, MR-J4-TM §2.2). MR-J3-T04 states no re-initialisation.
    pub reinit_on_leaving_op: bool,
    /// Whether alarms are also reported by CoE Emergency (ETG.1000.6 §5.6.2.1).
    pub emergency: EmergencyFacts,
    /// What the drive answers of SDO Information.
    pub sdo_info: SdoInfoFacts,
}

/// The limits a drive watches and the alarms and warnings they raise.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LimitFacts {
    /// Alarm for an excessive following error (603Fh code).
    pub following_error_alarm: u16,
    /// Alarm for a command implying more than the maximum speed (603Fh code).
    pub overspeed_alarm: u16,
    /// Where the torque limits come from.
    pub torque_limit_selection: TorqueLimitSelection,
    /// Warning raised while a stroke-end input (LSP/LSN) is OFF, where the sim models stroke
    /// ends (MR-J3-T04 AL.99, §9.1); `None`: not modelled for this drive.
    pub stroke_end_warning: Option<u16>,
    /// (EM1 forced stop, main circuit off) warnings where the sim models those inputs
    /// (MR-J3-T04 AL.E6 / AL.E9, §3.7); `None`: not modelled.
    pub power_warnings: Option<(u16, u16)>,
    /// Controlword2 bit of the csp manual stop C_MSTOP where modelled (MR-J3-T04 bit 8, §9.2).
    pub manual_stop_bit: Option<u8>,
    /// Warning raised, with no motion, when a pp set-point asks for a relative move while the
    /// position unit is degree (MR-J4-TM AL. F4.8, MR-J4-TM manual §5.4.6 bit 6); `None`: the manual
    /// states no such rule.
    pub relative_degree_warning: Option<u16>,
}

/// A drive's homing methods and what a homing changes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HomingSetup {
    /// Homing methods (6098h) the manual lists; empty where it lists none (MR-JET, MR-J5).
    pub methods: &'static [i8],
    /// Of those, the data-set methods: home = the current position, no motion.
    pub data_set_methods: &'static [i8],
    /// What a completed homing changes.
    pub reference: HomeReference,
    /// Home setting by Controlword2 edges in csp/csv (MR-J3-T04 §8.3); `None`: the model has
    /// none.
    pub setting: Option<HomeSetting>,
}

impl DriveProfile {
    /// True if the drive accepts `mode` in 6060h.
    pub fn supports_mode(&self, mode: ModeOfOperation) -> bool {
        self.cycle.modes.contains(&mode)
    }

    /// True if the drive can run its PDOs at `cycle`.
    pub fn supports_cycle_time(&self, cycle: CycleTime) -> bool {
        self.cycle.cycle_times_us.contains(&cycle.as_micros())
    }

    /// Cycles to hold Fault Reset at `cycle`: the model's minimum hold rounded up to whole cycles
    /// (TV-5: 80 at 0.125 ms, 10 at 1 ms, 3 at 4 ms, 3 at 8 ms), never fewer than one.
    pub fn fault_reset_hold(&self, cycle: CycleTime) -> Cycles {
        let ms = if cycle.as_micros() >= self.faults.long_cycle_from_us {
            self.faults.reset_hold_long_cycle_ms
        } else {
            self.faults.reset_hold_ms
        };
        let n = cycle.cycles_for(Duration::from_millis(u64::from(ms)));
        Cycles(n.0.max(1))
    }

    /// EtherCAT vendor ID, when a source documents it.
    pub const fn vendor_id(&self) -> Option<u32> {
        self.identity.vendor_id
    }

    /// EtherCAT product code, when a source documents it.
    pub const fn product_code(&self) -> Option<u32> {
        self.identity.product_code
    }

    /// The object-dictionary entry `index:sub`, if the profile lists it (the first of
    /// [`DriveProfile::all_objects`]). A scan of every table: per-cycle lookups use an
    /// [`ObjectIndex`].
    pub fn object(&self, index: u16, sub: u8) -> Option<&'static OdEntry> {
        self.all_objects()
            .find(|o| o.index == index && o.sub == sub)
    }

    /// Every object-dictionary entry the profile lists: its objects, the store/restore
    /// objects, the parameter objects and the parameter table's objects, in that order.
    pub fn all_objects(&self) -> impl Iterator<Item = &'static OdEntry> + '_ {
        self.objects
            .iter()
            .chain(self.store_restore_objects)
            .chain(self.parameters.objects)
            .chain(self.parameters.table.iter().map(|p| &p.object))
    }

    /// The alarm or warning with `code`, if the manual names it.
    pub fn alarm(&self, code: u16) -> Option<&'static AlarmInfo> {
        AlarmInfo::find(self.faults.alarms, code)
    }

    /// 603Fh `code` in words: the manual's number, name, cause and remedy where it lists them.
    pub fn alarm_text(&self, code: u16) -> AlarmText {
        AlarmText::decode(
            self.faults.alarms,
            self.name,
            AlarmRegister::ErrorCode603F,
            code,
        )
    }

    /// True if a Fault Reset clears alarm `code` (codes the manual does not name are treated as
    /// resettable, e.g. injected test alarms).
    pub fn alarm_resettable(&self, code: u16) -> bool {
        self.alarm(code).is_none_or(AlarmInfo::resettable)
    }

    /// The supported cycle times as text, e.g. "500, 1000, 2000 µs".
    pub fn cycle_times_text(&self) -> String {
        let v: Vec<String> = self
            .cycle
            .cycle_times_us
            .iter()
            .map(u32::to_string)
            .collect();
        format!("{} µs", v.join(", "))
    }

    /// True if one station carries several axes (MR-J5W2/W3-G-N1).
    pub const fn is_multi_axis(&self) -> bool {
        self.axes_per_unit > 1
    }

    /// The index of axis-A object `index` on slot `slot` of this model's unit (MR-J5-G-N1 manual
    /// §1.5 offsets on a multi-axis unit; `index` itself on a 1-axis drive's slot 0). `None` for
    /// a slot the unit does not have.
    pub const fn axis_object(&self, index: u16, slot: u8) -> Option<u16> {
        if slot >= self.axes_per_unit {
            None
        } else if self.is_multi_axis() {
            mr_j5_g_n1::axis_index(index, slot)
        } else {
            Some(index)
        }
    }

    /// The slot and axis-A index of object `index` of this model's unit (the inverse of
    /// [`DriveProfile::axis_object`]); `None` for the area of a slot the unit does not have.
    pub const fn object_slot(&self, index: u16) -> Option<(u8, u16)> {
        if self.is_multi_axis() {
            mr_j5_g_n1::index_axis(index, self.axes_per_unit)
        } else {
            Some((0, index))
        }
    }

    /// The most (RxPDO, TxPDO) bytes the whole amplifier exchanges at `cycle_us`; `None` where
    /// the profile's table has no row for that cycle.
    pub fn unit_pdo_limit(&self, cycle_us: u32) -> Option<(u16, u16)> {
        self.pdo
            .unit_limits
            .iter()
            .find(|l| (l.from_us..=l.to_us).contains(&cycle_us))
            .map(|l| (l.max_rx_bytes, l.max_tx_bytes))
    }

    /// This profile as a [`SharedProfile`] (a copy whose tables are shared, not copied).
    pub fn shared(&self) -> SharedProfile {
        Arc::new(self.clone())
    }

    /// The supported modes as text, e.g. "hm, csp, csv".
    pub fn modes_text(&self) -> String {
        let v: Vec<&str> = self.cycle.modes.iter().map(|m| m.as_str()).collect();
        v.join(", ")
    }
}

/// The static profile of `model`.
pub fn profile(model: DriveModel) -> &'static DriveProfile {
    match model {
        DriveModel::MrJ5GN1 => &mr_j5_g_n1::PROFILE,
        DriveModel::MrJ5W2GN1 => &mr_j5_g_n1::PROFILE_W2,
        DriveModel::MrJ5W3GN1 => &mr_j5_g_n1::PROFILE_W3,
        DriveModel::MrJ3T04 => &mr_j3_t04::PROFILE,
        DriveModel::MrJ4TM => &mr_j4_tm::PROFILE,
        DriveModel::MrJetGN1 => &mr_jet_g_n1::PROFILE,
        DriveModel::GenericCia402 => &generic_cia402::PROFILE,
    }
}

/// One object-dictionary row as a test pins it: (index, sub, type, access, PDO, default).
#[cfg(test)]
pub(crate) type PinnedRow = (u16, u8, DataType, Access, Pdo, Option<i64>);

/// Asserts that `profile` lists every row of `rows` with exactly that type, access, PDO mapping
/// and default (the model tests pin rows with the manual's literal values).
#[cfg(test)]
pub(crate) fn assert_rows(profile: &DriveProfile, rows: &[PinnedRow]) {
    for &(index, sub, data_type, access, pdo, default) in rows {
        let o = profile
            .object(index, sub)
            .unwrap_or_else(|| panic!("{} lists {index:04X}h:{sub}", profile.name));
        assert_eq!(
            (o.data_type, o.access, o.pdo, o.default),
            (data_type, access, pdo, default),
            "{} {index:04X}h:{sub}",
            profile.name
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::de::value::{Error as DeError, StrDeserializer};
    use serde::de::IntoDeserializer;

    #[test]
    fn model_names() {
        assert_eq!("mr-j5-g-n1".parse::<DriveModel>(), Ok(DriveModel::MrJ5GN1));
        assert_eq!(DriveModel::MrJ5GN1.as_str(), "mr-j5-g-n1");
        let e = "mr-j9".parse::<DriveModel>().unwrap_err().to_string();
        assert!(e.contains("\"mr-j9\"") && e.contains("mr-j5-g-n1"), "{e}");
        for m in DriveModel::ALL {
            assert_eq!(profile(*m).model, *m);
            assert_eq!(m.as_str().parse::<DriveModel>(), Ok(*m));
            let de: StrDeserializer<'_, DeError> = m.as_str().into_deserializer();
            assert_eq!(DriveModel::deserialize(de), Ok(*m));
            assert!(e.contains(m.as_str()), "{e}");
        }
    }

    #[test]
    fn the_object_index_finds_what_the_scan_finds() {
        for &m in DriveModel::ALL {
            let p = profile(m);
            let index = ObjectIndex::of(p);
            for o in p.all_objects() {
                let found = index.get(o.index, o.sub).map(|e| e as *const OdEntry);
                let scanned = p.object(o.index, o.sub).map(|e| e as *const OdEntry);
                assert_eq!(found, scanned, "{m:?} {:04X}h:{}", o.index, o.sub);
            }
            for (i, sub) in [(0x0000, 0), (0x60B0, 0), (0x6041, 9), (0xFFFF, 255)] {
                assert_eq!(
                    index.get(i, sub).is_some(),
                    p.object(i, sub).is_some(),
                    "{m:?} {i:04X}h:{sub}"
                );
            }
        }
    }

    #[test]
    fn model_deserializes_from_its_config_name() {
        let de: StrDeserializer<'_, DeError> = "mr-j5-g-n1".into_deserializer();
        assert_eq!(DriveModel::deserialize(de), Ok(DriveModel::MrJ5GN1));
        let de: StrDeserializer<'_, DeError> = "MrJ5GN1".into_deserializer();
        assert!(DriveModel::deserialize(de).is_err());
    }
}

/// A profile's object dictionary sorted by (index, sub): a lookup in O(log n) where
/// [`DriveProfile::object`] scans every table (with the parameter tables, a lookup of an
/// object the model lacks took hundreds of comparisons, in the simulated drives every cycle).
/// Built once, off the RT thread; a lookup allocates nothing.
#[derive(Debug, Clone)]
pub struct ObjectIndex(std::sync::Arc<[&'static OdEntry]>);

impl ObjectIndex {
    /// The index of `profile`'s entries; where an (index, sub) appears twice, the first of
    /// [`DriveProfile::all_objects`] (as [`DriveProfile::object`] finds it).
    pub fn of(profile: &DriveProfile) -> ObjectIndex {
        let mut all: Vec<(usize, &'static OdEntry)> = profile.all_objects().enumerate().collect();
        all.sort_by_key(|&(k, o)| (o.index, o.sub, k));
        all.dedup_by_key(|(_, o)| (o.index, o.sub));
        ObjectIndex(all.into_iter().map(|(_, o)| o).collect())
    }

    /// The entry `index:sub`, if the profile lists it.
    #[inline]
    pub fn get(&self, index: u16, sub: u8) -> Option<&'static OdEntry> {
        self.0
            .binary_search_by_key(&(index, sub), |o| (o.index, o.sub))
            .ok()
            .map(|k| self.0[k])
    }
}
